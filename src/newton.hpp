// Newton's method for the assembled residual: NOX (line search Newton) on a
// Thyra model evaluator, linear solves by the factories of
// src/linear_solver_factories.hpp (MUMPS, Belos + MUMPS, or Stratimikos' builder
// in the krylov plugin). newton.cpp and that file include NOX's and Thyra's heavy
// headers; the plugin includes Stratimikos', Ifpack2's and MueLu's.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "assembly.hpp"
#include "solver_settings.hpp"

namespace capstan {

struct NewtonResult {
  bool converged = false;
  int iterations = 0;
  int linearIterations = 0;
  double residualNorm = 0;
  std::vector<double> residualHistory;  // |R| at the start and after each iteration
  std::vector<double> stepLengths;      // the line search's step length at each iteration
  std::string failure;                  // why it did not converge
};

class NewtonSolver {
 public:
  // `solver`: its Auto choices are resolved here (SolverSettings::resolved)
  // if the caller has not resolved them for the scene's kind.
  NewtonSolver(Assembly& assembly, const SolverSettings& solver);
  ~NewtonSolver();
  // Solves R(u) = 0 from the initial guess u (updated in place) until
  // |R| <= tolerance.
  NewtonResult solve(Vector& u, double tolerance);
  // Pseudo-transient continuation (Kelley and Keyes, SIAM J. Numer. Anal. 35,
  // 1998) from u (updated in place) until |R| <= tolerance: Newton steps with
  // D / dtau added to the tangent's diagonal (D = |diag W|), every step that
  // neither inverts an element nor multiplies |R| by 10 accepted, dtau
  // doubled after a step that kept |R| within 1.5x and did not turn back on
  // the last one (a cycle across a kink), else halved. Small dtau follows the
  // flow du/dtau = -D^-1 R(u),
  // which moves along the unbalanced force rather than down |R|: it crosses a
  // region where |R| rises on the way to the root, which Newton's line search
  // cannot, and it stays stable where the tangent is indefinite (a soft body
  // dragged by friction whose force grows faster than its support's; docs/
  // friction.md, "What step 2 is"). Large dtau is Newton's step. A fallback
  // for a failed solve (src/augmentation.cpp); stepLengths holds dtau.
  NewtonResult pseudoTransient(Vector& u, double tolerance);
  // One linear solve W x = b with Newton's matrix W = matrix(), as the caller
  // assembled it, and the configured solver with a preconditioner of its own
  // (x: initial guess in, solution out), to the relative residual `tolerance`
  // (Krylov solvers). Newton reassembles W before it next solves.
  // `preconditioner`: Own (a new one), Kept (the one Newton keeps, Solver/
  // Preconditioner Reuse; built now if none is or a rebuild is due) or
  // KeptAsBuilt (the one Newton keeps as it is, however old: keepsFactorisation()
  // says whether there is one). `maxIterations` > 0: at most that many Krylov
  // iterations (fewer than the scene's limit).
  // Returns the Krylov iterations, or -1 if it failed.
  enum class Preconditioner { Own, Kept, KeptAsBuilt };
  int linearSolve(const Vector& b, Vector& x, double tolerance, Preconditioner preconditioner = Preconditioner::Own,
                  int maxIterations = 0);
  // Whether Newton keeps a factorisation built earlier (GMRES with the LU
  // preconditioner), for KeptAsBuilt.
  bool keepsFactorisation() const;
  // Newton's next linear solve builds a new preconditioner (with Solver/
  // Preconditioner Reuse = Adaptive it is otherwise kept while it works).
  void rebuildPreconditioner();
  // Newton's matrix (values: whatever was last assembled into it).
  RCP<FEMatrix> matrix() const;
  // z = K~^-1 r, an approximate inverse of matrix() as its values are now:
  // Newton's preconditioner (built if it has none yet), or, for a direct
  // solver, a factorisation made once here, or with `afterNewton` (matrix()
  // assembled where a Newton solve just converged) the one Newton made last,
  // one Newton step before. Building it counts as linear solve time (set-up
  // as preconditioner set-up); its applications are the caller's to time.
  std::function<void(const Vector& r, Vector& z)> approximateInverse(bool afterNewton = false);
  double linearSolveSeconds() const;
  // A failure that may be this rank's alone (a solver's exception), agreed
  // over the ranks: the lowest failed rank's message, empty where none failed
  // (FailureAgreement: a job whose other ranks are stuck in the solver ends).
  std::string agree(const std::string& failure) const;
  // The part of linearSolveSeconds() spent setting up preconditioners.
  double preconditionerSeconds() const;
  // Preconditioners Newton has built so far (the lagged one; CAPSTAN_NEWTON_LOG).
  int preconditionerBuilds() const;
  // Whether approximateInverse() is only approximate: a Krylov solver's
  // multigrid or ILU preconditioner (false: a direct solver, or an LU
  // preconditioner, whose inverse is that of a matrix near Newton's).
  bool iterative() const;
  // Whether Newton's solves are direct (a factorisation every iteration).
  bool direct() const;
  // The linear solver and preconditioner parameters in use (Stratimikos list).
  const Teuchos::ParameterList& linearSolverParameters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace capstan
