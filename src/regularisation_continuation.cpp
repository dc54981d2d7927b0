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
    } else if (f && f->exactCorner()) {
      corners_.push_back(f);
    }
  // 3^K about a third of the travel over v.
  if (ratio > 9) stages_ = int(std::ceil(std::log(ratio / 3) / std::log(3.0)));
}

bool RegularisationContinuation::canRetry() const {
  const auto acting = [](const FrictionEffect* f) { return f->acting(); };
  if (stages_ > 0) return std::any_of(frictions_.begin(), frictions_.end(), acting);
  return std::any_of(corners_.begin(), corners_.end(),
                     [](const FrictionEffect* f) { return f->acting() && f->exactCorner(); });
}

void RegularisationContinuation::setScale(double scale) {
  for (auto* f : frictions_) f->setRegularisationScale(scale);
}

// The short sequence's first power (see the header).
constexpr int kShortSequence = 2;
// The smoothed corner's width (Friction/Smoothing) for Coulomb's retry: 1e-2
// took the 18 fast rollers (docs/friction.md) from 24 cuts to 9.
constexpr double kCornerSmoothing = 1e-2;

NewtonResult RegularisationContinuation::solve(NewtonSolver& newton, Vector& u, double tolerance) {
  NewtonResult total;
  if (stages_ == 0) {
    total.converged = cornerSequence(newton, u, tolerance, total);
    if (!total.converged) total.failure = "continuation through a smoothed stick/slip corner failed: " + total.failure;
    return total;
  }
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
    if (!stage(newton, u, tolerance, format("regularisation x 3^%d", k), k, total)) return false;
  }
  return true;
}

bool RegularisationContinuation::cornerSequence(NewtonSolver& newton, Vector& u, double tolerance,
                                                NewtonResult& total) {
  for (auto* f : corners_) f->setCornerSmoothing(kCornerSmoothing);
  const bool smoothed = stage(newton, u, tolerance, format("stick/slip corner smoothed by %g", kCornerSmoothing),
                              -1, total);
  for (auto* f : corners_) f->setCornerSmoothing(0);
  return smoothed && stage(newton, u, tolerance, "exact stick/slip corner", -1, total);
}

bool RegularisationContinuation::stage(NewtonSolver& newton, Vector& u, double tolerance, const std::string& what,
                                       int power, NewtonResult& total) {
  const NewtonResult r = newton.solve(u, tolerance);
  if (log_.on("newton")) {
    auto event = json::Object().add("event", json::string("regularisation_stage")).add("stage", json::string(what));
    if (power >= 0) event.add("power", json::number(power));
    log_.event("newton", format("%s: %s in %d Newton iterations, |R| %.3e", what.c_str(),
                                r.converged ? "converged" : "failed", r.iterations, r.residualNorm),
               event.add("converged", r.converged ? "true" : "false").add("iterations", json::number(r.iterations)));
  }
  total.iterations += r.iterations;
  total.linearIterations += r.linearIterations;
  total.residualHistory.insert(total.residualHistory.end(), r.residualHistory.begin(), r.residualHistory.end());
  total.residualNorm = r.residualNorm;
  total.failure = r.failure;
  return r.converged;
}

}  // namespace capstan
