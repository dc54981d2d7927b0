#include "steady_rolling.hpp"

#include <cmath>
#include <limits>

#include "effects/steady_friction.hpp"
#include "rolling.hpp"

namespace capstan {

namespace {
// The first friction solve from rest crawls: Newton's steps under the exact
// stick (eps_t the contact's solve penalty) are cut to 1/128-1/4 while points
// switch between stick and slip. With eps_t 10x larger for that stage only,
// the 3D drive takes 17 Newton iterations there against 38 (58 in all against
// 79), the slice 22 against 28, the Carter coating 20 against 32, the first
// step of the drive's brake sweep 52 against 72; 3, 5, 7, 15, 20, 30 and 100
// gave the drive 68, 64, 64, 77, 97, 107 and 84 (a softer stick takes more
// multiplier passes). The free roller's solve, at the scene's eps_t, ends
// where it did (the drive's omega within 4e-9; at mu = 2 on the 4x64 slice
// 6e-7 from the answer at a 1e-9 penetration tolerance, against 2.6e-5).
constexpr double kFirstFrictionSoftening = 10;
}  // namespace

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
    // Coulomb's stick kFirstFrictionSoftening x softer while friction first
    // engages, the scene's own again for the free roller's solve.
    setStickSoftening(kFirstFrictionSoftening);
    if (ok) ok = solveStage(t, "friction at the no-slip angular velocity", rec, failure);
    setStickSoftening(1);
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

void SteadyRolling::setStickSoftening(double factor) {
  for (auto* f : m_.assembly->frictions())
    if (f) f->setTangentPenaltyScale(factor);
}

void SteadyRolling::enableFriction(bool on) {
  for (auto* f : m_.assembly->frictions())
    if (auto* steady = dynamic_cast<SteadyFrictionEffect*>(f)) steady->setEnabled(on);
}

}  // namespace capstan
