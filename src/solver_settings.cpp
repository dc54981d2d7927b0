#include "solver_settings.hpp"

#include <cctype>

#include "mumps_parameters.hpp"

namespace capstan {

namespace {
// The first string parameter under `list` (path `at`) that names Ifpack2's block relaxation,
// as "path = value", or "": in Trilinos 13.2 it crashes on capstan's matrices
// (docs/performance.md, "Defaults and why").
std::string blockRelaxationIn(const Teuchos::ParameterList& list, const std::string& at) {
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string path = at + "/" + list.name(it);
    const auto& entry = list.entry(it);
    if (entry.isList()) {
      const std::string inner = blockRelaxationIn(list.sublist(list.name(it)), path);
      if (!inner.empty()) return inner;
    } else if (entry.isType<std::string>()) {
      std::string squeezed;
      for (char c : entry.getValue<std::string>(nullptr))
        if (std::isalpha(static_cast<unsigned char>(c))) squeezed += char(std::toupper(static_cast<unsigned char>(c)));
      if (squeezed.find("BLOCKRELAXATION") != std::string::npos) return path + " = " + entry.getValue<std::string>(nullptr);
    }
  }
  return "";
}
}  // namespace

using Teuchos::ParameterList;
using S = SolverSettings;

const std::vector<std::pair<const char*, S::LinearSolver>> S::linearSolvers = {
    {"Auto", LinearSolver::Auto}, {"GMRES", LinearSolver::GMRES}, {"CG", LinearSolver::CG}, {"Direct", LinearSolver::Direct}};
const std::vector<std::pair<const char*, S::Preconditioner>> S::preconditioners = {
    {"Auto", Preconditioner::Auto}, {"ILU", Preconditioner::ILU}, {"Jacobi", Preconditioner::Jacobi},
    {"MueLu", Preconditioner::MueLu}, {"LU", Preconditioner::LU}, {"None", Preconditioner::None}};
const std::vector<std::pair<const char*, S::LineSearch>> S::lineSearches = {
    {"Backtrack", LineSearch::Backtrack}, {"Polynomial", LineSearch::Polynomial}, {"Full Step", LineSearch::FullStep}};

