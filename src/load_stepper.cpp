#include "load_stepper.hpp"

#include <algorithm>

#include "effect_state.hpp"
#include "rolling.hpp"
#include "solver_switches.hpp"

namespace capstan {

namespace {
// The smallest sub-step, as a fraction of Time/Step Size (in steady rolling, of
// the loads' ramp left at the step's start where that is shorter): ten halvings.
constexpr double kMinimumSubstep = 1.0 / 1024;
// Coulomb goes on in pseudo-time while points stick only in sub-steps up to this fraction of the
// step: the answer then depends on the path, and pseudo-time strays from it by about the sub-step
// (docs/friction.md, "G1 dragged by a turning capstan: pseudo-time in short sub-steps").
constexpr double kPseudoTimeWithStickSubstep = 1.0 / 8;
// Cuts in one step before it fails: sub-steps that pass at one size and fail at twice it would
// creep on; ten halvings reach the smallest sub-step, and converging runs need far fewer cuts
// (docs/numerics.md, "Load steps").
constexpr int kMostCutsPerStep = 40;
// A braked roller whose surface moves at under this fraction of the capstan's while every contact
// point slips stands: friction is at its limit everywhere, so the rotation is free and the brake
// is held by the mesh, not the nip (the braked slice on 4x40 cells at 1.35 N mm: speed ratio 0
// through steps 3-20 at exit 0, where 4x64 and 8x128 end with exit 2; docs/pinch-roller.md).
constexpr double kStalledSpeedRatio = 1e-3;

// How long after t the first of the cores' external loads (forces, torques) still ramping is
// in: 0 once all are. A cut halves that span, so the load that comes in first eases first: with
// a brake ramped over the whole step and the force over 1e-6, cuts within the brake's ramp left
// the force whole, and a footprint that needed a lighter one failed through every cut (the
// sweep's slice on a capstan of radius 1: exit 2; without the brake's ramp it converged).
double loadRampLeft(const Assembly& assembly, double t) {
  double left = 0;
  auto first = [&](double rampTime) {
    if (rampTime > t && (left == 0 || rampTime - t < left)) left = rampTime - t;
  };
  for (const auto& core : assembly.rigidCores()) {
    const bool force = core.force[0] != 0 || core.force[1] != 0 || core.force[2] != 0;
    if (force) first(core.rampTime);
    if (core.torque != 0) first(core.torqueRampTime);
  }
  return left;
}
}  // namespace

LoadStepper::LoadStepper(Model& model, Log& log, bool checkTangent, double tDone)
    : m_(model), log_(log), predictors_(model, log), augmentation_(model, log, checkTangent),
      steady_(model, log, augmentation_, predictors_, tDone > 0), tDone_(tDone) {}

bool LoadStepper::solveIncrement(double t0, double t1, const std::vector<double>& rotations, StepRecord& rec,
                                  std::string& failure) {
  m_.assembly->setInterval(t0, t1);
  if (m_.scene.analysis.steady()) return steady_.solve(t1, rec, failure);
  const double bare = predictors_.firstGuess(t0, t1, rec);
  if (!augmentation_.solve(t1, bare, rec, failure)) return false;
  failure = brakedRollerStalled(rotations, t1 - t0);
  return failure.empty();
}

std::string LoadStepper::brakedRollerStalled(const std::vector<double>& rotations, double dt) {
  const auto& cores = m_.assembly->rigidCores();
  for (size_t c = 0; c < cores.size(); ++c) {
    const auto& core = cores[c];
    if (!core.free[3] || core.holding() || core.torque == 0) continue;
    const double ratio = speedRatio(m_.scene, core, (core.rotation - rotations[c]) / dt);
    if (!(ratio < kStalledSpeedRatio) || !augmentation_.everyPointSlips()) continue;
    return format("support '%s': the braked roller stands or turns back (speed ratio %.4g over the increment) while "
                  "every contact point slips: the nip does not carry the brake (the mesh's normal forces off the line "
                  "of centres take up the rest)",
                  core.name.c_str(), ratio);
  }
  return "";
}

bool LoadStepper::advance(StepRecord& rec, std::string& failure) {
  auto& assembly = *m_.assembly;
  const auto& effects = assembly.effects();
  const double dt = m_.scene.stepSize;
  const bool steady = m_.scene.analysis.steady();
  // Steady rolling halves the loads' span instead of the step where they ramp
  // within it (below).
  const double rampAtStart = steady ? loadRampLeft(assembly, tDone_) : 0;
  const double minimumSubstep = kMinimumSubstep * (rampAtStart > 0 ? std::min(dt, rampAtStart) : dt);
  // A reused preconditioner starts each step afresh, so a run restarted at
  // any step repeats the uninterrupted run's arithmetic exactly.
  m_.newton->rebuildPreconditioner();
  double h = rec.time - tDone_;
  // The step's start: a failed step's converged sub-steps are not outputs.
  const auto atStep = m_.snapshot();
  const double tStep = tDone_;
  const bool andersonMayFail = !m_.pressureStep && m_.scene.solver.saddlePointIfAndersonFails;
  const auto predictorsAtStep = andersonMayFail ? predictors_.memory() : Predictors::Memory{};
  int cutsBefore = 0;  // the cuts of a failed Anderson try (below)
  while (tDone_ < rec.time - 1e-12 * dt) {
    const double tEnd = std::min(tDone_ + h, rec.time);
    // The cores' records from u: a failed attempt left them at its last trial,
    // and the rotations saved here give the next sub-step's turn (Predictors).
    assembly.applyConstraints(*m_.u, tDone_);
    const auto saved = m_.snapshot();
    std::vector<double> rotationsSaved;
    for (const auto& core : assembly.rigidCores()) rotationsSaved.push_back(core.rotation);
    std::string why;
    augmentation_.allowPseudoTimeWithStick(!steady && tEnd - tDone_ <= kPseudoTimeWithStickSubstep * dt * (1 + 1e-12));
    if (solveIncrement(tDone_, tEnd, rotationsSaved, rec, why)) {
      predictors_.remember(saved.u, tDone_, rotationsSaved);
      tDone_ = tEnd;
      // History (friction) moves on to this converged state; the step's
      // last sub-step commits after the step's figures are taken, which
      // belong to the increment that just converged.
      if (tDone_ < rec.time - 1e-12 * dt)
        for (const auto& e : effects) e->commit(assembly.positions());
      h = std::min(2 * h, rec.time - tDone_);
      continue;
    }
    m_.restore(saved);
    ++rec.cutbacks;
    h /= 2;
    // A steady state depends on the time only through the loads: a cut is a
    // continuation in them, so a sub-step ends before they are all in (the
    // steady drive pressed 8x harder than shipped, its force ramped in 1e-6 s
    // of a 1e-3 s step: half the force first; docs/steady-rolling.md).
    const double rampLeft = steady ? loadRampLeft(assembly, tDone_) : 0;
    if (rampLeft > 0 && h >= rampLeft) h = rampLeft / 2;
    const bool lastTry = h < minimumSubstep || rec.cutbacks - cutsBefore > kMostCutsPerStep;
    if (!lastTry) {
      // How much of the step is done: a run of cuts to the same dt is then seen to advance. (After
      // the last try the failure speaks instead: no cut it would not take.)
      log_.progress(format("  step %d, %.3g of it done: cut back to dt = %.4g (%s)", rec.step,
                           (tDone_ - tStep) / (rec.time - tStep), h, why.c_str()));
      const std::string hint = chatterHinted_ ? std::string() : stickChatterHint(m_.scene, why);
      if (!hint.empty()) {
        chatterHinted_ = true;  // once a run: the hint, before the cuts' retries
        log_.progress("  " + hint.substr(2));
      }
    }
    if (lastTry && andersonMayFail && !m_.pressureStep) {
      // Auto's Anderson loop failed the step through every cut, where the saddle-point step can
      // converge (a soft stick: docs/numerics.md): the step again with it, kept from here on.
      m_.buildPressureStep();
      solver_switches::note(format("the saddle-point pressure step (the Anderson loop failed the step through %d cuts)",
                                   rec.cutbacks));
      log_.progress(format("  step %d: the Anderson loop failed through %d cuts (%s); the step again with the "
                           "saddle-point pressure step, kept from here on",
                           rec.step, rec.cutbacks, why.c_str()));
      m_.restore(atStep);
      predictors_.recall(predictorsAtStep);
      tDone_ = tStep;
      h = rec.time - tDone_;
      cutsBefore = rec.cutbacks;
      continue;
    }
    if (lastTry) {
      failure = "step " + std::to_string(rec.step) +
                (h < minimumSubstep ? format(" failed at minimum step size %.4g", minimumSubstep)
                                    : format(" failed after %d cuts, %.3g of its %.3g done", rec.cutbacks,
                                             tDone_ - tStep, rec.time - tStep)) +
                ": " + why + brakeDiagnosis(m_.scene) + stickChatterHint(m_.scene, why);
      if (const std::string rollOff = rollOffDiagnosis(m_.scene); !rollOff.empty()) failure += "; " + rollOff;
      m_.restore(atStep);
      tDone_ = tStep;
      assembly.setInterval(tDone_, tDone_);
      return false;
    }
  }
  assembly.applyConstraints(*m_.u, tDone_);  // rigid cores' face nodes where the cores are
  Vector f(m_.u->getMap());
  assembly.evaluate(*m_.u, &f, nullptr);  // reactions at the converged state
  return true;
}

}  // namespace capstan
