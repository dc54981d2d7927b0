#include "augmentation.hpp"

#include "effects/contact.hpp"
#include "errors.hpp"
#include "solver_switches.hpp"
#include "stopwatch.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

namespace capstan {

namespace {

// The saddle-point pressure step's GMRES tolerance (relative): the volume
// error then falls about 1000x per pass in the linear regime.
constexpr double kPressureStepTolerance = 1e-3;
// ... and the volume error it aims to leave, as a fraction of the volume
// tolerance: the pass it ends is then the last.
constexpr double kPressureStepVolumeMargin = 0.3;
// Passes after the first start below the step's tolerance: x must still
// respond to the new multipliers, so they reduce the residual by this factor
// (one Newton iteration, usually). 1e-6 took two and gave the same answer;
// 1e-2 is too loose and the pressure loop stalls (docs/numerics.md).
constexpr double kLaterPassReduction = 1e-4;
// With the saddle-point step, a later pass starting below this x Newton's
// tolerance gets one Newton step (AugmentationLoop::polish). 10 and 100 gave
// the 3D drive the same 578 Newton iterations over 20 steps; 1 gave 631, the
// absolute tolerance 656 (docs/friction.md).
constexpr double kPolishBelow = 10;
// A starting guess (solve's passLimit: steady rolling's footprint and Tanh stages) needs Newton
// only to this x r0 where its solves are direct: each stage's last quadratic iteration changes
// nothing the next stage keeps (docs/steady-rolling.md, "Start from rest").
constexpr double kGuessTolerance = 1e-7;
// A capstan cutting a contact face deeper than the contact points' own penetration plus this
// fraction of the face's longest edge h (or half its radius R), between the face's points, has
// passed into the body or fits between the points: a touching face's sagitta h^2 / 8R reaches
// either only where h > 2R. A body node that deep beyond the points (by this fraction of the
// shortest edge) is inside it (AugmentationLoop::bodyThroughCapstan).
constexpr double kCutFraction = 0.25;
// A saddle-point step is halved (to kShortestPressureStep at most) while the residual it leaves
// exceeds kPressureStepMerit x its starting one: its linear model holds only while no point
// crosses between stick, slip and free (docs/friction.md, "The multiplier loop in rolling").
constexpr double kPressureStepMerit = 1;
constexpr double kShortestPressureStep = 1.0 / 16;
// Pressure Update = Monolithic: the step is Newton's, so it is solved closer than the nested
// loop's 1e-3; tighter costs more Krylov iterations than the passes it saves
// (docs/numerics.md, "The pressure loop").
constexpr double kMonolithicStepTolerance = 1e-4;
// With the saddle-point step the constraints fall fast from pass to pass; a loop whose worst
// constraint (over its tolerance) has not come below its best for this many passes is failing,
// and its retry is cheaper (docs/numerics.md, "A loop that stalls fails early").
constexpr int kStallPasses = 10;
// Points cycling between stick and slip (FrictionEffect::notePass) are held in
// slip once the worst constraint has not come below its best for this many
// passes (docs/steady-rolling.md, "Stick and slip that cycle").
constexpr int kHoldAfterPasses = 3;
// The last resort, once it has not for this many (of kStallPasses): every point whose state
// changed four times or more is held in slip too, as fine nips' chatter is no 2-cycle; sooner,
// it held loops about to converge (docs/friction.md, "The multiplier loop in rolling").
constexpr int kHoldAnyAfterPasses = 6;
// And once it has not for this many, every point's state is frozen (FrictionEffect::notePass:
// in stick until its traction leaves the cone, then in slip) and the stall test counts afresh:
// states that move one way only settle (docs/friction.md, "The multiplier loop in rolling").
constexpr int kFreezeAfterPasses = 8;
// Frozen, the loop goes on while its worst constraint falls at least kFrozenGain-fold over each
// kFrozenWindow passes, for at most kFrozenPasses: finer nips need more than 10 frozen passes,
// and a loop stalled otherwise creeps (docs/friction.md, "The multiplier loop in rolling").
constexpr int kFrozenWindow = 5;
constexpr double kFrozenGain = 2;
constexpr int kFrozenPasses = 30;

json::Object eventOf(const char* name) { return json::Object().add("event", json::string(name)); }

}  // namespace

AugmentationLoop::AugmentationLoop(Model& model, Log& log, bool checkTangent)
    : m_(model), log_(log), checkTangent_(checkTangent), continuation_(model.assembly->frictionsPresent(), log) {}

bool AugmentationLoop::solve(double t, double bare, StepRecord& rec, std::string& failure, int passLimit) {
  if (solveOnce(t, bare, rec, failure, passLimit)) return true;
  // The factored block matrix makes each saddle-point step exact; where the
  // loop fails with it anyway (the steady drive at 3x180x8: its frozen passes
  // stalled, and cut after cut followed), the caller's retries go on with the
  // block-triangular step, which converged there (docs/numerics.md).
  if (m_.pressureStep && m_.pressureStep->factorsBlockMatrix()) {
    m_.pressureStep->useBlockPreconditioner();
    solver_switches::note("the block-triangular pressure step (the loop failed with the factored block matrix)");
    if (log_.on("newton"))
      log_.event("newton", "the loop failed with the factored block matrix: the block-triangular step from here on",
                 eventOf("pressure_step_block_from_here"));
  }
  return false;
}

bool AugmentationLoop::solveOnce(double t, double bare, StepRecord& rec, std::string& failure, int passLimit) {
  const auto& sol = m_.scene.solver;
  if (checkTangent_) checkTangent();
  // r0 is capped by the body's force scale c L^2: with a small penalty the bare
  // increment's residual is huge (volume error / eps), and a tolerance relative
  // to it would accept a poorly converged state.
  const double r0 = std::min(bare, m_.forceScale);
  double tol = std::max(sol.newtonRelativeTolerance * r0, m_.absTolerance);
  if (passLimit > 0 && m_.newton->direct()) tol = std::max(tol, kGuessTolerance * r0);  // a starting guess
  int maxOuter = sol.maxPressureIterations;
  for (const auto& e : m_.assembly->effects()) maxOuter = std::max(maxOuter, e->maxAugmentations());
  AndersonMixing mixing(sol.pressureAccelerationDepth, m_.comm);
  PassPolicy passes(m_.monolithic);
  for (auto* fr : m_.assembly->frictionsPresent()) fr->releaseHeldSlips();  // a new solve: every point free
  frozen_ = false;
  std::optional<StepStart> beforeStep;
  Vector f(m_.u->getMap());
  double lastWorst = 0;       // the last pass's worst constraint, for the failure
  std::string lastWorstName;
  for (int it = 1; it <= maxOuter; ++it) {
    const Pass pass = startPass(it, tol, passes, f);
    const NewtonResult r = solvePositions(t, pass, beforeStep.has_value(), rec);
    // A later pass may start below what round-off lets Newton reach; a state
    // within the absolute tolerance is as converged as it gets.
    if (!r.converged && !(it > 1 && r.residualNorm <= m_.absTolerance)) {
      if (beforeStep) {
        // The saddle-point step's linear model broke down (stick and slip
        // change over it near the traction limit): back to where it started,
        // with the plain update instead, rather than a cut step.
        if (log_.on("newton"))
          log_.event("newton", format("newton failed (%s) after the pressure step: a plain pass from before it",
                                      r.failure.c_str()),
                     eventOf("pressure_step_undone").add("failed_iterations", json::number(r.iterations)));
        m_.restore(beforeStep->at);
        setMultipliers(m_.assembly->effects(), beforeStep->pressureNext, true);
        // The kept preconditioner was factored in the failed solve, far from here: the
        // next pressure step's GMRES ran to its limit on it (the Hertz ring pressed 400x).
        m_.newton->rebuildPreconditioner();
        beforeStep.reset();
        continue;
      }
      if (checkTangent_) checkTangent();
      failure = r.failure;
      return false;
    }
    beforeStep.reset();
    // Refresh p(x), v, contact pressures at the converged state.
    m_.assembly->evaluate(*m_.u, &f, nullptr);
    if (holdCyclingSlips(it)) m_.assembly->evaluate(*m_.u, &f, nullptr);  // the held points' tractions
    Constraints c;
    if (!checkConstraints(it, rec, c, failure)) return false;
    lastWorst = c.worst, lastWorstName = c.worstName;
    // Constraints met: the momentum residual left is Newton's to remove, down
    // to round-off as the nested loop's last pass does (one polishing step
    // within the tolerance), so the two loops' answers agree to round-off.
    if (c.met && pass.stepAlone && pass.start > m_.absTolerance) {
      passes.newtonNext();
      continue;
    }
    if (c.met) {
      rec.statesFrozen = frozen_ ? 1 : 0;
      return true;
    }
    if (stalled(it, c, failure)) return false;
    if (m_.pressureStep) {
      moveByPressureStep(t, f, c, pass.stepAlone, passes, beforeStep, rec);
    } else {
      const auto& effects = m_.assembly->effects();
      setMultipliers(effects, mixing.next(multipliers(effects, true), multiplierMap(effects, true)), true);
      // Rolling: contact and friction multipliers within their tolerance stay put, since points
      // flickering at the tolerance would keep changing the mixing's map and stall it; elsewhere
      // every multiplier moves each pass (a symmetric problem then stays symmetric to round-off).
      setMultipliers(effects, multiplierMap(effects, false), false, c.settled);
    }
    if (passLimit > 0 && it >= passLimit) return true;  // a starting guess: the moved state
  }
  failure = format("augmentation loop did not meet the volume and contact tolerances in %d passes: %s at %.3g x its "
                   "tolerance at the last", maxOuter, lastWorstName.c_str(), lastWorst);
  return false;
}

bool AugmentationLoop::holdCyclingSlips(int it) {
  // Only once the loop has stopped gaining: early passes move the stick zone's
  // edge back and forth on their way (the 3D drive at 3x160x8 converges so;
  // holding its edge node there moved the speed ratio by 7e-5).
  const bool mayHold = it - bestPass_ >= kHoldAfterPasses;
  // Freezing is friction's last resort: a scene without it has nothing to
  // freeze, and its loop keeps the plain stall test (kStallPasses).
  const auto& frictions = m_.assembly->frictionsPresent();
  const bool freezeNow = !frictions.empty() && !frozen_ && it - bestPass_ >= kFreezeAfterPasses;
  int local = 0, any = 0;
  for (auto* fr : frictions)
    if (fr->notePass(mayHold, it - bestPass_ >= kHoldAnyAfterPasses, frozen_ || freezeNow)) local = 1;
  Teuchos::reduceAll(*m_.comm, Teuchos::REDUCE_MAX, local, Teuchos::outArg(any));
  if (freezeNow) {
    frozen_ = true, frozenAt_ = it, frozenWorst_.clear();
    bestWorst_ = std::numeric_limits<double>::infinity();  // the stall test from this pass
    if (log_.on("newton"))
      log_.event("newton", format("pass %d: stick and slip frozen (stick until the cone, then slip)", it),
                 eventOf("states_frozen"));
  }
  if (!any) return false;
  long mine = 0, all = 0;
  for (auto* fr : frictions) mine += fr->heldPoints();
  Teuchos::reduceAll(*m_.comm, Teuchos::REDUCE_SUM, mine, Teuchos::outArg(all));
  if (log_.on("newton"))
    log_.event("newton", format("pass %d: %ld points held (cycling between stick and slip, or frozen)", it, all),
               eventOf("held_slips").add("points", json::number(double(all))));
  return true;
}

bool AugmentationLoop::stalled(int it, const Constraints& c, std::string& failure) {
  if (it == 1 || c.worst < bestWorst_) bestWorst_ = c.worst, bestPass_ = it;
  if (!m_.pressureStep) return false;
  if (frozen_) {
    frozenWorst_.push_back(c.worst);  // one per pass checked since the freeze
    const int k = it - frozenAt_, m = int(frozenWorst_.size()) - 1;
    const bool slow = m >= kFrozenWindow && c.worst > frozenWorst_[m - kFrozenWindow] / kFrozenGain;
    if (slow || k >= kFrozenPasses) {
      failure = format("%s: %s at %.3g x its tolerance %d passes after stick and slip were frozen%s", kStalledLoop,
                       c.worstName.c_str(), c.worst, k, slow ? format(", not %gx below it %d passes before", kFrozenGain,
                                                                       kFrozenWindow).c_str() : "");
      return true;
    }
  }
  if (it - bestPass_ < kStallPasses) return false;
  failure = format("%s: %s at %.3g x its tolerance, not below pass %d's %.3g x in %d passes", kStalledLoop,
                   c.worstName.c_str(), c.worst, bestPass_, bestWorst_, kStallPasses);
  return true;
}

AugmentationLoop::Pass AugmentationLoop::startPass(int it, double tol, PassPolicy& passes, Vector& f) {
  Pass pass;
  pass.number = it;
  pass.stepAlone = passes.stepAlone(it);
  pass.tolerance = tol;
  if (it == 1 && !pass.stepAlone) return pass;
  const bool valid = m_.assembly->evaluate(*m_.u, &f, nullptr);
  pass.start = f.norm2();
  // A state no step can start from (an inverted brick): Newton's to fail.
  pass.stepAlone = pass.stepAlone && valid && std::isfinite(pass.start);
  // Later passes: down to round-off, 1e-3 x the absolute tolerance.
  pass.tolerance = std::max(std::min(tol, kLaterPassReduction * pass.start), 1e-3 * m_.absTolerance);
  // Nor below a steep friction law's round-off where it passes the body's
  // (FrictionEffect::residualRoundOff): G1 under Tanh at eps3 = 1e-6 stalled
  // at |R| 1e-10 to 1e-9 against 5e-12 and ended with exit 2; with its
  // round-off (2.7e-9-3.8e-9) it converges.
  for (auto* fr : m_.assembly->frictionsPresent()) {
    const double roundOff = fr->residualRoundOff(*m_.comm);
    if (roundOff > m_.absTolerance) pass.tolerance = std::max(pass.tolerance, roundOff);
  }
  // A later pass starting near Newton's tolerance gets one polishing Newton step, as a full
  // solve stagnates at round-off; Anderson's mixing needs its map at converged states, so there
  // only within the absolute tolerance (docs/friction.md, "The multiplier loop in rolling").
  const double polishBelow = m_.pressureStep ? kPolishBelow * tol : m_.absTolerance;
  pass.polish = !pass.stepAlone && it > 1 && pass.start <= polishBelow;
  return pass;
}

NewtonResult AugmentationLoop::solvePositions(double t, const Pass& pass, bool afterStep, StepRecord& rec) {
  const auto solveStart = Clock::now();
  NewtonResult r;
  if (pass.stepAlone) {
    r.converged = true, r.residualNorm = pass.start, r.residualHistory = {pass.start};
  } else {
    // The solve's start, for a retry through wider friction laws or a smoothed
    // stick/slip corner, and in pseudo-time (only kept where there is one: the
    // steady start's regularised laws too, where a scene's Coulomb has its own
    // smoothed corner and no retry).
    const bool retries = continuation_.applies() || pseudoTimeOnRegularised_;
    const RCP<Vector> start = retries ? rcp(new Vector(*m_.u, Teuchos::Copy)) : Teuchos::null;
    r = pass.polish ? polish(t, pass.start) : m_.newton->solve(*m_.u, pass.tolerance);
    // Neither retry after a saddle-point step: undoing the step is the remedy
    // there (solve()). The steady drive under Tanh, eps3 = 1e-4, ran the whole
    // continuation after one (11 stages, about 130 Newton iterations, and it
    // failed), where the undone step's plain pass converged in 1.
    if (!r.converged && continuation_.canRetry() && (cornerRetry_ || continuation_.regularised()) && !afterStep) {
      if (log_.on("newton"))
        log_.event("newton", continuation_.regularised()
                                 ? format("newton failed (%s) in %d iterations: continuation in the friction "
                                          "regularisation, %d stages", r.failure.c_str(), r.iterations, continuation_.stages())
                                 : format("newton failed (%s) in %d iterations: again through a smoothed stick/slip corner",
                                          r.failure.c_str(), r.iterations),
                   eventOf("continuation").add("failed_iterations", json::number(r.iterations)));
      rec.newton += r.iterations;
      rec.linear += r.linearIterations;
      m_.u->update(1.0, *start, 0.0);
      r = continuation_.solve(*m_.newton, *m_.u, pass.tolerance);
    }
    // Where the retry failed too, before a cut: again in pseudo-time, past the |R| minimum that
    // stops the line search; Coulomb only where all slip or in a cut's short sub-steps, where the
    // path matters less (docs/friction.md, "What step 2 is, and the fallback for Tanh and Arctan").
    // Where no point sticks the answer does not depend on the path, and pseudo-time's steps may
    // grow as fast as |R| falls; where points stick they follow the path, doubling. Regularised
    // laws in Coulomb's place (steady rolling's start) only where the caller allows it.
    const bool again = !r.converged && !(pass.number > 1 && r.residualNorm <= m_.absTolerance) && !afterStep;
    const bool pathFree =
        again && (continuation_.regularised() || (pseudoTimeOnRegularised_ && lawsRegularisedNow()) ||
                  (continuation_.applies() && everyPointSlips()));
    if (again && (pathFree || (continuation_.applies() && pseudoTimeWithStick_))) {
      if (log_.on("newton"))
        log_.event("newton", format("newton failed (%s) in %d iterations: pseudo-transient continuation",
                                    r.failure.c_str(), r.iterations),
                   eventOf("pseudo_transient").add("failed_iterations", json::number(r.iterations)));
      rec.newton += r.iterations;
      rec.linear += r.linearIterations;
      m_.u->update(1.0, *start, 0.0);
      r = m_.newton->pseudoTransient(*m_.u, pass.tolerance, pathFree);
      if (log_.on("newton"))
        log_.event("newton", format("pseudo-transient continuation: %s in %d iterations, |R| %.3e",
                                    r.converged ? "converged" : "failed", r.iterations, r.residualNorm),
                   eventOf("pseudo_transient_end").add("converged", r.converged ? "true" : "false")
                       .add("iterations", json::number(r.iterations)));
    }
  }
  rec.newton += r.iterations;
  rec.linear += r.linearIterations;
  rec.residual = r.residualNorm;
  rec.augmentations = pass.number;
  logPass(pass, r, since(solveStart));
  return r;
}

void AugmentationLoop::logPass(const Pass& pass, const NewtonResult& r, double seconds) {
  if (!log_.on("newton")) return;
  std::string text = pass.stepAlone ? "saddle-point pass, no Newton solve, |R|:" : "newton |R|:";
  for (double n : r.residualHistory) text += format(" %.3e", n);
  if (!r.stepLengths.empty()) {
    text += "  steps:";
    for (double a : r.stepLengths) text += format(" %.2g", a);
  }
  text += format("  (%d linear; preconditioners built: %d; %.3f s)", r.linearIterations,
                 m_.newton->preconditionerBuilds(), seconds);
  std::vector<double> history(r.residualHistory.begin(), r.residualHistory.end());
  log_.event("newton", text,
             eventOf("newton").add("pass", json::number(pass.number)).add("residuals", json::array(history))
                 .add("step_lengths", json::array(r.stepLengths))
                 .add("converged", r.converged ? "true" : "false")
                 .add("linear_iterations", json::number(r.linearIterations))
                 .add("preconditioners_built", json::number(m_.newton->preconditionerBuilds()))
                 .add("seconds", json::number(seconds)));
}

bool AugmentationLoop::checkConstraints(int it, StepRecord& rec, Constraints& c, std::string& failure) {
  auto& assembly = *m_.assembly;
  for (const auto& e : assembly.effects()) {
    double v = 0;
    Teuchos::reduceAll(*m_.comm, Teuchos::REDUCE_MAX, e->constraintViolation(), Teuchos::outArg(v));
    if (e.get() == &assembly.bricks()) {
      rec.volumeChange = v, c.volumeMet = v <= e->constraintTolerance();
      if (m_.pressureStep) m_.pressureStep->measuredAfterNewton(v);
    }
    if (log_.on("newton"))
      log_.event("newton", format("%s: %.3e (tolerance %.1e)", e->constraintName().c_str(), v, e->constraintTolerance()),
                 eventOf("constraint").add("name", json::string(e->constraintName())).add("violation", json::number(v))
                     .add("tolerance", json::number(e->constraintTolerance())));
    if (v / e->constraintTolerance() > c.worst) c.worst = v / e->constraintTolerance(), c.worstName = e->constraintName();
    if (v <= e->constraintTolerance()) {
      if (m_.rolling) c.settled.push_back(e.get());
      continue;
    }
    c.met = false;
    c.rowsUnmet = c.rowsUnmet || e->stepsForItself();
    if (e->maxAugmentations() > 0 && it >= e->maxAugmentations()) {
      failure = format("%s %.4g above its tolerance %.4g after %d augmentations", e->constraintName().c_str(), v,
                       e->constraintTolerance(), it);
      return false;
    }
  }
  if (c.met) {
    const std::string through = bodyThroughCapstan();
    if (!through.empty()) {
      failure = through;
      return false;
    }
  }
  return true;
}

// Contact holds the faces' points only: a body pushed through a capstan, the faces closed
// behind it, balances with every point clear. Such a state is no answer; the step fails. The
// sweep's slice on a capstan of radius 1 (8x128) converged with it inside the coating and the
// roller turning backwards (speed ratio -1.06); the drive on 4 cells round converged with the
// capstan between two nodes.
std::string AugmentationLoop::bodyThroughCapstan() const {
  const auto& assembly = *m_.assembly;
  for (const ContactEffect* contact : assembly.contacts()) {
    const double tol = contact->constraintTolerance();
    // The contact points' own penetration (a soft penalty's is the model's) comes first.
    double points = 0;
    Teuchos::reduceAll(*m_.comm, Teuchos::REDUCE_MAX, contact->figures({0, 0, 0}).maxPenetration,
                       Teuchos::outArg(points));
    const ContactEffect::Cut cut = contact->deepestCut(assembly.positions(), *m_.comm);
    if (cut.depth > points + std::min(kCutFraction * cut.edge, 0.5 * contact->radius()) && cut.depth > 10 * tol)
      return format("%s: the capstan (radius %.4g) cuts %.3g into a contact face at (%.4g, %.4g, %.4g), between "
                    "the face's contact points (its longest edge %.3g; the points %.3g): the contact faces there "
                    "are too coarse to hold the capstan (their edges should be well under its diameter), or the "
                    "body has passed through it",
                    contact->name().c_str(), contact->radius(), cut.depth, cut.at[0], cut.at[1], cut.at[2], cut.edge,
                    points);
    const ContactEffect::Cut node = contact->deepestNode(assembly.positions(), *m_.comm);
    if (node.depth > points + kCutFraction * contact->shortestEdge() + 10 * tol)
      return format("%s: the body has passed through the capstan (radius %.4g): a node at (%.4g, %.4g, %.4g) lies "
                    "%.3g inside it while the contact points are clear (%.3g), the body's faces closed behind it; "
                    "smaller steps, a firmer support of the body, or contact faces fine enough to hold it",
                    contact->name().c_str(), contact->radius(), node.at[0], node.at[1], node.at[2], node.depth,
                    points);
  }
  return "";
}

void AugmentationLoop::moveByPressureStep(double t, Vector& f, const Constraints& c, bool stepAlone,
                                          PassPolicy& passes, std::optional<StepStart>& beforeStep,
                                          StepRecord& rec) {
  const auto& effects = m_.assembly->effects();
  // A step alone with nothing to step (the volumes met, no rows of its own unmet): the state is
  // no equilibrium, so the plain update would be no augmentation. Newton first. From rest
  // (`Predictor = Previous`) contact's update pushed the Hertz ring's overlapping points off with
  // eps g, and every cut of step 1 crawled after it; G2 took 763 Newton iterations, now 55.
  if (stepAlone && c.volumeMet && !c.rowsUnmet) {
    passes.newtonNext();
    return;
  }
  // The other multipliers first: the pressure step then re-balances the
  // body under their new values too, so their change does not spoil the
  // volumes it makes exact.
  const std::vector<double> pressureNext = multiplierMap(effects, true);  // at the converged state
  setMultipliers(effects, multiplierMap(effects, false), false, c.settled);
  // Mixed effects other than the bricks (steady friction) take their plain
  // update here too: the step moves only the rows it has.
  std::vector<const Effect*> keep = c.settled;
  keep.push_back(&m_.assembly->bricks());
  setMultipliers(effects, pressureNext, true, keep);
  if (c.volumeMet && !c.rowsUnmet) {
    passes.newtonNext();  // the plain update alone: Newton re-balances the body
    return;
  }
  beforeStep = StepStart{m_.snapshot(), pressureNext};
  if (!saddlePointPressureStep(t, f, c.volumeMet, stepAlone, rec)) {  // no progress: a plain pass instead
    m_.restore(beforeStep->at);  // a step that inverted an element even at its shortest moved u
    setMultipliers(effects, pressureNext, true);
    beforeStep.reset();
    passes.newtonNext();
    return;
  }
  if (!stepAlone) return;
  ++rec.newton;  // the monolithic system's Newton iteration
  // A step its linear model did not carry whole (contact points entering or leaving): a Newton
  // solve on the positions next, then steps again (docs/numerics.md, "The pressure loop").
  if (lastStepShortened_) passes.newtonNext();
}

bool AugmentationLoop::saddlePointPressureStep(double t, Vector& f, bool volumeMet, bool monolithic, StepRecord& rec) {
  auto& assembly = *m_.assembly;
  BrickEffect& bricks = assembly.bricks();
  auto W = m_.newton->matrix();
  assembly.evaluate(*m_.u, &f, W.get());  // the tangent at the converged state
  Vector dx(assembly.dofMap());
  // Solved until the volume error predicted after the next Newton solve is a
  // fraction of the volume tolerance (PressureStep::solve).
  // Volumes already met (a step for other rows), or no Newton solve next
  // (monolithic): the plain GMRES tolerance.
  const double volumeTarget = volumeMet || monolithic ? 0.0 : kPressureStepVolumeMargin * bricks.constraintTolerance();
  PressureStep::Result step;
  const auto stepStart = Clock::now();
  std::string failure;
  try {
    const bool onNewtonsFactors = !monolithic && m_.scene.solver.pressureStepOnNewtonsFactors;
    step = m_.pressureStep->solve(*W, m_.newton->approximateInverse(onNewtonsFactors), f,
                                  monolithic ? kMonolithicStepTolerance : kPressureStepTolerance, volumeTarget,
                                  m_.scene.solver.maxLinearIterations, dx, pressureStepDmu_);
  } catch (const std::exception& e) {  // e.g. a preconditioner that cannot be built: a plain pass
    failure = e.what();
  }
  if (const std::string why = m_.newton->agree(failure); !why.empty()) {
    if (log_.on("newton"))
      log_.event("newton", format("pressure step failed (%s): a plain pass instead", why.c_str()),
                 eventOf("pressure_step_failed"));
    return false;
  }
  rec.linear += step.iterations;
  rec.pressureStep += step.iterations;
  if (log_.on("newton"))
    log_.event("newton",
             format("pressure step: %d GMRES iterations%s, residual reduced %.2e, volume error left %.2e "
                    "(stopped on the prediction after Newton %.2e, target %.2e, %d checks), %d contact and stick rows; %.3f s",
                    step.iterations, step.lu ? " (LU)" : "", step.reduction, step.volumeResidual, step.volumePredicted,
                    step.predictionTarget, step.predictions, step.contactRows, since(stepStart)),
             eventOf("pressure_step").add("iterations", json::number(step.iterations))
                 .add("lu", step.lu ? "true" : "false")
                 .add("reduction", json::number(step.reduction))
                 .add("volume_error", json::number(step.volumeResidual))
                 .add("volume_predicted", json::number(step.volumePredicted))
                 .add("prediction_target", json::number(step.predictionTarget))
                 .add("predictions", json::number(step.predictions))
                 .add("contact_rows", json::number(step.contactRows))
                 .add("seconds", json::number(since(stepStart))));
  if (!step.luRefused.empty())
    solver_switches::note("the block-triangular pressure step (MUMPS did not factor the block matrix: " +
                          step.luRefused + ")");
  if (!step.luRefused.empty() && log_.on("newton"))
    log_.event("newton", "pressure step: its block matrix not factored (" + step.luRefused + "): Block from here on",
               eventOf("pressure_step_lu_refused"));
  lastStepShortened_ = false;
  if (!(step.reduction < 1)) return false;
  // The step's start, to scale it back from (the constraint rows are the
  // last evaluation's, so the trial's merit is its momentum residual alone).
  const Vector u0(*m_.u, Teuchos::Copy);
  std::vector<Kokkos::View<double*>> mu0;
  for (auto& e : assembly.effects()) {
    auto mu = e->multipliers();
    Kokkos::View<double*> copy("multipliers before the step", mu.extent(0));
    Kokkos::deep_copy(copy, mu);
    mu0.push_back(copy);
  }
  for (double alpha = 1;; alpha /= 2) {
    m_.u->update(1.0, u0, alpha, dx, 0.0);
    assembly.applyConstraints(*m_.u, t);
    // Each effect's multipliers move by their part of dmu (contact's back into
    // lambda >= 0: a point the step pulls free is released).
    for (size_t i = 0; i < assembly.effects().size(); ++i) {
      Effect& e = *assembly.effects()[i];
      auto mu = e.multipliers();
      auto d = pressureStepDmu_[i];
      auto start = mu0[i];
      if (mu.extent(0) == 0 || d.extent(0) != mu.extent(0)) continue;
      Kokkos::parallel_for(
          "pressure step multipliers", Kokkos::RangePolicy<ExecSpace>(0, mu.extent(0)),
          KOKKOS_LAMBDA(int k) { mu(k) = start(k) + alpha * d(k); });
      e.projectMultipliers();
    }
    if (alpha <= kShortestPressureStep) {
      if (assembly.evaluate(*m_.u, &f, nullptr)) break;
      // Even its shortest length inverts an element: Newton from there solved on a meaningless
      // tangent and failed (the Hertz ring pressed 400x harder: 2,000 GMRES iterations, 17 s,
      // each time). No step: the caller goes back to where it started.
      if (log_.on("newton"))
        log_.event("newton", format("pressure step %.4g inverts an element: not taken", alpha),
                   eventOf("pressure_step_inverts"));
      return false;
    }
    const bool valid = assembly.evaluate(*m_.u, &f, nullptr);
    const double left = f.norm2();  // collective: every rank
    if (valid && left <= kPressureStepMerit * step.initial) break;
    m_.pressureStep->shortened();
    lastStepShortened_ = true;
    if (log_.on("newton"))
      log_.event("newton", format("pressure step %.4g halved: it leaves |R| %.3e above %.3e", alpha, left, step.initial),
                 eventOf("pressure_step_halved").add("length", json::number(alpha)).add("residual", json::number(left))
                     .add("start", json::number(step.initial)));
  }
  return true;
}

NewtonResult AugmentationLoop::polish(double t, double start) {
  auto& assembly = *m_.assembly;
  const auto map = m_.u->getMap();
  Vector f(map), dx(map), trial(*m_.u, Teuchos::Copy);
  auto W = m_.newton->matrix();
  assembly.evaluate(*m_.u, &f, W.get());
  NewtonResult r;
  r.iterations = 1;
  r.converged = true;
  r.residualNorm = start;
  r.residualHistory = {start};
  const int linear = m_.newton->linearSolve(f, dx, 1e-12, NewtonSolver::Preconditioner::Kept);
  if (linear >= 0) {
    r.linearIterations = linear;
    trial.update(-1.0, dx, 1.0);
    assembly.applyConstraints(trial, t);
    const bool valid = assembly.evaluate(trial, &f, nullptr);
    const double after = f.norm2();  // collective: every rank
    if (valid && after < start) m_.u->update(1.0, trial, 0.0), r.residualNorm = after;
  }
  r.residualHistory.push_back(r.residualNorm);
  return r;
}

bool AugmentationLoop::lawsRegularisedNow() const {
  const auto& frictions = m_.assembly->frictionsPresent();
  bool any = false;
  for (const auto* f : frictions) {
    if (!f->acting()) continue;
    if (!f->regularisedLaw()) return false;
    any = true;
  }
  return any;
}

bool AugmentationLoop::everyPointSlips() {
  auto& assembly = *m_.assembly;
  const auto& frictions = assembly.frictionsPresent();
  if (frictions.empty()) return false;
  assembly.evaluate(*m_.u, nullptr, nullptr);
  long stick = 0, all = 0;
  for (const auto* f : frictions) stick += f->figures().stick;
  Teuchos::reduceAll(*m_.u->getMap()->getComm(), Teuchos::REDUCE_SUM, stick, Teuchos::outArg(all));
  return all == 0;
}

void AugmentationLoop::checkTangent() {
  auto& assembly = *m_.assembly;
  const auto map = m_.u->getMap();
  Vector v(map), Wv(map), fp(map), fm(map), trial(map);
  v.randomize();
  {
    auto d = v.getDataNonConst();
    for (LO i = 0; i < LO(d.size()); ++i)
      if (assembly.ownedConstrained(i)) d[i] = 0;
  }
  auto W = assembly.createMatrix();
  assembly.evaluate(*m_.u, nullptr, W.get());
  W->apply(v, Wv);
  const double h = 1e-7;
  trial.update(1.0, *m_.u, h, v, 0.0);
  assembly.evaluate(trial, &fp, nullptr);
  trial.update(1.0, *m_.u, -h, v, 0.0);
  assembly.evaluate(trial, &fm, nullptr);
  Vector diff(map);
  diff.update(1.0 / (2 * h), fp, -1.0 / (2 * h), fm, 0.0);
  diff.update(-1.0, Wv, 1.0);
  const double error = diff.norm2(), scale = Wv.norm2();  // collective: every rank
  const std::string text = format("tangent check: |W v - FD| / |W v| = %.3e (|W v| = %.3e)", error / scale, scale);
  if (log_.on("newton"))
    log_.event("newton", text, eventOf("tangent_check").add("relative_error", json::number(error / scale))
                                   .add("norm", json::number(scale)));
  else if (!log_.quiet())
    std::printf("    %s\n", text.c_str());
  assembly.evaluate(*m_.u, nullptr, nullptr);
}

}  // namespace capstan