void SolverSettings::declare(ParameterList& sol) {
  sol.set("Linear Solver", std::string("Auto"),
          "Auto | GMRES | CG | Direct (Belos GMRES, Belos CG, MUMPS on any number of ranks). Auto, up to "
          "Direct Solver Max Dofs: Direct with friction or in steady rolling, GMRES with an LU preconditioner "
          "otherwise; above it GMRES (with LU in steady rolling; docs/performance.md, \"Linear solvers\")");
  sol.set("Direct Solver Max Dofs", 0,
          "Auto: the largest problem factorised by MUMPS; 0: automatic, 5,000 on a Box mesh, 50,000 "
          "on an Annulus (graded rings, on which smoothed aggregation needs hundreds of iterations)");
  sol.set("Preconditioner", std::string("Auto"),
          "Auto | ILU | Jacobi | MueLu | LU | None (Ifpack2 RILUK per rank, Jacobi relaxation; MueLu smoothed "
          "aggregation with the rigid-body modes; LU: a MUMPS factorisation kept across Newton iterations "
          "while it works, see Preconditioner Reuse). Auto: LU in steady rolling, else MueLu from 1000 dofs, ILU "
          "below. A direct linear solve builds none (a named one is a warning)");
  sol.set("ILU Level", 1, "ILU: level of fill (>= 0)");
  sol.set("Preconditioner Reuse", std::string("Adaptive"),
          "Adaptive | None. Adaptive: Newton builds its preconditioner at each load step's start "
          "and keeps it across iterations and pressure passes, rebuilding it when a Krylov solve "
          "needs more than twice the iterations (+10) of the first solve after the last build, or "
          "hits its limit; None: a new one every Newton iteration");
  sol.set("Linear Tolerance", 1e-10, "Relative residual of each linear solve (0 < tol < 1)");
  sol.set("Linear Tolerance Method", std::string("Adaptive"),
          "Adaptive | Fixed. Adaptive: Eisenstat-Walker forcing terms (each Krylov solve only as "
          "tight as Newton's progress needs, never tighter than Linear Tolerance); Fixed: every "
          "Krylov solve to Linear Tolerance. Direct solves are exact either way");
  sol.set("Max Linear Iterations", 2000, "Krylov iteration limit per linear solve");
  sol.set("Newton Relative Tolerance", 1e-10, "Converged when |R| <= this x |R| at the step's start");
  sol.set("Newton Absolute Tolerance", 0.0, "Converged when |R| <= this; 0 = 1e-13 x c x (body size)^2");
  sol.set("Max Newton Iterations", 0,
          "Newton iteration limit per solve; 0: automatic, 60 for rolling with friction (a free-turning core "
          "in the quasi-static analysis, or steady rolling), 30 otherwise. A rolling increment's first solve can "
          "crawl 3-5% per iteration past 30 and converge (the 3D drive's 20 steps: no cut at 60, 6 at 30; the "
          "steady drive at 57k dofs converges at 60 and fails at 30, where cuts cannot help); elsewhere a longer "
          "limit only lengthens failing attempts (docs/friction.md)");
  sol.set("Predictor", std::string("Tangent"),
          "Tangent (linear response to the step's prescribed increment, from the previous "
          "step) | Previous (the previous step's solution with the new boundary values)");
  sol.set("Rolling Predictor", std::string("Streamline Shift"),
          "A turning free core's first guess: Streamline Shift (from the third step on, while the core "
          "turns within 20% of rolling without slip: the body's shape kept standing in space while "
          "its material turns through it, interpolated along the rings of nodes; src/streamline_shift.hpp) "
          "| Rigid Roll (the last increment extrapolated, else the body turned with the core). "
          "The shift: the slice 18.7 Newton iterations per step against 57.6, the 3D drive 23% fewer "
          "(docs/numerics.md, Predictors)");
  sol.set("Line Search", std::string("Backtrack"),
          "Newton's damping (NOX line search): Backtrack (halves the step until |R| falls) | Polynomial "
          "(interpolates the step length) | Full Step (takes every Newton step whole, into inverted "
          "elements too). A failed search takes no step, and the load step is cut");
  sol.set("Volume Tolerance", 1e-10, "Pressure loop ends when max |v_e/V_e - 1| is below this");
  sol.set("Max Pressure Iterations", 100, "Most pressure-anchor updates per step");
  sol.set("Pressure Update", std::string("Auto"),
          "How the pressure loop moves the element pressure anchors after each Newton solve: "
          "Saddle Point (positions, anchors, exact contact's multipliers and Coulomb's stick tractions from one block Krylov solve, "
          "v_e = V_e and g = 0 to first order), "
          "Monolithic (the same step taken from the predictor on and repeated, with no Newton solve on the positions "
          "alone in between: Newton's method on positions, anchors and multipliers together; no friction), "
          "Anderson (pbar <- p(x), Anderson-accelerated), or Auto (Monolithic without friction where the step's K^-1 is exact, with a direct solver or the LU "
          "preconditioner, Saddle Point elsewhere without friction, for a "
          "free-turning core rolling with friction in the quasi-static analysis and for steady rolling; "
          "Anderson for other friction scenes, Saddle Point from a step Anderson fails through every cut; "
          "docs/friction.md, \"The multiplier loop in rolling\", "
          "docs/performance.md, \"Defaults and why\")");
  sol.set("Pressure Step Schur", std::string("Auto"),
          "The saddle-point step's approximation of its volume rows' Schur complement: Laplacian "
          "((eps V)^-1 + 0.15 L^-1, L = G^T diag(K0)^-1 G by 30 CG iterations: it holds Q1P0's nearly "
          "spurious pressure modes), Diagonal ((eps V)^-1 alone), or Auto (Laplacian with Krylov "
          "linear solves, Diagonal with a direct solver, whose exact K^-1 leaves it little to gain). "
          "The same answer either way");
  sol.set("Pressure Step Factorisation", std::string("Newton's"),
          "With a direct solver, the saddle-point step after a Newton solve preconditions its Krylov solve with: "
          "Newton's (its last factorisation, the tangent one Newton step before the converged state) | New (one "
          "made at the converged state). Newton's: the steady drive 0.86 against 1.04 s, the quasi-static drive "
          "9.05 against 9.77 s, the same Newton iterations (docs/performance.md, \"Defaults and why\")");
  sol.set("Pressure Step Preconditioner", std::string("Auto"),
          "The saddle-point step's GMRES preconditioner: Block (K^-1 and the Schur approximation above) | LU (the "
          "step's whole block matrix factored by MUMPS, its repeated stick and contact rows regularised: 1-3 "
          "iterations a step) | Auto (LU for steady rolling above 10,000 unknowns where Newton's solves factor the matrix (direct or the LU preconditioner), "
          "Block elsewhere: a fine nip's thousands of stick rows take Block 50-2,000 iterations a step; "
          "docs/performance.md, \"Defaults and why\")");
  sol.set("Pressure Acceleration Depth", 5,
          "Anderson acceleration depth of the pressure loop (0 = plain pbar <- p(x))");
  sol.set("Minimum Solve Penalty", -1.0,
          "Smallest eps1 x c used in the Newton solves: below it the condensed pressure "
          "cannot be evaluated in double precision; the pressure loop still makes v_e = V_e exact. "
          "-1: automatic, 3e-2 with the Saddle Point pressure update without friction, 1e-2 otherwise "
          "(and where the pressure loop is monolithic)");
  sol.sublist("NOX", false, "Passed to NOX unchanged, over capstan's defaults (NOX ignores names it does not read: a name NOX did not read in the run's first Newton solve is a warning)");
  sol.sublist("Stratimikos", false, "Passed to Stratimikos unchanged, over capstan's defaults (Ifpack2's block relaxation, which crashes in Trilinos 13.2, is refused)");
  sol.sublist("Belos", false,
              "Passed to the Belos solver (Block GMRES, or Pseudo Block CG with Linear Solver = CG) unchanged, "
              "over capstan's defaults; its names, types and values are checked against the solver's (unused with Direct)");
  sol.sublist("Ifpack2", false,
              "Passed to the Ifpack2 preconditioner (Preconditioner = ILU or Jacobi) unchanged, over capstan's "
              "defaults (unused with the other preconditioners; block relaxation refused)");
}

