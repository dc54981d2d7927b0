// A run of a scene (deal.II step-44 style: run() is the method's named steps;
// docs/architecture.md draws the data flow). Each phase is its own object:
//   Model            the mesh, effects, assembly and solvers (src/model.hpp)
//   LoadStepper      load steps and step cutting (src/load_stepper.hpp), around
//     Predictors     first guesses (src/predictors.hpp) and the
//     AugmentationLoop  Newton at fixed multipliers, then the multipliers
//                   (src/augmentation.hpp)
//   measureStep      a converged step's figures (src/step_figures.hpp)
//   Outputs          fields, history.csv, summary.json (src/outputs.hpp)
//   Restart          checkpoints and --restart (src/restart.hpp)
#pragma once

#include <string>
#include <vector>

#include "scene.hpp"
#include "types.hpp"

namespace capstan {

struct RunOptions {
  bool quiet = false;
  // Output directory of an earlier run of the scene: continue from its last
  // checkpoint (OUTDIR/checkpoint/step-N, see src/restart.hpp). Empty: start
  // at t = 0.
  std::string restart;
  // Log topics (capstan run --log TOPIC; src/log.hpp).
  std::vector<std::string> log;
  // Compare the assembled tangent with differences of the residual before
  // each Newton solve (capstan run --check-tangent; a debugging aid).
  bool checkTangent = false;
};

// Runs the scene. Returns the exit status: 0 converged, 2 failed to converge
// (every converged step's output is complete). Throws InputError for input
// problems (the scene, a checkpoint that does not fit it) found before
// anything is written.
int runScene(const Scene& scene, const RCP<const Comm>& comm, const RunOptions& options);

}  // namespace capstan
