// What a run builds from its scene and every phase of the method works on:
// the distributed mesh, the assembly with its effects, Newton and the
// saddle-point pressure step, and the displacement.
#pragma once

#include <memory>

#include "assembly.hpp"
#include "effect_state.hpp"
#include "newton.hpp"
#include "pressure_step.hpp"
#include "scene.hpp"

namespace capstan {

struct Model {
  // Throws InputError where the scene cannot run on these ranks (fewer
  // elements than ranks), before anything is built.
  static void checkRanks(const Scene& scene, const Comm& comm);
  // Builds the mesh, effects, assembly and solvers (collective).
  Model(const Scene& scene, const RCP<const Comm>& comm);

  const Scene& scene;
  RCP<const Comm> comm;
  bool rank0;
  std::unique_ptr<MeshGenerator> generator;
  Mesh mesh;
  std::unique_ptr<Assembly> assembly;
  std::unique_ptr<NewtonSolver> newton;
  std::unique_ptr<PressureStep> pressureStep;  // null with Solver/Pressure Update = Anderson
  // The pressure loop's passes are saddle-point steps alone (Pressure Update =
  // Monolithic, or Auto without friction where the step's K^-1 is exact).
  bool monolithic = false;
  RCP<Vector> u;
  // A rigid core turns freely: the rolling measures (extrapolation, rolling
  // first guess, settled multipliers) are on.
  bool rolling = false;
  double forceScale = 1;    // c L^2, L the body's largest extent
  double absTolerance = 0;  // Newton's absolute tolerance (Solver/Newton Absolute Tolerance, 0: 1e-13 c L^2)
  long numContactFaces = 0; // global, each candidate face once

  const EffectList& effects() const { return assembly->effects(); }
  // A state to go back to (a failed increment, a failed start): u and the
  // effects' multipliers and history.
  struct Snapshot {
    Vector u;
    EffectState effects;
  };
  Snapshot snapshot() const { return {Vector(*u, Teuchos::Copy), saveState(effects())}; }
  void restore(const Snapshot& s) {
    u->update(1.0, s.u, 0.0);
    restoreState(effects(), s.effects);
  }
  // The saddle-point pressure step (Solver/Pressure Update), also built mid-run where Auto's
  // Anderson loop fails a step through every cut (LoadStepper::advance).
  void buildPressureStep();
  // Newton's linear solves and the pressure steps' block solves.
  double linearSolveSeconds() const;
};

}  // namespace capstan