SolverSettings SolverSettings::parse(const ParameterList& sol, const ParameterReader& r, bool friction,
                                     bool rolling, bool steady) {
  const std::string at = "Solver";
  SolverSettings s;
  s.linearSolver = r.choice(sol, at, "Linear Solver", linearSolvers);
  s.unsymmetric = friction || steady;
  s.directSolverMaxDofs = r.atLeast(sol, at, "Direct Solver Max Dofs", 0);
  s.preconditioner = r.choice(sol, at, "Preconditioner", preconditioners);
  s.iluLevel = r.atLeast(sol, at, "ILU Level", 0);
  s.preconditionerReuse = r.choice(sol, at, "Preconditioner Reuse",
                                   std::vector<std::pair<const char*, Reuse>>{{"Adaptive", Reuse::Adaptive},
                                                                              {"None", Reuse::None}});
  s.linearTolerance = r.fraction(sol, at, "Linear Tolerance");
  s.linearToleranceMethod = r.choice(sol, at, "Linear Tolerance Method",
                                     std::vector<std::pair<const char*, ToleranceMethod>>{
                                         {"Adaptive", ToleranceMethod::Adaptive}, {"Fixed", ToleranceMethod::Fixed}});
  s.maxLinearIterations = r.atLeast(sol, at, "Max Linear Iterations", 1);
  s.newtonRelativeTolerance = r.fraction(sol, at, "Newton Relative Tolerance");
  s.newtonAbsoluteTolerance = sol.get<double>("Newton Absolute Tolerance");
  if (!(s.newtonAbsoluteTolerance >= 0)) r.fail("Solver/Newton Absolute Tolerance", "must be >= 0");
  s.maxNewtonIterations = r.atLeast(sol, at, "Max Newton Iterations", 0);
  if (s.maxNewtonIterations == 0) s.maxNewtonIterations = friction && (rolling || steady) ? 60 : 30;
  s.crawlIterations = friction ? 0 : 10;
  s.predictor = r.choice(sol, at, "Predictor",
                         std::vector<std::pair<const char*, Predictor>>{{"Tangent", Predictor::Tangent},
                                                                        {"Previous", Predictor::Previous}});
  s.rollingPredictor = r.choice(sol, at, "Rolling Predictor",
                                std::vector<std::pair<const char*, RollingPredictor>>{
                                    {"Rigid Roll", RollingPredictor::RigidRoll},
                                    {"Streamline Shift", RollingPredictor::StreamlineShift}});
  s.lineSearch = r.choice(sol, at, "Line Search", lineSearches);
  s.volumeTolerance = r.fraction(sol, at, "Volume Tolerance");
  s.maxPressureIterations = r.atLeast(sol, at, "Max Pressure Iterations", 1);
  // Auto: without friction the saddle-point step alone (Monolithic) where linear solves are exact,
  // else after each Newton solve, as for rolling with friction; other friction scenes keep
  // Anderson, as the step changes their stick/slip path (docs/performance.md, "Defaults and why").
  enum class Update { Auto, SaddlePoint, Monolithic, Anderson };
  const Update update = r.choice(sol, at, "Pressure Update",
                                 std::vector<std::pair<const char*, Update>>{{"Auto", Update::Auto},
                                                                             {"Saddle Point", Update::SaddlePoint},
                                                                             {"Monolithic", Update::Monolithic},
                                                                             {"Anderson", Update::Anderson}});
  if (update == Update::Monolithic && friction)
    r.fail("Solver/Pressure Update", "Monolithic takes no friction (a capstan has Friction); use Saddle Point or Auto");
  s.monolithic = update == Update::Monolithic || (update == Update::Auto && !friction);
  s.monolithicIfExact = update == Update::Auto;
  s.pressureUpdate = update == Update::SaddlePoint || s.monolithic || (update == Update::Auto && (rolling || steady))
                         ? PressureUpdate::SaddlePoint
                         : PressureUpdate::Anderson;
  s.saddlePointIfAndersonFails = update == Update::Auto && s.pressureUpdate == PressureUpdate::Anderson;
  s.pressureStepSchur = r.choice(sol, at, "Pressure Step Schur",
                                 std::vector<std::pair<const char*, Schur>>{
                                     {"Auto", Schur::Auto}, {"Laplacian", Schur::Laplacian}, {"Diagonal", Schur::Diagonal}});
  s.pressureStepPreconditioner = r.choice(sol, at, "Pressure Step Preconditioner",
                                          std::vector<std::pair<const char*, StepPreconditioner>>{
                                              {"Auto", StepPreconditioner::Auto},
                                              {"Block", StepPreconditioner::Block},
                                              {"LU", StepPreconditioner::LU}});
  s.pressureStepOnNewtonsFactors =
      r.choice(sol, at, "Pressure Step Factorisation",
               std::vector<std::pair<const char*, bool>>{{"Newton's", true}, {"New", false}});
  s.pressureAccelerationDepth = r.atLeast(sol, at, "Pressure Acceleration Depth", 0);
  // Automatic: the fastest on G1 for each update, 3e-2 with the saddle-point step and 1e-2 with
  // Anderson; 1e-2 with friction and for the monolithic loop (kMonolithicSolvePenalty, set by
  // Model) (docs/performance.md, "Defaults and why").
  s.minimumSolvePenalty = sol.get<double>("Minimum Solve Penalty");
  if (!(s.minimumSolvePenalty > 0 || s.minimumSolvePenalty == -1) || !std::isfinite(s.minimumSolvePenalty))
    r.fail("Solver/Minimum Solve Penalty", "must be > 0, or -1 (automatic), got " + shortest(s.minimumSolvePenalty));
  s.minimumSolvePenaltyAutomatic = s.minimumSolvePenalty == -1;
  if (s.minimumSolvePenaltyAutomatic)
    s.minimumSolvePenalty = s.pressureUpdate == PressureUpdate::SaddlePoint && !friction ? 3e-2 : 1e-2;
  s.nox = sol.sublist("NOX");
  for (const char* pass : {"Stratimikos", "Ifpack2"}) {
    const std::string found = blockRelaxationIn(sol.sublist(pass), std::string("Solver/") + pass);
    if (!found.empty())
      r.fail(found.substr(0, found.find(" = ")),
             "Ifpack2's block relaxation (" + found.substr(found.find(" = ") + 3) +
                 ") crashes on capstan's matrices in Trilinos 13.2; use RELAXATION or CHEBYSHEV");
  }
  s.stratimikos = sol.sublist("Stratimikos");
  // capstan's own MUMPS lists, checked whether or not this run builds the solver they set.
  for (const char* kind : {"Linear Solver Types", "Preconditioner Types"}) {
    if (!s.stratimikos.isSublist(kind) || !s.stratimikos.sublist(kind).isSublist("MUMPS")) continue;
    try {
      mumpsOptionsFrom(s.stratimikos.sublist(kind).sublist("MUMPS"));
    } catch (const MumpsParameterError& e) {
      r.fail(std::string("Solver/Stratimikos/") + kind + "/MUMPS/" + e.name, e.what());
    }
  }
  s.belos = sol.sublist("Belos");
  s.ifpack2 = sol.sublist("Ifpack2");
  return s;
}

