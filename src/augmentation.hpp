// The augmentation loop (formulation.md §1 and §2; docs/numerics.md, "The
// pressure loop"): Newton at fixed multipliers (element pressure anchors,
// contact and stick multipliers), then each effect's constraint is checked
// and the multipliers move: by the saddle-point pressure step
// (Solver/Pressure Update = Saddle Point) or to their fixed-point map,
// Anderson-accelerated, until every constraint meets its tolerance.
#pragma once

#include <string>

#include "anderson.hpp"
#include "log.hpp"
#include "model.hpp"
#include "regularisation_continuation.hpp"
#include "step_record.hpp"

namespace capstan {

class AugmentationLoop {
 public:
  // checkTangent: compare the assembled tangent with differences of the
  // residual before each solve and after a failed one (--check-tangent).
  AugmentationLoop(Model& model, Log& log, bool checkTangent);
  // Solves the increment ending at t from the first guess in u. `bare`: the
  // residual norm of the bare increment (Newton's tolerance is relative to
  // it). Adds its iterations to rec. False with `failure` set if Newton or
  // the loop failed (u and the multipliers are then the caller's to restore).
  bool solve(double t, double bare, StepRecord& rec, std::string& failure);

 private:
  // The saddle-point step at the converged state (src/pressure_step.hpp):
  // moves u and the multipliers together. False if the block solve made no
  // progress (nothing is changed then).
  // volumeMet: the volumes already meet their tolerance (a step for other rows).
  // monolithic: no Newton solve follows (Pressure Update = Monolithic).
  bool saddlePointPressureStep(double t, Vector& f, bool volumeMet, bool monolithic, StepRecord& rec);
  // One full Newton step from u, whose residual `start` is within the
  // absolute tolerance, kept if it lowers the residual: one iteration.
  NewtonResult polish(double t, double start);
  // Debugging aid: the assembled tangent against a central difference of the
  // residual along a random direction, logged (topic newton, or stdout).
  void checkTangent();
  // At u (evaluated here): whether no contact point of any capstan sticks
  // (every rank; false without friction).
  bool everyPointSlips();

  Model& m_;
  Log& log_;
  bool checkTangent_;
  // A failed Newton solve under a regularised friction law is repeated
  // through wider laws (src/regularisation_continuation.hpp).
  RegularisationContinuation continuation_;
  std::vector<Kokkos::View<double*>> pressureStepDmu_;  // per effect: its multipliers' change in the step
  bool lastStepShortened_ = false;                     // the last saddle-point step was halved
};

}  // namespace capstan
