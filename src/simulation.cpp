#include "simulation.hpp"

#include <chrono>
#include <cstdio>

#include "effects/bricks.hpp"
#include "load_stepper.hpp"
#include "log.hpp"
#include "model.hpp"
#include "outputs.hpp"
#include "restart.hpp"
#include "solver_switches.hpp"
#include "step_figures.hpp"
#include "stopwatch.hpp"

namespace capstan {

namespace {

// Below this smallest Gauss-point det F at the last converged state, a failed run says where its
// mesh is most distorted: G1's deepest converged indentation ends below it, and the next step
// fails (docs/numerics.md, "How deep an indentation goes").
constexpr double kDistortedDetF = 0.5;

std::string distortionNote(const BrickEffect::Compression& c) {
  if (!(c.detF < kDistortedDetF)) return "";
  return format("; at the last converged state the most compressed Gauss point has det F = %.3g, in the element "
                "around (%.4g, %.4g, %.4g) (reference position): the mesh is strongly distorted there",
                c.detF, c.centroid[0], c.centroid[1], c.centroid[2]);
}

class Simulation {
 public:
  Simulation(const Scene& scene, const RCP<const Comm>& comm, const RunOptions& options)
      : scene_(scene), comm_(comm), options_(options), log_(comm->getRank() == 0, options.quiet, options.log) {}

  // The method: everything about the input is checked before anything is
  // written; then each load step is solved, measured and written.
  int run() {
    Model::checkRanks(scene_, *comm_);
    if (!options_.restart.empty()) restart_ = std::make_unique<Restart>(scene_, *comm_, options_.restart);
    model_ = std::make_unique<Model>(scene_, comm_);
    warnOfMeshDependentSettings();
    outputs_ = std::make_unique<Outputs>(*model_, log_, start_);
    if (restart_) restart_->restore(*model_, steps_, switches_, outputs_->earlier);
    openOutputs();
    LoadStepper stepper(*model_, log_, options_.checkTangent, restart_ ? restart_->time() : 0.0);
    if (restart_) stepper.predictors().recall(restart_->predictors());
    std::string failure;
    bool ok = true;
    for (int step = restart_ ? restart_->step() + 1 : 1; step <= scene_.steps && ok; ++step) {
      const auto stepStart = Clock::now();
      log_.setStep(step);
      StepRecord rec;
      rec.step = step;
      rec.time = step * scene_.stepSize;
      ok = stepper.advance(rec, failure);
      warnOfUnreadNoxParameters();
      for (auto& what : solver_switches::take()) switches_.push_back({step, std::move(what)});
      if (ok) finishStep(rec, stepper, stepStart);
    }
    warnOfUnreadNoxParameters(true);
    if (!ok) {
      model_->assembly->evaluate(*model_->u, nullptr, nullptr);  // final figures: last converged state
      failure += distortionNote(model_->assembly->bricks().mostCompressed(*comm_));
    }
    outputs_->writeHistory(steps_);
    outputs_->writeSummary(steps_, switches_, ok, failure);
    if (!ok && model_->rank0) std::fprintf(stderr, "capstan: did not converge: %s\n", failure.c_str());
    return ok ? 0 : 2;
  }

 private:
  // What the scene's settings mean on its mesh, known once the mesh is built
  // (the scene's own warnings come from loadScene).
  void warnOfMeshDependentSettings() const {
    if (!model_->rank0) return;
    const auto& contacts = model_->assembly->contacts();
    for (size_t i = 0; i < contacts.size(); ++i) {
      if (!contacts[i]->quadratureWarning().empty())
        std::fprintf(stderr, "capstan: WARNING: %s: parameter 'Capstans/%s/Contact/Quadrature': %s\n",
                     scene_.file.c_str(), contacts[i]->capstan().name.c_str(), contacts[i]->quadratureWarning().c_str());
      if (!contacts[i]->softPenaltyWarning().empty())
        std::fprintf(stderr, "capstan: WARNING: %s: parameter 'Capstans/%s/Contact/Penalty': %s\n",
                     scene_.file.c_str(), contacts[i]->capstan().name.c_str(), contacts[i]->softPenaltyWarning().c_str());
      if (!contacts[i]->coarseFacesWarning().empty())
        std::fprintf(stderr, "capstan: WARNING: %s: parameter 'Mesh/Cells', 'Capstans/%s/Radius': %s\n",
                     scene_.file.c_str(), contacts[i]->capstan().name.c_str(), contacts[i]->coarseFacesWarning().c_str());
    }
  }

