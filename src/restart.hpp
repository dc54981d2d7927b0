// Checkpoints and restarts (Output/Checkpoint Every, capstan run --restart DIR;
// the file format is src/checkpoint.hpp). A checkpoint holds everything a
// continuation needs: u, every effect's multipliers (pressure anchors,
// contact and tangential multipliers) and history (friction's positions,
// tractions and stick states), the step and its time, and the step records
// and timings for summary.json and history.csv, and the rolling predictors'
// last increment (the state before it: Predictors::Memory). The step size
// needs no saving: every step starts at the full Time/Step Size (cuts last
// only within a step), and nothing else carries over between steps (each
// Newton solve, Anderson mixing and preconditioner is built afresh).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "checkpoint.hpp"
#include "model.hpp"
#include "outputs.hpp"
#include "predictors.hpp"
#include "solver_switches.hpp"
#include "step_record.hpp"

namespace capstan {

// Writes OUTDIR/checkpoint/step-<k>/ (collective; one file per rank, published
// by a rename when all are written), then removes the older ones.
void writeCheckpoint(const Model& model, Outputs& outputs, const std::vector<StepRecord>& steps,
                     const std::vector<SolverSwitch>& switches, int step, double time,
                     const Predictors::Memory& predictors);

// Removes the checkpoints in OUTDIR/checkpoint but `keep` (rank 0): an earlier
// run's do not belong to this one.
void removeCheckpoints(const std::filesystem::path& outputDir, const std::filesystem::path& keep);

class Restart {
 public:
  // Finds the newest complete checkpoint in DIR/checkpoint and checks it
  // against the scene (mesh, step size, steps, ranks), before anything is
  // built. Throws InputError where it does not fit.
  Restart(const Scene& scene, const Comm& comm, const std::string& dir);
  ~Restart();
  int step() const { return step_; }
  double time() const { return time_; }
  const std::filesystem::path& checkpointDirectory() const { return checkpointDir_; }
  // Loads u, the effects' multipliers and history, and (rank 0) the step
  // records and the earlier runs' timings into the built run; checks that
  // fields.h5 is there to continue. Throws InputError where it does not fit.
  void restore(Model& model, std::vector<StepRecord>& steps, std::vector<SolverSwitch>& switches, Timings& earlier);
  // The predictors' memory read by restore().
  const Predictors::Memory& predictors() const { return predictors_; }
  // Continues the earlier run's fields.h5 in `outputDir` (a copy when this run
  // writes elsewhere).
  void continueFields(const Model& model, const std::filesystem::path& outputDir) const;

 private:
  std::string where() const;
  const Scene& scene_;
  const Comm& comm_;
  std::string dir_;                        // --restart DIR
  std::filesystem::path checkpointDir_;    // DIR/checkpoint/step-N
  std::filesystem::path file_;             // this rank's file in it
  int step_ = 0;
  double time_ = 0;
  std::unique_ptr<checkpoint::Reader> in_; // positioned after the header
  Predictors::Memory predictors_;
};

}  // namespace capstan
