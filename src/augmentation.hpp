// The augmentation loop (formulation.md §1 and §2; docs/numerics.md, "The
// pressure loop"): Newton at fixed multipliers (element pressure anchors,
// contact and stick multipliers), then each effect's constraint is checked
// and the multipliers move: by the saddle-point pressure step
// (Solver/Pressure Update = Saddle Point) or to their fixed-point map,
// Anderson-accelerated, until every constraint meets its tolerance. With
// Pressure Update = Monolithic a pass is the saddle-point step alone
// (PassPolicy says which passes).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "anderson.hpp"
#include "effect_state.hpp"
#include "log.hpp"
#include "model.hpp"
#include "regularisation_continuation.hpp"
#include "step_record.hpp"

namespace capstan {

// Which passes are a saddle-point step alone (Pressure Update = Monolithic: Newton on the mixed
// problem) and which a Newton solve: monolithic, a Newton solve only after a step that made no
// progress or was halved, and after kMonolithicPasses. The nested loops: always Newton.
class PassPolicy {
 public:
  static constexpr int kMonolithicPasses = 12;
  explicit PassPolicy(bool monolithic) : monolithic_(monolithic), stepNext_(monolithic) {}
  // Whether pass `it` (from 1) is a step alone; the pass after it is one too
  // unless newtonNext() is called.
  bool stepAlone(int it) {
    const bool step = stepNext_ && it <= kMonolithicPasses;
    stepNext_ = monolithic_;
    return step;
  }
  // The next pass solves Newton on the positions.
  void newtonNext() { stepNext_ = false; }

 private:
  bool monolithic_;
  bool stepNext_;
};

class AugmentationLoop {
 public:
  // checkTangent: compare the assembled tangent with differences of the
  // residual before each solve and after a failed one (--check-tangent).
  AugmentationLoop(Model& model, Log& log, bool checkTangent);
  // Solves the increment ending at t from the guess in u (`bare`: the bare increment's residual,
  // Newton's reference), adding to rec; false with `failure` set (the caller restores u and the
  // multipliers). passLimit > 0: stop after that many passes, met or not (a first guess).
  bool solve(double t, double bare, StepRecord& rec, std::string& failure, int passLimit = 0);
  // At u (evaluated here): whether no contact point of any capstan sticks
  // (every rank; false without friction).
  bool everyPointSlips();
  // Coulomb: whether a failed solve may go on in pseudo-time while points
  // stick (LoadStepper: in sub-steps cut a few times; otherwise only where
  // every point slips, see solvePositions).
  void allowPseudoTimeWithStick(bool allow) { pseudoTimeWithStick_ = allow; }
  // Coulomb: whether a failed Newton solve is tried again through a smoothed stick/slip corner
  // (RegularisationContinuation); off where the caller's own retry does better (steady
  // rolling's start: SteadyRolling::startFromRest).
  void allowCornerRetry(bool allow) { cornerRetry_ = allow; }
  bool cornerRetryAllowed() const { return cornerRetry_; }
  // Whether a failed solve under regularised laws that the scene did not ask to widen (steady
  // rolling's Tanh stages in Coulomb's place) goes on in pseudo-time: off unless the caller asks.
  void allowPseudoTimeOnRegularisedLaws(bool allow) { pseudoTimeOnRegularised_ = allow; }

