#include "rolling.hpp"

#include <cmath>

#include "assembly.hpp"
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

std::string brakeDiagnosis(const Scene& scene) {
  std::string out;
  if (scene.mesh.type != MeshSpec::Type::Annulus) return out;
  for (const auto& s : scene.supports) {
    if (!s.isCore() || s.rotation != SupportSpec::Rotation::Free || s.torque == 0) continue;
    // Friction at most mu |t_n| everywhere, at most the outer radius from the
    // axis: the nip carries at most sum mu |F| R_outer about the core's axis.
    const double F = norm(s.force);
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

}  // namespace capstan
