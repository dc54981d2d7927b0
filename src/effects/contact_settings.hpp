// A capstan's Contact sublist, typed: declared (name, default, doc string) and
// parsed side by side, the only place its defaults are stated. ContactEffect
// reads it as it is; what depends on the mesh (the automatic tolerance and
// solve penalty) is resolved there.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <utility>
#include <vector>

#include "../parameters.hpp"

namespace capstan {

struct ContactSettings {
  enum class Method { Penalty, AugmentedLagrangian };
  // Values are kernels::FaceRule's (checked in contact.cpp).
  enum class Quadrature { Gauss2x2 = 0, Gauss3x3 = 1, Nodal = 2 };

  Method method = Method::Penalty;
  double penalty = 0;               // eps2: penetration per unit contact pressure
  double penetrationTolerance = 0;  // 0: 1e-4 x the smallest candidate face edge
  double minimumSolvePenalty = 0;   // < 0: automatic (ContactEffect)
  int maxAugmentations = 0;
  Quadrature quadrature = Quadrature::Gauss2x2;  // Auto resolved by parse(), then for a stiff penalty by ContactEffect
  bool quadratureAuto = false;                   // the scene left Quadrature at Auto
  double smoothing = 0;             // pressure scale of the smoothed corner; 0: max(0, .)

  // Augmented Lagrangian: g = 0 at the points in contact (else g = eps2 t_n).
  bool exact() const { return method == Method::AugmentedLagrangian; }

  static void declare(Teuchos::ParameterList& contact);
  static ContactSettings parse(const Teuchos::ParameterList& contact, const std::string& path,
                               const ParameterReader& r);
  static const std::vector<std::pair<const char*, Method>> methods;
};

}  // namespace capstan
