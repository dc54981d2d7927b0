// A capstan's Contact sublist, typed: declared (name, default, doc string) and
// parsed side by side, the only place its defaults are stated. ContactEffect
// reads it as it is; what depends on the mesh (the automatic tolerance, solve
// penalty and quadrature) is resolved there, the quadrature's rule here.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <utility>
#include <vector>

#include "../parameters.hpp"

namespace capstan {

struct ContactSettings {
  enum class Method { Penalty, AugmentedLagrangian };
  // Values are kernels::FaceRule's (checked in contact.cpp); Auto is resolved
  // by resolvedQuadrature() once the faces are known.
  enum class Quadrature { Gauss2x2 = 0, Gauss3x3 = 1, Nodal = 2, Auto = 3 };
  // Below this times h / c (h the smallest candidate face edge, c the shear
  // modulus), Quadrature Auto gives a penalty the nodal rule.
  static constexpr double kGaussPenaltyLimit = 1e-3;
  // Penalty 0 (the default), a plain penalty: this times h / c, 1e-3 on G1's mesh (formulation.md's
  // study value), in whatever units the scene is written (docs/contact.md, "Penalties in any units").
  static constexpr double kAutomaticPenalty = 2e-3;
  // Penalty 0, the augmented Lagrangian (whose answer does not depend on eps2): the study's 1e-3,
  // which every shipped scene was measured with, held between the floor and kSoftestExactSolve h / c.
  static constexpr double kStudyPenalty = 1e-3;
  // The augmented Lagrangian solves at most this times h / c: its answer does not depend on eps2,
  // and a softer solve slows the multiplier loop (G1: 5 passes a step at 2e-2 h / c, 7 at 2, 13
  // at 20, exit 2 at 2000; docs/contact.md, "Penalties in any units").
  static constexpr double kSoftestExactSolve = 1e-1;
  // A plain penalty above this times h / c (formulation.md's softest, 1e-2, on G1's mesh) warns:
  // the body sinks into the capstan by about eps2 x the contact pressure.
  static constexpr double kSoftestPenalty = 2e-2;

  Method method = Method::Penalty;
  double penalty = 0;               // eps2: penetration per unit contact pressure; 0: automatic
  double penetrationTolerance = 0;  // 0: 1e-4 x the smallest candidate face edge
  double minimumSolvePenalty = 0;   // < 0: automatic (ContactEffect)
  int maxAugmentations = 0;
  Quadrature quadrature = Quadrature::Auto;  // as the scene names it (ContactEffect resolves Auto)
  double smoothing = 0;             // pressure scale of the smoothed corner; 0: max(0, .)

  // Augmented Lagrangian: g = 0 at the points in contact (else g = eps2 t_n).
  bool exact() const { return method == Method::AugmentedLagrangian; }
  // The rule the contact points follow, Auto resolved: Nodal for the augmented
  // Lagrangian, for a Penalty below kGaussPenaltyLimit hMin / c, and where the
  // friction on these faces sticks exactly (exactStick: steady Coulomb, whose
  // stick rows sit at the nodal rule's points); else Gauss 2x2.
  Quadrature resolvedQuadrature(double hMin, double c, bool exactStick = false) const;
  // eps2, the automatic one resolved (hMin the smallest candidate face edge, c the material's).
  double resolvedPenalty(double hMin, double c) const {
    return penalty > 0 ? penalty : exact() ? kStudyPenalty : kAutomaticPenalty * hMin / c;
  }
  // The eps of the Newton solves: eps2, at least the floor (Minimum Solve Penalty; automatic
  // 1e-2 h / c with the nodal rule), the augmented Lagrangian's at most kSoftestExactSolve h / c.
  double solvePenalty(double hMin, double c, bool nodal) const;

  static void declare(Teuchos::ParameterList& contact);
  static ContactSettings parse(const Teuchos::ParameterList& contact, const std::string& path,
                               const ParameterReader& r);
  static const std::vector<std::pair<const char*, Method>> methods;
};

}  // namespace capstan
