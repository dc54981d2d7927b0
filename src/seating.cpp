#include "seating.hpp"

#include <cmath>

#include "effects/contact.hpp"

namespace capstan {

namespace {

// The one rigid core that may carry the whole body: the scene's only core, translating freely
// along some direction that no other support holds, against the scene's only capstan. With two,
// the overlaps on the contact faces cannot see a capstan the body is moved through: on the fast
// roller with a second capstan across it, the body moved 4.9 and ended with that capstan inside
// its coating (the sweep of 2026-12-07). -1 where there is none.
int seatableCore(const Model& m) {
  const auto& cores = m.assembly->rigidCores();
  if (cores.size() != 1 || m.assembly->contacts().size() != 1) return -1;
  const auto& core = cores[0];
  if (!(core.free[0] || core.free[1] || core.free[2])) return -1;
  for (const auto& s : m.scene.supports)
    if (!s.isCore())
      for (int i = 0; i < 3; ++i)
        if (s.components[i] && core.free[i]) return -1;
  return 0;
}

// The capstan's largest overlap with the body at u (collective), and its force on the body.
double largestOverlap(Model& m, const Vector& u, std::array<double, 3>* forceOnBody = nullptr) {
  m.assembly->evaluate(u, nullptr, nullptr);
  const auto fig = m.assembly->contacts()[0]->figures({0, 0, 0});
  double local[4] = {fig.maxPenetration, -fig.force[0], -fig.force[1], -fig.force[2]};
  double overlap = 0, force[3];
  Teuchos::reduceAll(*m.comm, Teuchos::REDUCE_MAX, local[0], Teuchos::outArg(overlap));
  Teuchos::reduceAll(*m.comm, Teuchos::REDUCE_SUM, 3, local + 1, force);
  if (forceOnBody) *forceOnBody = {force[0], force[1], force[2]};
  return overlap;
}

}  // namespace

double seatFreeCore(Model& m, Log& log, double t, double bare) {
  const int c = seatableCore(m);
  if (c < 0) return 0;
  auto& assembly = *m.assembly;
  const double edge = assembly.contacts()[0]->shortestEdge();
  std::array<double, 3> force{};
  const double overlap = largestOverlap(m, *m.u, &force);
  if (!(overlap > kSeatingOverlap * edge)) return 0;
  // Along the capstan's push on the body, within the core's free directions.
  std::array<double, 3> n{};
  double length = 0;
  for (int i = 0; i < 3; ++i) n[i] = assembly.rigidCores()[c].free[i] ? force[i] : 0.0, length += n[i] * n[i];
  length = std::sqrt(length);
  if (!(length > 0)) return 0;
  for (double& x : n) x /= length;
  const double target = kSeatedOverlap * edge;
  auto moved = [&](double d) {
    Vector trial(*m.u, Teuchos::Copy);
    assembly.translateWithCore(trial, size_t(c), {d * n[0], d * n[1], d * n[2]});
    assembly.applyConstraints(trial, t);
    return trial;
  };
  // Bracket the translation that leaves the target overlap, then bisect: the overlap falls as the
  // body moves away. A move longer than 4x the overlap (the push 75 degrees or more off the
  // capstan's normal) is no seating: none.
  double lo = 0, hi = overlap - target;
  while (largestOverlap(m, moved(hi)) > target) {
    lo = hi, hi *= 2;
    if (hi > 4 * overlap) return 0;
  }
  for (int k = 0; k < 40 && hi - lo > 1e-3 * target; ++k) {
    const double mid = 0.5 * (lo + hi);
    (largestOverlap(m, moved(mid)) > target ? lo : hi) = mid;
  }
  Vector seated = moved(hi);
  Vector f(m.u->getMap());
  assembly.evaluate(seated, &f, nullptr);
  const double residual = f.norm2();
  const bool kept = residual < bare;
  log.event("newton",
            format("seated: the body moved %.4g with its core (overlap %.3g down to %.3g, |R| %.3e, bare %.3e)%s", hi,
                   overlap, target, residual, bare, kept ? "" : ": not kept"),
            json::Object().add("event", json::string("seating")).add("translation", json::number(hi))
                .add("overlap", json::number(overlap)).add("residual", json::number(residual))
                .add("kept", kept ? "true" : "false"));
  if (!kept) return 0;
  m.u->update(1.0, seated, 0.0);
  return hi;
}

}  // namespace capstan
