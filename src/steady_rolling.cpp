#include "steady_rolling.hpp"

#include <cmath>
#include <limits>

#include "effects/steady_friction.hpp"
#include "rolling.hpp"

namespace capstan {

SteadyRolling::SteadyRolling(Model& model, Log& log, AugmentationLoop& augmentation, Predictors& predictors,
                             bool started)
    : m_(model), log_(log), augmentation_(augmentation), predictors_(predictors), started_(started) {}

bool SteadyRolling::solve(double t, StepRecord& rec, std::string& failure) {
  bool ok = true;
  if (!started_) {
    holdCores(true);
    enableFriction(false);
    predictors_.linearResponse(t, rec);
    ok = solveStage(t, "frictionless footprint", rec, failure);
    enableFriction(true);
    if (ok) ok = solveStage(t, "friction at the no-slip angular velocity", rec, failure);
    holdCores(false);
  }
  if (ok) ok = solveStage(t, "steady state", rec, failure);
  started_ = started_ || ok;
  return ok;
}

bool SteadyRolling::solveStage(double t, const char* what, StepRecord& rec, std::string& failure) {
  auto& assembly = *m_.assembly;
  assembly.applyConstraints(*m_.u, t);
  // Newton's tolerance relative to the body's force scale c L^2 (the
  // continuation's first residuals say nothing about the answer's size).
  if (log_.on("newton"))
    log_.event("newton", format("steady rolling: %s", what),
               json::Object().add("event", json::string("steady stage")).add("stage", json::string(what)));
  return augmentation_.solve(t, m_.forceScale, rec, failure);
}

void SteadyRolling::holdCores(bool hold) {
  auto& cores = m_.assembly->cores();
  for (size_t c = 0; c < cores.size(); ++c) {
    const auto& core = cores.records()[c];
    if (!core.free[3]) continue;
    cores.holdAngularVelocity(c, hold ? noSlipAngularVelocity(m_.scene, core) : std::numeric_limits<double>::quiet_NaN());
  }
}

void SteadyRolling::enableFriction(bool on) {
  for (auto* f : m_.assembly->frictions())
    if (auto* steady = dynamic_cast<SteadyFrictionEffect*>(f)) steady->setEnabled(on);
}

}  // namespace capstan
