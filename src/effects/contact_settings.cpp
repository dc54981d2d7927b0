#include "contact_settings.hpp"

#include <algorithm>

namespace capstan {

const std::vector<std::pair<const char*, ContactSettings::Method>> ContactSettings::methods = {
    {"Penalty", Method::Penalty}, {"Augmented Lagrangian", Method::AugmentedLagrangian}};

void ContactSettings::declare(Teuchos::ParameterList& contact) {
  contact.set("Method", std::string("Penalty"), "Penalty | Augmented Lagrangian");
  contact.set("Penalty", 0.0,
              "eps2 >= 0: penetration per unit contact pressure; 0 = automatic: 2e-3 h / c for Penalty (h the "
              "smallest candidate face edge; 1e-3 on G1), the same answer in any consistent units; 1e-3 for the "
              "Augmented Lagrangian, whose answer does not depend on it and whose solves hold it between "
              "Minimum Solve Penalty and 1e-1 h / c");
  contact.set("Penetration Tolerance", 0.0,
              "Multiplier loop (augmented Lagrangian, or a penalty solved at a larger penalty): "
              "stop when the penetration (or its error against the penalty answer) is below "
              "this; 0 = 1e-4 x the smallest candidate face edge");
  contact.set("Max Augmentations", 50, "Augmented Lagrangian: most multiplier updates per step");
  contact.set("Minimum Solve Penalty", -1.0,
              "Newton solves use eps = max(Penalty, this) (the Augmented Lagrangian's at most 1e-1 h / c), "
              "and multiplier updates then reach the "
              "answer of Penalty (or exact contact): a well-conditioned solve for any Penalty. "
              "< 0: automatic, 1e-2 h / c with the Nodal rule (h the smallest candidate face edge), "
              "off with Gauss rules; 0: off");
  contact.set("Quadrature", std::string("Auto"),
              "Contact points per face: Auto | Gauss 2x2 | Gauss 3x3 | Nodal (at the face's nodes). "
              "Auto: Nodal for Augmented Lagrangian (exact contact at every Gauss point of flat faces "
              "on a curved capstan over-constrains the body), and for a Penalty below 1e-3 h / c "
              "(h the smallest candidate face edge: Gauss points lock there, and the loops stall), "
              "and in steady rolling under Coulomb (its exact stick needs one point per node); "
              "Gauss 2x2 for a softer Penalty");
  contact.set("Smoothing", 0.0,
              "Pressure scale eta >= 0 of a smoothed contact law: t_n = (tn + sqrt(tn^2 + eta^2)) / 2 "
              "instead of max(0, tn), at most eta/2 different. Removes the corner where points enter "
              "and leave contact, at which Newton stalls in rolling contact; 0 = the exact max");
}

ContactSettings ContactSettings::parse(const Teuchos::ParameterList& ct, const std::string& path,
                                       const ParameterReader& r) {
  ContactSettings s;
  s.method = r.choice(ct, path, "Method", methods);
  s.penalty = r.nonNegative(ct, path, "Penalty");
  s.penetrationTolerance = r.nonNegative(ct, path, "Penetration Tolerance");
  s.minimumSolvePenalty = r.finite(ct, path, "Minimum Solve Penalty");
  s.quadrature = r.choice(ct, path, "Quadrature",
                          std::vector<std::pair<const char*, Quadrature>>{{"Auto", Quadrature::Auto},
                                                                          {"Gauss 2x2", Quadrature::Gauss2x2},
                                                                          {"Gauss 3x3", Quadrature::Gauss3x3},
                                                                          {"Nodal", Quadrature::Nodal}});
  if (s.exact() && s.quadrature != Quadrature::Nodal && s.quadrature != Quadrature::Auto)
    r.fail(path + "/Quadrature",
           "the Augmented Lagrangian needs Nodal (or Auto): zero gap at every Gauss point of flat "
           "faces against a curved capstan is impossible, and the multipliers would never settle");
  s.smoothing = r.nonNegative(ct, path, "Smoothing");
  s.maxAugmentations = r.atLeast(ct, path, "Max Augmentations", 1);
  return s;
}

// Nodal for the augmented Lagrangian, a stiff penalty and Coulomb's exact stick: Gauss points of
// flat faces over-constrain the curved capstan as eps2 -> 0, and stick rows exist only at nodal
// points (docs/contact.md, "Contact points: Gauss or nodal").
ContactSettings::Quadrature ContactSettings::resolvedQuadrature(double hMin, double c, bool exactStick) const {
  if (quadrature != Quadrature::Auto) return quadrature;
  return exact() || exactStick || resolvedPenalty(hMin, c) < kGaussPenaltyLimit * hMin / c ? Quadrature::Nodal
                                                                                           : Quadrature::Gauss2x2;
}

double ContactSettings::solvePenalty(double hMin, double c, bool nodal) const {
  // Automatic floor for the nodal rule only: with Gauss points the penalty answer approaches an
  // over-constrained one as eps2 -> 0 (flat faces cannot touch a curved capstan at every Gauss
  // point), and the multiplier loop crawls (measured on G1: eps2 = 1e-4 needed 100+ passes per step).
  const double floor = minimumSolvePenalty >= 0 ? minimumSolvePenalty : nodal ? 1e-2 * hMin / c : 0.0;
  const double eps2 = resolvedPenalty(hMin, c);
  if (!exact()) return std::max(eps2, floor);
  // The augmented Lagrangian's answer does not depend on eps2: a softer solve than
  // kSoftestExactSolve h / c is stiffened to it (a scene in metres and pascals with a penalty meant
  // for millimetres and megapascals stalled: docs/contact.md, "Penalties in any units"). The
  // automatic one above it (the study's 1e-3 in other units than its own) solves at the floor,
  // where the shipped scenes in millimetres solve, so that they solve alike in any units.
  const double softest = kSoftestExactSolve * hMin / c;
  if (penalty == 0 && eps2 > softest && floor > 0) return floor;
  return std::max(std::min(eps2, softest), floor);
}

}  // namespace capstan
