// The Solver sublist, typed: Newton, the linear solvers and the pressure loop.
// declare() states every parameter with its default and doc string (`capstan
// params`); parse() reads a validated list into the struct and resolves the
// automatic choices, so the run sees what is used.
#pragma once

#include <algorithm>

#include <Teuchos_ParameterList.hpp>

#include <utility>
#include <vector>

#include "parameters.hpp"

namespace capstan {

struct SolverSettings {
  enum class LinearSolver { Auto, GMRES, CG, Direct };
  enum class Preconditioner { Auto, ILU, Jacobi, MueLu, LU, None };
  enum class Reuse { Adaptive, None };
  enum class ToleranceMethod { Adaptive, Fixed };
  enum class Predictor { Tangent, Previous };
  enum class RollingPredictor { StreamlineShift, RigidRoll };
  enum class LineSearch { Backtrack, Polynomial, FullStep };
  enum class PressureUpdate { SaddlePoint, Anderson };  // Auto is resolved by parse()
  enum class Schur { Auto, Laplacian, Diagonal };
  enum class StepPreconditioner { Auto, Block, LU };

  LinearSolver linearSolver{};
  int directSolverMaxDofs = 0;  // 0: automatic (resolved())
  Preconditioner preconditioner{};
  int iluLevel = 0;
  Reuse preconditionerReuse{};
  double linearTolerance = 0;
  ToleranceMethod linearToleranceMethod{};
  int maxLinearIterations = 0;
  double newtonRelativeTolerance = 0;
  double newtonAbsoluteTolerance = 0;  // 0: 1e-13 c L^2 (Model)
  int maxNewtonIterations = 0;
  // Newton gives up after this many iterations in a row with line-search steps of at most
  // 1/8 that did not halve |R| (0: never): without friction, 10; with it, stick and slip
  // sorting themselves out crawl like that and converge (NewtonSolver::solve).
  int crawlIterations = 0;
  Predictor predictor{};
  RollingPredictor rollingPredictor{};
  LineSearch lineSearch{};
  double volumeTolerance = 0;
  int maxPressureIterations = 0;
  PressureUpdate pressureUpdate{};
  // Auto's Anderson (friction without rolling): a step whose loop fails is solved again with the
  // saddle-point step, kept from there on (AugmentationLoop::solve).
  bool saddlePointIfAndersonFails = false;
  // Pressure Update = Monolithic (Auto without friction): each pass one saddle-point step from the
  // last, no Newton solve between (src/augmentation.cpp). Auto's only where the step's K^-1 is
  // exact (a direct solver or the LU preconditioner; Model decides).
  bool monolithic = false;
  bool monolithicIfExact = false;
  Schur pressureStepSchur{};
  // With a direct solver, the saddle-point step after a Newton solve
  // preconditions with Newton's last factorisation (false: a new one).
  bool pressureStepOnNewtonsFactors = true;
  // The saddle-point step's GMRES preconditioner: block-triangular (K^-1, the Schur approximation)
  // or the whole block matrix factored (src/saddle_point_lu.hpp). Auto: factored for steady rolling
  // above kStepLUAboveDofs where Newton factors (docs/performance.md, "Defaults and why").
  StepPreconditioner pressureStepPreconditioner{};
  static constexpr long kStepLUAboveDofs = 10000;
  int pressureAccelerationDepth = 0;
  double minimumSolvePenalty = 0;  // resolved: > 0
  // Automatic (-1): Model lowers it to kMonolithicSolvePenalty where the loop
  // turns out monolithic (it knows the linear solver).
  bool minimumSolvePenaltyAutomatic = false;
  static constexpr double kMonolithicSolvePenalty = 1e-2;
  // eps1 x c above this is lowered to it in the solves, as one below the floor is raised: the
  // converged state does not depend on eps1, but a softer one slows the pressure loop (G1:
  // 0.22 s at 1e-1, 0.45 s at 1, 1.93 s at 1e3; docs/numerics.md, "Penalties in any units").
  static constexpr double kSoftestSolvePenalty = 1e-1;
  // The pressure penalty of the linear solves: the scene's eps1 within [floor, kSoftestSolvePenalty] / c,
  // the floor where eps1 is 0 (automatic).
  static double solvePenalty(double eps1, double floor, double c) {
    return std::max(std::min(eps1, kSoftestSolvePenalty / c), floor / c);
  }
  // Set by resolved() for an annulus: MueLu with symmetric Gauss-Seidel
  // smoothing and a drop tolerance, which suit graded rings (src/newton.cpp).
  bool gradedRings = false;
  // Set by parse() with friction or in steady rolling: Newton's matrix is far
  // from symmetric. Otherwise it is nearly so (|A - A^T| about 3e-3 of |A| on
  // G1, from the stress 2c(B - I) off J = 1), and the LU preconditioner
  // factors its symmetric part (MumpsOptions::symmetricPart).
  bool unsymmetric = false;
  Teuchos::ParameterList nox, stratimikos;  // passed to NOX and Stratimikos over capstan's defaults
  // Passed to the Belos solver (GMRES or CG) and to the Ifpack2 preconditioner
  // (ILU, Jacobi) over capstan's defaults; Solver/Stratimikos over both.
  Teuchos::ParameterList belos, ifpack2;

  static void declare(Teuchos::ParameterList& solver);
  // `friction`: some capstan has friction; `rolling`: a free-turning rigid
  // core in the quasi-static analysis; `steady`: the steady-rolling analysis
  // (Pressure Update = Auto picks Monolithic without friction, Anderson with
  // friction unless rolling or steady).
  static SolverSettings parse(const Teuchos::ParameterList& solver, const ParameterReader& r, bool friction,
                              bool rolling = false, bool steady = false);
  // Linear Solver = Auto and Preconditioner = Auto resolved for a problem of
  // `dofs` unknowns on an annulus (or box) mesh, with or without friction
  // (docs/performance.md, "Linear solvers", has the measurements).
  SolverSettings resolved(long dofs, bool annulus, bool friction, bool steady = false) const;
  // The defaults (tests, benchmarks).
  static SolverSettings defaults(bool friction = false, bool rolling = false, bool steady = false);

  static const std::vector<std::pair<const char*, LinearSolver>> linearSolvers;
  static const std::vector<std::pair<const char*, Preconditioner>> preconditioners;
  static const std::vector<std::pair<const char*, LineSearch>> lineSearches;
};

}  // namespace capstan
