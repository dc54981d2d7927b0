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

// A stall: |R| fell by less than 1 - factor over the last `window` iterations (window 0: no test).
struct StallRule {
  int window = 0;
  double factor = 1;
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
  // While set, a solve fails on a stall (StallRule): for solves whose failure has a cheaper way
  // on, as steady rolling's start (docs/steady-rolling.md, "Failed tries in the start"). Off
  // (StallRule{}) by default.
  void failOnStall(StallRule rule);
  StallRule stallRule() const;
  // The same for pseudo-time (pseudoTransient), whose |R| swings: it fails where its lowest |R|
  // fell by less than 1 - factor over the last `window` iterations. Off by default.
  void failPseudoTimeOnStall(StallRule rule);
  StallRule pseudoTimeStallRule() const;
  // Pseudo-transient continuation (Kelley and Keyes 1998) to |R| <= tolerance: Newton with
  // |diag W| / dtau on the diagonal. Small dtau follows the force across rising |R| and indefinite
  // tangents, where the line search stalls; a failed solve's fallback. stepLengths: dtau.
  // dtau doubles after a step that keeps |R| within 1.5x; with `growWithFall`, by |R|'s fall
  // where that is more (where the answer does not depend on the path: docs/friction.md).
  NewtonResult pseudoTransient(Vector& u, double tolerance, bool growWithFall);
  // One solve W x = b with matrix() as the caller assembled it (x: guess in, answer out), to the
  // relative `tolerance`, at most `maxIterations` if > 0: Krylov iterations, -1 on failure. Own: a
  // new preconditioner; Kept: Newton's, built if due; KeptAsBuilt: Newton's as it is.
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
  // z = K~^-1 r for matrix() as it is now: Newton's preconditioner (built if none), or for a direct
  // solver a factorisation made here, or with `afterNewton` Newton's last (one Newton step old).
  // Its set-up counts as linear solve time; its applications are the caller's to time.
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
  // Once, after the run's first Newton solve that took an iteration: the scene's Solver/NOX
  // parameters (paths below Solver/NOX) that NOX did not read there. NOX ignores what it does not
  // read, so such a name is misspelt or belongs to a method this run does not use. With runEnded
  // and no such solve yet (the monolithic pressure loop's Newton is capstan's own): all of them.
  std::vector<std::string> takeUnreadNoxParameters(bool runEnded = false);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A solver's stall rules (Newton's, and pseudo-time's) for a scope; the ones before them again at
// the scope's end.
class ScopedStallRule {
 public:
  ScopedStallRule(NewtonSolver& newton, StallRule rule, StallRule pseudoTime = {})
      : newton_(newton), before_(newton.stallRule()), pseudoTimeBefore_(newton.pseudoTimeStallRule()) {
    newton_.failOnStall(rule);
    newton_.failPseudoTimeOnStall(pseudoTime);
  }
  ~ScopedStallRule() {
    newton_.failOnStall(before_);
    newton_.failPseudoTimeOnStall(pseudoTimeBefore_);
  }
  ScopedStallRule(const ScopedStallRule&) = delete;
  ScopedStallRule& operator=(const ScopedStallRule&) = delete;

 private:
  NewtonSolver& newton_;
  StallRule before_, pseudoTimeBefore_;
};

}  // namespace capstan
