// First guesses for a load increment's Newton solve (docs/numerics.md,
// "Predictors"): the tangent predictor, and for a rolling body (a rigid core
// turning freely) the extrapolation along the last increment and the rigid
// roll with the cores.
#pragma once

#include <memory>
#include <vector>

#include "log.hpp"
#include "model.hpp"
#include "step_record.hpp"
#include "streamline_shift.hpp"

namespace capstan {

class Predictors {
 public:
  Predictors(Model& model, Log& log) : m_(model), log_(log) {}
  // Moves u from the converged state at t0 to a first guess at t1 (constraints at t1). Returns the
  // bare increment's residual (only prescribed values moved): a guess must beat it, and Newton's
  // tolerance is relative to it. Krylov iterations count in rec.
  double firstGuess(double t0, double t1, StepRecord& rec);
  // The state before the increment that just converged (u, its time and the
  // cores' rotations): the base of the rolling extrapolation.
  void remember(const Vector& before, double tBefore, std::vector<double> rotationsBefore);
  // What remember() holds, for a checkpoint (u's local values, as u's; empty
  // before the first increment), and its return on a restart.
  struct Memory {
    std::vector<double> u, rotations;
    double t = 0;
  };
  Memory memory() const;
  void recall(const Memory& memory);
  // Steady rolling's start from rest: the tangent predictor alone, at the
  // loads of time t (no rolling measures: the steady mesh does not turn).
  void linearResponse(double t, StepRecord& rec);

 private:
  // A fresh run's first increment: the body seated clear of a deep overlap (src/seating.hpp), said
  // on the progress lines once.
  void seat(double t, double bare);
  // Rolling: u extrapolated along the last converged increment; true if kept.
  bool extrapolate(double t0, double t1, double bare, Vector& f);
  // Rolling: each free core's turn in the increment, at its last angular
  // velocity (at first: rolling without slip), from the cores' records of the
  // converged state (the bare evaluation: a rejected extrapolation's
  // evaluation leaves its own there, a turn ahead).
  std::vector<double> coreTurns(double t0, double t1) const;
  // Rolling: the body turned with each free core by dTheta; true if any core turned.
  bool rollWithCores(const std::vector<double>& dTheta);
  // Rolling, Solver/Rolling Predictor = Streamline Shift (the default), from
  // the third step on (the second starts from rest: its last increment is no
  // rolling): the body's shape kept in space as one free core turns
  // (src/streamline_shift.hpp); true if done.
  bool shiftAlongStreamlines(double t0, double t1, const std::vector<double>& dTheta);
  // K_ff du = -(R + K z)_f from the converged state and the prescribed
  // increment z; kept if it beats the bare increment.
  // turned: the cores' prescribed turns are in u already (rollWithCores).
  void tangent(double t0, double t1, double bare, StepRecord& rec, bool turned = false);

  Model& m_;
  Log& log_;
  RCP<Vector> previous_;  // the state before the last converged increment
  double tPrevious_ = 0;
  std::vector<double> previousRotation_;  // the cores' rotations in that state
  std::unique_ptr<StreamlineShift> shift_;  // built at its first use
  bool seated_ = false;
};

}  // namespace capstan