SolverSettings SolverSettings::resolved(long dofs, bool annulus, bool friction, bool steady) const {
  SolverSettings s = *this;
  s.gradedRings = gradedRings || annulus;  // NewtonSolver resolves again, knowing no mesh
  // Auto's direct size: 50,000 on an annulus; on a box 5,000, and 40,000 for the monolithic loop
  // (no friction), whose steps a factorisation of the symmetric part serves better than MueLu's
  // V-cycle up to about there (docs/performance.md, "Defaults and why").
  const long most = s.directSolverMaxDofs > 0 ? s.directSolverMaxDofs
                    : annulus                  ? 50000
                    : s.monolithic && !friction ? 40000
                                               : 5000;
  if (s.linearSolver == LinearSolver::Auto && steady) {
    // Steady rolling: a factorisation every Newton iteration up to the direct solver's size, GMRES
    // with a kept one above (docs/steady-rolling.md, "Measurements"). Never MueLu: omega's row
    // (the torque balance) has no diagonal, which smoothers cannot take.
    s.linearSolver = dofs > most ? LinearSolver::GMRES : LinearSolver::Direct;
    if (s.linearSolver == LinearSolver::GMRES && s.preconditioner == Preconditioner::Auto)
      s.preconditioner = Preconditioner::LU;
  }
  if (s.linearSolver == LinearSolver::Auto) {
    if (dofs > most) {
      s.linearSolver = LinearSolver::GMRES;
    } else if (friction) {
      // Friction changes Newton's matrix much from one iteration to the next:
      // a new factorisation each time beats reusing one (the 3D drive: 40 ms a
      // Newton iteration against 44 ms with GMRES + LU, 334 ms with MueLu).
      s.linearSolver = LinearSolver::Direct;
    } else {
      // Without it, one factorisation serves several Newton iterations (G1:
      // 0.54 s against 0.81 s factorising each time; the Hertz ring: 1.69 s
      // against 2.45 s).
      s.linearSolver = LinearSolver::GMRES;
      if (s.preconditioner == Preconditioner::Auto) s.preconditioner = Preconditioner::LU;
    }
  }
  if (s.preconditioner == Preconditioner::Auto)  // steady rolling: never MueLu (above)
    s.preconditioner = steady ? Preconditioner::LU : dofs >= 1000 ? Preconditioner::MueLu : Preconditioner::ILU;
  return s;
}

SolverSettings SolverSettings::defaults(bool friction, bool rolling, bool steady) {
  ParameterList list;
  declare(list);
  return parse(list, ParameterReader{"(defaults)"}, friction, rolling, steady);
}

}  // namespace capstan
