// The load-step controller: each step from the last converged time to the
// step's time, in sub-steps that halve on failure and grow back after
// success; a failed increment puts u, the multipliers and the effects'
// history back as they were.
#pragma once

#include <string>
#include <vector>

#include "augmentation.hpp"
#include "log.hpp"
#include "model.hpp"
#include "predictors.hpp"
#include "steady_rolling.hpp"
#include "step_record.hpp"

namespace capstan {

class LoadStepper {
 public:
  // tDone: the time of the converged state in u (a restart's).
  LoadStepper(Model& model, Log& log, bool checkTangent, double tDone);
  // Advances to rec.time = rec.step * Time/Step Size, adding the iterations and
  // cuts to rec. True: u holds the converged state, evaluated there (the
  // figures and reactions). False, with `failure`: no equilibrium even at the
  // smallest sub-step; u and the effects are back at the step's start.
  bool advance(StepRecord& rec, std::string& failure);
  double time() const { return tDone_; }
  Predictors& predictors() { return predictors_; }

 private:
  // rotations: the cores' at t0 (the increment's start).
  bool solveIncrement(double t0, double t1, const std::vector<double>& rotations, StepRecord& rec,
                      std::string& failure);
  // Quasi-static: why the increment's converged state is no answer, or empty: a braked core free
  // to turn that stands or turns back while every contact point slips (rotations: the cores'
  // at the increment's start, dt its length).
  std::string brakedRollerStalled(const std::vector<double>& rotations, double dt);

  Model& m_;
  Log& log_;
  Predictors predictors_;
  AugmentationLoop augmentation_;
  SteadyRolling steady_;  // Analysis/Type = Steady Rolling: each step a steady state
  double tDone_;
  bool chatterHinted_ = false;  // the stick chatter hint printed (stickChatterHint)
};

}  // namespace capstan
