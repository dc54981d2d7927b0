#include "regularisation_continuation.hpp"

#include <algorithm>
#include <cmath>

#include "effects/friction.hpp"

namespace capstan {

RegularisationContinuation::RegularisationContinuation(const std::vector<FrictionEffect*>& frictions, Log& log)
    : log_(log) {
  double ratio = 0;  // every rank holds every capstan's effect (maybe with no faces)
  for (auto* f : frictions)
    if (f && f->travelOverSlipScale() > 0) {
      frictions_.push_back(f);
      ratio = std::max(ratio, f->travelOverSlipScale());
    }
  // 3^K about a third of the travel over v.
  if (ratio > 9) stages_ = int(std::ceil(std::log(ratio / 3) / std::log(3.0)));
}

void RegularisationContinuation::setScale(double scale) {
  for (auto* f : frictions_) f->setRegularisationScale(scale);
}

// The short sequence's first power (see the header).
constexpr int kShortSequence = 2;

NewtonResult RegularisationContinuation::solve(NewtonSolver& newton, Vector& u, double tolerance) {
  NewtonResult total;
  const Vector start(u, Teuchos::Copy);
  bool converged = sequence(newton, u, tolerance, std::min(kShortSequence, stages_), total);
  if (!converged && stages_ > kShortSequence) {
    u.update(1.0, start, 0.0);
    converged = sequence(newton, u, tolerance, stages_, total);
  }
  setScale(1.0);
  total.converged = converged;
  if (!converged) total.failure = "continuation in the friction regularisation failed: " + total.failure;
  return total;
}

bool RegularisationContinuation::sequence(NewtonSolver& newton, Vector& u, double tolerance, int first,
                                          NewtonResult& total) {
  for (int k = first; k >= 0; --k) {
    setScale(std::pow(3.0, k));
    const NewtonResult r = newton.solve(u, tolerance);
    if (log_.on("newton"))
      log_.event("newton", format("regularisation x 3^%d: %s in %d Newton iterations, |R| %.3e", k,
                                  r.converged ? "converged" : "failed", r.iterations, r.residualNorm),
                 json::Object().add("event", json::string("regularisation_stage")).add("power", json::number(k))
                     .add("converged", r.converged ? "true" : "false")
                     .add("iterations", json::number(r.iterations)));
    total.iterations += r.iterations;
    total.linearIterations += r.linearIterations;
    total.residualHistory.insert(total.residualHistory.end(), r.residualHistory.begin(), r.residualHistory.end());
    total.residualNorm = r.residualNorm;
    total.failure = r.failure;
    if (!r.converged) return false;
  }
  return true;
}

}  // namespace capstan
