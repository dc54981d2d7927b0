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
};

// Runs the scene. Returns the exit status: 0 converged, 2 failed to converge
// (every converged step's output is complete). Throws InputError for input
// problems found before anything is written.
int runScene(const Scene& scene, const RCP<const Comm>& comm, const RunOptions& options);

}  // namespace capstan
