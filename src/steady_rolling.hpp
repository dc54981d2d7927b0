// Steady rolling (formulation.md §8): each load step's steady state, solved
// from the previous one (a continuation in the loads). The first comes from
// rest without the user's help: the frictionless footprint (from the linear
// response to the loads, as a quasi-static first step) with each free core's
// angular velocity held at the no-slip value; then, with the angular velocity
// free, laws of falling slip scale: Tanh in Coulomb's place, whose tractions
// seed Coulomb's stick multipliers, or a narrow Tanh or Arctan scene's own law
// (wider Tanh and Arctan scenes, or where that fails: friction at the held
// angular velocity); then the steady state.
#pragma once

#include <string>
#include <vector>

#include "augmentation.hpp"
#include "log.hpp"
#include "model.hpp"
#include "predictors.hpp"
#include "step_record.hpp"

namespace capstan {

class SteadyFrictionEffect;

class SteadyRolling {
 public:
  // started: u already holds a steady state (a restart).
  SteadyRolling(Model& model, Log& log, AugmentationLoop& augmentation, Predictors& predictors, bool started);
  // The steady state at the loads of time t, from the one in u (where that
  // fails, once until a step converges: from it again through the start's
  // wider laws). False with `failure` as AugmentationLoop::solve (the caller
  // restores u).
  bool solve(double t, StepRecord& rec, std::string& failure);

 private:
  // The steady state (the start from rest, or the continuation from u).
  bool solveSteadyState(double t, StepRecord& rec, std::string& failure);
  // Why the state in u is no answer: a free roller turning against the capstan; "" if none does.
  std::string rollerTurningBackwards() const;
  // The footprint, then (Coulomb) the Tanh stages and the steady state (where
  // it fails, again from the Tanh answer with a softer stick,
  // kRetryStickSoftening); where those fail, from the footprint again through
  // friction at the held angular velocity, then the steady state.
  bool startFromRest(double t, StepRecord& rec, std::string& failure);
  // Friction off and omega held: from the linear response, Newton failing on a quick stall
  // (kFootprintStall) into pseudo-time, which fails on its own stall; without friction (no
  // pseudo-time) from rest again without the rule.
  bool solveFootprint(double t, StepRecord& rec, std::string& failure);
  // Coulomb's frictions, and Tanh and Arctan ones much narrower than the
  // first start stage: those the start widens.
  std::vector<SteadyFrictionEffect*> frictionsStartedWide() const;
  // The start stages' slip speed scales over the capstan's surface speed:
  // Analysis/Start Slip Scales, then on down to about the narrowest
  // regularised law's.
  std::vector<double> startSlipScales(const std::vector<SteadyFrictionEffect*>& widened) const;
  // Omega free and the start stages: Tanh in Coulomb's place, a Tanh or Arctan
  // scene's law at the stage's scale where wider than its own; the scene's
  // laws again after them, Coulomb's multipliers their tractions if they converged.
  bool startThroughWideLaws(double t, const std::vector<SteadyFrictionEffect*>& widened, StepRecord& rec,
                            std::string& failure);
  // The steady state from the start stages' answer, with the scene's stick
  // and, where Coulomb's fails, sticks kRetryStickSoftening x and 3x the
  // automatic one (then the scene's stick from their answer). False, with u and the
  // multipliers at the start stages' answer, if all fail.
  bool steadyStateWithStickRetries(double t, const std::vector<SteadyFrictionEffect*>& widened, StepRecord& rec,
                                   std::string& failure);
  // passLimit > 0: a starting guess, that many augmentation passes.
  // announce: a progress line when it ends (the start's stages and a step's
  // retries take minutes on a fine nip; a continuation step's one solve not).
  bool solveStage(double t, const char* what, StepRecord& rec, std::string& failure, int passLimit = 0,
                  bool announce = true);
  void holdCores(bool hold);
  void enableFriction(bool on);

  Model& m_;
  Log& log_;
  AugmentationLoop& augmentation_;
  Predictors& predictors_;
  bool started_;
  bool wideRetryUsed_ = false;  // since the last converged steady state
};

}  // namespace capstan
