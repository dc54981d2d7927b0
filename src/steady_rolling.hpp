// Steady rolling (formulation.md §8): each load step's steady state, solved
// from the previous one (a continuation in the loads). The first comes from
// rest without the user's help: the frictionless footprint (from the linear
// response to the loads, as a quasi-static first step) with each free core's
// angular velocity held at the no-slip value; then, under Coulomb, Tanh laws
// of falling slip scale with the angular velocity free, whose tractions seed
// Coulomb's stick multipliers (Tanh and Arctan scenes, or where that fails:
// friction at the held angular velocity); then the steady state.
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
  // The steady state at the loads of time t, from the one in u. False with
  // `failure` as AugmentationLoop::solve (the caller restores u).
  bool solve(double t, StepRecord& rec, std::string& failure);

 private:
  // The footprint, then (Coulomb) the Tanh stages and the steady state (where
  // it fails, again from the Tanh answer with a softer stick,
  // kRetryStickSoftening); where those fail, from the footprint again through
  // friction at the held angular velocity, then the steady state.
  bool startFromRest(double t, StepRecord& rec, std::string& failure);
  std::vector<SteadyFrictionEffect*> coulombFrictions() const;
  // Omega free and the Tanh stages (kStartSlipScales) in Coulomb's place;
  // Coulomb again after them, its multipliers their tractions if they converged.
  bool startThroughTanh(double t, const std::vector<SteadyFrictionEffect*>& coulomb, StepRecord& rec,
                        std::string& failure);
  // Coulomb's steady state from the Tanh stages' answer, with the scene's
  // stick and, where that fails, sticks kRetryStickSoftening x and 3x the
  // automatic one (then the scene's stick from their answer). False, with u and the
  // multipliers at the Tanh answer, if all three fail.
  bool steadyStateWithStickRetries(double t, const std::vector<SteadyFrictionEffect*>& coulomb, StepRecord& rec,
                                   std::string& failure);
  // passLimit > 0: a starting guess, that many augmentation passes.
  bool solveStage(double t, const char* what, StepRecord& rec, std::string& failure, int passLimit = 0);
  void holdCores(bool hold);
  void enableFriction(bool on);

  Model& m_;
  Log& log_;
  AugmentationLoop& augmentation_;
  Predictors& predictors_;
  bool started_;
};

}  // namespace capstan