 private:
  // solve() once, with the step's preconditioner as it stands.
  bool solveOnce(double t, double bare, StepRecord& rec, std::string& failure, int passLimit);
  // How a pass starts: a step alone or a Newton solve (or one polishing Newton
  // step), and the residual it starts from and is to reach.
  struct Pass {
    int number = 1;
    bool stepAlone = false;
    bool polish = false;
    double start = 0;      // |R| at the start (0 for a first Newton pass: not evaluated)
    double tolerance = 0;  // Newton's tolerance in this pass
  };
  // The state before the last saddle-point step, while the pass after it runs:
  // where a pass that fails after the step goes back to.
  struct StepStart {
    Model::Snapshot at;                // u, and the multipliers after their plain update
    std::vector<double> pressureNext;  // the mixed effects' plain update
  };
  // After a converged pass: which constraints are met.
  struct Constraints {
    bool met = true;        // all of them
    bool volumeMet = true;  // the bricks' volumes
    bool rowsUnmet = false; // some effect with rows of its own in the step (contact, stick) is not
    std::vector<const Effect*> settled;  // rolling: effects within tolerance, whose multipliers stay put
    double worst = 0;       // the largest violation over its tolerance
    std::string worstName;  // whose
  };

  Pass startPass(int it, double tol, PassPolicy& passes, Vector& f);
  // With the saddle-point step: whether the worst constraint has not come
  // below its best for kStallPasses passes (failure set).
  bool stalled(int it, const Constraints& c, std::string& failure);
  // After a pass's Newton solve: friction points cycling between stick and
  // slip held in slip, at last every state frozen (FrictionEffect::notePass);
  // true where a hold changed.
  bool holdCyclingSlips(int it);
  bool frozen_ = false;  // the friction points' states frozen (holdCyclingSlips), at pass frozenAt_
  int frozenAt_ = 0;
  std::vector<double> frozenWorst_;  // the worst constraint of each pass checked since (stalled)
  double bestWorst_ = 0;
  int bestPass_ = 0;
  // The pass's Newton solve on the positions (none for a step alone), with
  // the friction retries (through wider laws, in pseudo-time) where it fails.
  // afterStep: the pass follows a saddle-point step (which is undone instead).
  NewtonResult solvePositions(double t, const Pass& pass, bool afterStep, StepRecord& rec);
  void logPass(const Pass& pass, const NewtonResult& r, double seconds);
  // Evaluates the constraints at u (converged). False with `failure` set if
  // an effect ran out of augmentations.
  bool checkConstraints(int it, StepRecord& rec, Constraints& c, std::string& failure);
  // Why a state whose constraints are met is no answer: the body through a capstan (empty: none).
  std::string bodyThroughCapstan() const;
  // The multipliers' move with the saddle-point step: the plain update for
  // contact and friction, then the step where a constraint with rows is unmet.
  void moveByPressureStep(double t, Vector& f, const Constraints& c, bool stepAlone, PassPolicy& passes,
                          std::optional<StepStart>& beforeStep, StepRecord& rec);
  // The saddle-point step at the converged state (src/pressure_step.hpp): moves u and the
  // multipliers; false, nothing changed, if the block solve made no progress. volumeMet: the
  // volumes are met already; monolithic: no Newton solve follows.
  bool saddlePointPressureStep(double t, Vector& f, bool volumeMet, bool monolithic, StepRecord& rec);
  // One full Newton step from u, whose residual `start` is within the
  // absolute tolerance, kept if it lowers the residual: one iteration.
  NewtonResult polish(double t, double start);
  // Debugging aid: the assembled tangent against a central difference of the
  // residual along a random direction, logged (topic newton, or stdout).
  void checkTangent();
  // Whether some friction acts and every acting one's law is regularised now.
  bool lawsRegularisedNow() const;

  Model& m_;
  Log& log_;
  bool checkTangent_;
  // A failed Newton solve under a regularised friction law is repeated
  // through wider laws (src/regularisation_continuation.hpp).
  RegularisationContinuation continuation_;
  std::vector<Kokkos::View<double*>> pressureStepDmu_;  // per effect: its multipliers' change in the step
  bool lastStepShortened_ = false;                     // the last saddle-point step was halved
  bool pseudoTimeWithStick_ = false;                   // allowPseudoTimeWithStick
  bool cornerRetry_ = true;                            // allowCornerRetry
  bool pseudoTimeOnRegularised_ = false;               // allowPseudoTimeOnRegularisedLaws
};

}  // namespace capstan
