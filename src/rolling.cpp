#include "rolling.hpp"

#include <cmath>
#include <vector>

#include "assembly.hpp"
#include "errors.hpp"
#include "log.hpp"
#include "mesh.hpp"
#include "parameters.hpp"
#include "vec3.hpp"

namespace capstan {

double noSlipAngularVelocity(const Scene& scene, const RigidCore& core) {
  if (scene.mesh.type != MeshSpec::Type::Annulus) return 0;
  for (const auto& c : scene.capstans) {
    if (c.angularVelocity == 0) continue;
    const double along = dot(core.axisDirection, c.axisDirection) / norm(c.axisDirection);
    return -c.angularVelocity * c.radius * along / scene.mesh.outerRadius;
  }
  return 0;
}

double speedRatio(const Scene& scene, const RigidCore& core, double angularVelocity) {
  const double rolling = noSlipAngularVelocity(scene, core);
  return rolling != 0 ? angularVelocity / rolling : std::nan("");
}

std::string brakeDiagnosis(const Scene& scene) {
  std::string out;
  if (scene.mesh.type != MeshSpec::Type::Annulus) return out;
  for (const auto& s : scene.supports) {
    if (!s.isCore() || s.rotation != SupportSpec::Rotation::Free || s.torque == 0) continue;
    // Friction at most mu |t_n| everywhere, at most the outer radius from the
    // axis: the nip carries at most sum mu |F| R_outer about the core's axis.
    // A held core (no Force) presses by the overlap the scene gives it, which only the solve knows.
    const double F = norm(s.force);
    if (F == 0) continue;
    double mu = 0;
    for (const auto& c : scene.capstans) mu += c.friction.on() ? c.friction.coefficient : 0.0;
    const double capacity = mu * F * scene.mesh.outerRadius;
    if (std::fabs(s.torque) > capacity)
      out += "; support '" + s.name + "': its Torque " + brief(s.torque) +
             " exceeds what friction in the nip can carry (mu |Force| R = " + brief(mu) + " x " + brief(F) +
             " x " + brief(scene.mesh.outerRadius) + " = " + brief(capacity) +
             "): there is no quasi-static equilibrium, the roller would stop and the capstan slip";
  }
  return out;
}

namespace {
// Quasi-static rolling follows the nip while the capstan's surface moves a few of its cells a step.
// The free slice's speed ratio (steps 6-20; steady rolling: 0.991) against the capstan's speed,
// in nip cells a step: 0.28 (shipped) mean 0.989, range 0.980-0.996; 0.83: 0.992, 0.990-0.994;
// 2.8: 0.998, 0.957-1.032; 8.3: 1.012, 0.996-1.067; 28: 1.064, 1.002-1.130 (docs/friction.md,
// "How fast a quasi-static roll may go").
constexpr double kMostNipCellsPerStep = 3;
}  // namespace

std::string fastRollingDiagnosis(const Scene& scene) {
  if (scene.mesh.type != MeshSpec::Type::Annulus || scene.analysis.steady()) return "";
  const auto& m = scene.mesh;
  const double cell = m.outerRadius * (M_PI / 180) * AnnulusGenerator::narrowestRingCellDegrees(m.cells[1], m.fineSector);
  std::string out;
  for (const auto& c : scene.capstans) {
    const double travel = std::fabs(c.angularVelocity) * c.radius * scene.stepSize;
    if (!(travel > kMostNipCellsPerStep * cell)) continue;
    out += std::string(out.empty() ? "" : "; ") +
           format("capstan '%s': its surface moves %.3g a step (|Angular Velocity| x Radius x Step Size), %.3g of the "
                  "annulus' narrowest cells round (%.3g wide): quasi-static rolling follows the nip to about %g "
                  "cells a step; beyond, the speed ratio strays (the slice: by 2%% at 8 cells a step, 7%% at 28): "
                  "take a smaller Time/Step Size, or Analysis/Type = Steady Rolling",
                  c.name.c_str(), travel, travel / cell, cell, kMostNipCellsPerStep);
  }
  return out;
}

std::string rollOffDiagnosis(const Scene& scene) {
  if (scene.mesh.type != MeshSpec::Type::Annulus || scene.capstans.size() != 1) return "";
  const auto& c = scene.capstans[0];
  const Vec3 a = unit(c.axisDirection);
  std::string out;
  for (const auto& s : scene.supports) {
    // Friction holds a core that does not turn; one that turns rolls, one on a capstan without
    // friction slides.
    const bool rolls = s.rotation == SupportSpec::Rotation::Free, slides = !c.friction.grips();
    if (!s.isCore() || !(rolls || slides)) continue;
    if (!(norm(cross(Vec3{s.force[0], s.force[1], s.force[2]}, a)) > 0)) continue;  // no force across the axis
    // Free in two independent directions normal to the capstan's axis: the core can move round
    // the capstan. Along one line only (the shipped rollers: y) it is held on that line.
    std::string free;
    std::vector<Vec3> normal;
    for (int i = 0; i < 3; ++i)
      if (s.freeTranslation[i]) {
        Vec3 e{i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0};
        const double along = dot(e, a);
        for (int k = 0; k < 3; ++k) e[k] -= along * a[k];
        free += char('x' + i), normal.push_back(e);
      }
    bool plane = false;
    for (size_t i = 0; i < normal.size(); ++i)
      for (size_t j = i + 1; j < normal.size(); ++j) plane = plane || norm(cross(normal[i], normal[j])) > 1e-6;
    if (!plane) continue;
    out += std::string(out.empty() ? "" : "; ") + "support '" + s.name + "': " +
           (rolls ? "free to turn" : "on a capstan without friction") + " and free along " + free +
           ", so free to move round capstan '" + c.name +
           "': pressed onto one capstan by a force of fixed direction, its only position of rest is unstable (it " +
           (rolls ? "rolls" : "slides") +
           " off the capstan, as a ball off the top of a dome), and a solve that starts beside it does not "
           "converge; hold one of " + free + " (as a pinch roller's arm keeps the roller on its arc)";
  }
  return out;
}

std::string stickChatterHint(const Scene& scene, const std::string& failure) {
  if (scene.mesh.type != MeshSpec::Type::Annulus || failure.find(kStalledLoop) == std::string::npos)
    return "";
  for (const auto& c : scene.capstans) {
    if (c.friction.law != FrictionSettings::Law::Coulomb || !c.friction.grips()) continue;
    // Points cycling between stick and slip are held in slip (docs/friction.md,
    // item 11); where the loop still stalls, these converged on the meshes
    // measured (docs/steady-rolling.md, "Stick and slip that cycle").
    const double speed = std::fabs(c.angularVelocity * c.radius);
    // Tanh's scale from the capstan's surface speed; a capstan that does not spin gives none.
    const std::string tanh = speed > 0 ? ", or Friction/Law = Tanh with Regularization " + brief(1e-3 * speed) +
                                             " (1e-3 x the capstan's surface speed),"
                                       : "";
    return "; capstan '" + c.name + "': Coulomb's stick and slip may not settle on this mesh (with --log newton, " +
           "the pressure step's contact and stick rows change from pass to pass): a nip of many fine cells over " +
           "an outer radial cell thicker than the contact's half-width makes them chatter; more radial cells " +
           "under the nip" + tanh + " converge (docs/steady-rolling.md, \"Stick and slip that cycle\")";
  }
  return "";
}

}  // namespace capstan
