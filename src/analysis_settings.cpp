#include "analysis_settings.hpp"

#include <cmath>
#include <string>

#include "scene.hpp"

namespace capstan {

const std::vector<std::pair<const char*, AnalysisSettings::Type>> AnalysisSettings::types = {
    {"Quasi-Static", Type::QuasiStatic}, {"Steady Rolling", Type::SteadyRolling}};

void AnalysisSettings::declare(Teuchos::ParameterList& analysis) {
  analysis.set("Type", std::string("Quasi-Static"),
               "Quasi-Static (load steps on a Lagrangian mesh) | Steady Rolling (each step's steady "
               "rolling state on a fixed annulus the material flows through: formulation.md §8)");
  analysis.set("Upwind Order", 2,
               "Steady Rolling: the surface velocity along the rings as a first- (1) or second-order (2) "
               "upwind difference (docs/steady-rolling.md: 2 converges faster under refinement)");
  const AnalysisSettings defaults;
  analysis.set("Start Slip Scales", Teuchos::Array<double>(defaults.startSlipScales),
               "Steady Rolling with Coulomb friction: the slip speed scales, as fractions of the capstan's surface "
               "speed, of the Tanh laws the start from rest passes through before Coulomb, widest first "
               "(docs/steady-rolling.md, \"Start from rest\", has the measurements that chose them)");
}

AnalysisSettings AnalysisSettings::parse(const Teuchos::ParameterList& analysis, const ParameterReader& r) {
  AnalysisSettings a;
  a.type = r.choice(analysis, "Analysis", "Type", types);
  a.upwindOrder = analysis.get<int>("Upwind Order");
  if (a.upwindOrder != 1 && a.upwindOrder != 2)
    r.fail("Analysis/Upwind Order", "must be 1 or 2, got " + std::to_string(a.upwindOrder));
  const auto& scales = analysis.get<Teuchos::Array<double>>("Start Slip Scales");
  if (scales.empty()) r.fail("Analysis/Start Slip Scales", "needs at least one scale");
  for (int k = 0; k < int(scales.size()); ++k)
    if (!(std::isfinite(scales[k]) && scales[k] > 0 && (k == 0 || scales[k] < scales[k - 1])))
      r.fail("Analysis/Start Slip Scales", "must be positive, finite and falling, widest first");
  a.startSlipScales.assign(scales.begin(), scales.end());
  return a;
}

namespace {
// Whether a unit direction is along +-z to round-off (the annulus axis).
bool alongZ(const std::array<double, 3>& d) {
  const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return n > 0 && std::fabs(std::fabs(d[2]) / n - 1) < 1e-12;
}
}  // namespace

void AnalysisSettings::checkScene(const Scene& sc, const ParameterReader& r) {
  if (!sc.analysis.steady()) return;
  const std::string why = " (Analysis/Type = Steady Rolling, interface.md \"Steady rolling\")";
  if (sc.mesh.type != MeshSpec::Type::Annulus)
    r.fail("Mesh/Type", "must be Annulus: the material flows around the annulus axis" + why);
  bool innerHeld = false;
  for (const auto& s : sc.supports) {
    if (s.face != "inner") continue;
    const std::string path = "Supports/" + s.name;
    if (s.type == SupportSpec::Type::Fixed && s.components == std::array<bool, 3>{true, true, true}) {
      innerHeld = true;
      continue;
    }
    if (!s.isCore())
      r.fail(path + "/Type", "on the inner face must be Rigid Core or Fixed" + why);
    innerHeld = true;
    const auto& A = s.axisPoint;
    const std::array<double, 3> off{A[0] - sc.mesh.center[0], A[1] - sc.mesh.center[1], 0.0};
    if (!alongZ(s.axisDirection)) r.fail(path + "/Axis Direction", "must be the annulus axis (along z)" + why);
    if (std::hypot(off[0], off[1]) > 1e-12 * sc.mesh.outerRadius)
      r.fail(path + "/Axis Point", "must lie on the annulus axis (x, y of Mesh/Center)" + why);
  }
  if (!innerHeld) r.fail("Supports", "no Rigid Core or Fixed support on the inner face" + why);
  if (sc.capstans.empty()) r.fail("Capstans", "none: steady rolling needs a spinning capstan" + why);
  for (const auto& c : sc.capstans) {
    const std::string path = "Capstans/" + c.name;
    if (!alongZ(c.axisDirection)) r.fail(path + "/Axis Direction", "must be parallel to the annulus axis (z)" + why);
    if (c.velocity != std::array<double, 3>{0, 0, 0})
      r.fail(path + "/Velocity", "must be zero: the capstan stays put in the steady frame" + why);
    if (c.angularVelocity == 0) r.fail(path + "/Angular Velocity", "must not be zero: the capstan drives the roller" + why);
  }
}

}  // namespace capstan
