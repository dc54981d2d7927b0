// The run's files in the output directory (interface.md, "Outputs"):
// fields.h5 + fields.xmf per step, history.csv after every step and
// summary.json at the end; also the run's time by phase, added up over a
// run and the runs it restarted from.
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "field_writer.hpp"
#include "nip_table.hpp"
#include "log.hpp"
#include "model.hpp"
#include "solver_switches.hpp"
#include "step_record.hpp"

namespace capstan {

// summary.json's "timing" and "effects": seconds by phase, each effect's
// kernel launches and seconds (in the assembly's effect order).
struct Timings {
  double total = 0, assembly = 0, linearSolve = 0, output = 0, preconditionerSetup = 0;
  long directAnalyses = 0, directFactorizations = 0, directSolves = 0;  // MumpsSolver::processCounts
  struct Effect {
    std::string name;
    long launches = 0;
    double seconds = 0;
  };
  std::vector<Effect> effects;
};

class Outputs {
 public:
  // start: when the run started (summary.json's total time counts from it).
  Outputs(Model& model, Log& log, std::chrono::steady_clock::time_point start);
  ~Outputs();
  // Checks that Output/Directory can be written and that no other run is
  // writing there (InputError otherwise, before anything is written), creates
  // it and holds its lock (.capstan-lock, an flock released when the process
  // ends) for the run.
  void checkDirectory();
  const std::filesystem::path& directory() const { return dir_; }
  // Starts fields.h5 (a restart continues `restartDir`'s after step
  // `lastKept`; lastKept < 0: a new file).
  void openFields(const std::string& restartDir, int lastKept);
  // The step's fields (collective).
  void writeFields(int step, double time);
  void writeHistory(const std::vector<StepRecord>& steps);
  // scene.xml: the scene as this run resolved it (every default, every --set),
  // as `capstan validate` prints it: `capstan run OUT/scene.xml` runs it again.
  void writeScene();
  // nip.csv: started (a restart keeps the earlier run's rows up to lastKept, from restartDir),
  // then each converged step's rows (collective).
  void openNip(int lastKept, const std::string& restartDir = "");
  void writeNip(int step);
  void writeSummary(const std::vector<StepRecord>& steps, const std::vector<SolverSwitch>& switches, bool converged,
                    const std::string& failure);
  // This run's timings plus the earlier runs' (`earlier`, from a checkpoint).
  Timings timings() const;
  Timings earlier;
  // Time spent on output that is not fields (checkpoints) counts as output.
  void addOutputSeconds(double s) { outputSeconds_ += s; }

 private:
  FieldLayout fieldLayout() const;

  Model& m_;
  Log& log_;
  std::chrono::steady_clock::time_point t0_;
  std::filesystem::path dir_;
  std::unique_ptr<FieldWriter> writer_;
  std::unique_ptr<NipTable> nip_;
  double outputSeconds_ = 0;
  int lock_ = -1;  // the output directory's lock file, held by rank 0
};

// Writes `text` to `path` through a temporary file and a rename: readers see
// the old file or the new one, never a part.
void writeAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace capstan