  // NOX ignores names it does not read: say so once the first Newton solve has read its list, or at
  // the run's end where no Newton iteration went through NOX.
  void warnOfUnreadNoxParameters(bool runEnded = false) const {
    for (const auto& path : model_->newton->takeUnreadNoxParameters(runEnded))
      if (model_->rank0)
        std::fprintf(stderr, "capstan: WARNING: %s: parameter 'Solver/NOX/%s': %s, so it had no effect%s\n",
                     scene_.file.c_str(), path.c_str(),
                     runEnded ? "no Newton iteration of this run went through NOX"
                              : "NOX did not read it in the run's first Newton solve",
                     runEnded ? " (the monolithic pressure loop takes its Newton steps itself, without NOX)"
                              : " (misspelt, or for a method this run does not use)");
  }

  // The output directory, the files a restart continues, the initial state.
  void openOutputs() {
    outputs_->checkDirectory();
    outputs_->writeScene();
    // Checkpoints of an earlier run into this directory do not belong to this
    // one (a restart keeps the one it started from until it writes its own).
    if (model_->rank0) removeCheckpoints(outputs_->directory(), restart_ ? restart_->checkpointDirectory() : "");
    log_.open(outputs_->directory(), bool(restart_));
    if (restart_) {
      restart_->continueFields(*model_, outputs_->directory());
      log_.progress(format("restart from %s: step %d, t=%.4g", restart_->checkpointDirectory().string().c_str(),
                           restart_->step(), restart_->time()));
    }
    outputs_->openFields(options_.restart, restart_ ? restart_->step() : -1);
    outputs_->openNip(restart_ ? restart_->step() : -1, options_.restart);
    const double t = restart_ ? restart_->time() : 0.0;
    model_->assembly->setInterval(t, t);
    model_->assembly->evaluate(*model_->u, nullptr, nullptr);
    if (!restart_) outputs_->writeFields(0, 0.0);
  }

  // A converged step: its figures, outputs, the effects' history moved on,
  // a checkpoint when due, the progress lines.
  void finishStep(StepRecord& rec, LoadStepper& stepper, Clock::time_point stepStart) {
    measureStep(*model_, steps_, rec);
    rec.wall = since(stepStart);
    steps_.push_back(rec);
    outputs_->writeFields(rec.step, rec.time);
    outputs_->writeNip(rec.step);
    for (const auto& e : model_->effects()) e->commit(model_->assembly->positions());
    outputs_->writeHistory(steps_);
    // A run that ends before its own summary (killed, or MPI_Abort where a
    // failure on one rank alone left the others stuck) leaves this one.
    outputs_->writeSummary(steps_, switches_, false,
                           "the run stopped after step " + std::to_string(rec.step) + " of " +
                               std::to_string(scene_.steps) + " without finishing its summary (killed, or see its stderr)");
    if (scene_.checkpointEvery > 0 && rec.step % scene_.checkpointEvery == 0)
      writeCheckpoint(*model_, *outputs_, steps_, switches_, rec.step, stepper.time(), stepper.predictors().memory());
    for (const auto& line : progressLines(rec, scene_.steps, outputs_->timings().total)) log_.progress(line);
  }

  const Scene& scene_;
  RCP<const Comm> comm_;
  RunOptions options_;
  Log log_;
  const Clock::time_point start_ = Clock::now();
  std::unique_ptr<Restart> restart_;
  std::unique_ptr<Model> model_;
  std::unique_ptr<Outputs> outputs_;
  std::vector<StepRecord> steps_;
  std::vector<SolverSwitch> switches_;  // summary.json's "solver_switches"
};

}  // namespace

int runScene(const Scene& scene, const RCP<const Comm>& comm, const RunOptions& options) {
  return Simulation(scene, comm, options).run();
}

}  // namespace capstan
