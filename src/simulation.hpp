// A run of a scene: load steps with step cutting, the pressure (augmentation)
// loop around each Newton solve, and the outputs (progress lines, history.csv,
// summary.json, fields.h5 + fields.xmf).
#pragma once

#include <string>

#include "scene.hpp"
#include "types.hpp"

namespace capstan {

struct RunOptions {
  bool quiet = false;
  // Output directory of an earlier run of the scene: continue from its last
  // checkpoint (OUTDIR/checkpoint/step-N, see src/checkpoint.hpp). Empty: start
  // at t = 0.
  std::string restart;
};

// Runs the scene. Returns the exit status: 0 converged, 2 failed to converge
// (every converged step's output is complete). Throws InputError for input
// problems (the scene, a checkpoint that does not fit it) found before
// anything is written.
int runScene(const Scene& scene, const RCP<const Comm>& comm, const RunOptions& options);

}  // namespace capstan
