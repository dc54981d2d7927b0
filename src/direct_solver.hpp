// A distributed sparse direct solver (MUMPS 5.5, Debian's MPI build) for
// capstan's Tpetra matrices. Why: the iterative solvers' iterations grow with the
// mesh and with friction's non-symmetry; an exact LU of the Newton tangent is the
// robust fallback, and Newton's tangents keep one sparsity pattern from iteration
// to iteration, so the costly symbolic analysis is done once and only the numeric
// factorisation is repeated.
//
// Each rank hands MUMPS its own rows (distributed assembled input, ICNTL(18) = 3,
// 1-based global indices; on one rank, or below MumpsOptions::hostOnlyBelow,
// the whole matrix on rank 0); right-hand sides are gathered to rank 0 (MUMPS'
// host) and the solution is scattered back. Unsymmetric mode (SYM = 0), or
// symmetric (SYM = 2) on A's symmetric part (MumpsOptions::symmetricPart). The
// factors are double (dmumps) or single precision (smumps, MumpsOptions::
// precision: for the LU preconditioner).
//
// Every method is collective over the matrix's communicator, the destructor too
// (MUMPS' JOB = -2): create and destroy a solver on every rank, before MPI is
// finalised. Errors are thrown on every rank alike (std::runtime_error naming
// the phase and MUMPS' INFOG(1), INFOG(2)), so a caller may catch and go on.
#pragma once

#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_MultiVector.hpp>

#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include "mumps_parameters.hpp"
#include "types.hpp"

namespace capstan {

class MumpsSolver {
 public:
  using Scalar = Tpetra::CrsMatrix<>::scalar_type;
  using CrsMatrix = Tpetra::CrsMatrix<>;
  using MultiVector = Tpetra::MultiVector<>;
  static_assert(std::is_same<Scalar, double>::value, "MumpsSolver takes double matrices (factored by dmumps or smumps)");

  explicit MumpsSolver(const MumpsOptions& options = MumpsOptions());
  ~MumpsSolver();
  MumpsSolver(const MumpsSolver&) = delete;
  MumpsSolver& operator=(const MumpsSolver&) = delete;

  // Factorises A (fill complete, square, row map = domain map = range map, one to one; any GIDs) on
  // the communicator of the first call. MUMPS' analysis runs first and whenever the global pattern
  // changes (with nonzeroPattern: gains a nonzero); otherwise only the numeric factorisation runs.
  void factor(const CrsMatrix& A);

  // Solves A x = b for every column of b (b on A's range map, x on its domain
  // map, as many columns as b). Throws std::logic_error if nothing is factored.
  void solve(const MultiVector& b, MultiVector& x);
  // Whether a factorisation is there to solve with.
  bool factored() const { return factored_; }

  // Counters (since construction).
  int numAnalyses() const { return numAnalyses_; }
  // MUMPS analyses run: Ordering = Auto runs two or three for one analysis.
  int numOrderingAnalyses() const { return numOrderingAnalyses_; }
  int numFactorizations() const { return numFactorizations_; }
  int numWorkspaceRetries() const { return numWorkspaceRetries_; }  // -8/-9 retries
  // Every instance's together, over the process (summary.json's timing.direct_solver): analyses
  // (as numAnalyses), factorisations, and right-hand sides solved.
  struct Counts {
    long analyses = 0, factorizations = 0, solves = 0;
  };
  static Counts processCounts() { return processCounts_; }

  // The last factorisation's size and memory: entries in the factors (INFOG(29),
  // all ranks) and MB used during the factorisation (INFOG(21): the largest on
  // any rank; INFOG(22): all ranks together).
  std::int64_t factorEntries() const;
  int peakMemoryMB() const;
  int totalMemoryMB() const;
  // The ordering MUMPS used (INFOG(7): 0 AMD, 1 given (Metis here), 2 AMF, 4 PORD, 6 QAMD).
  int orderingUsed() const;
  double estimatedFlops() const;  // the last analysis' estimate for one factorisation (RINFOG(1))

  // Wall times of the last analysis (with the pattern gathering and METIS),
  // factorisation and solve (with the gather and scatter), in seconds.
  double analysisSeconds() const { return analysisSeconds_; }
  double factorSeconds() const { return factorSeconds_; }
  double solveSeconds() const { return solveSeconds_; }

 private:
  struct Impl;  // MUMPS' structure stays out of the header
  void initialize(const Teuchos::Comm<int>& comm, bool hostOnly);
  void run(int job);  // MUMPS' JOB on the ranks that run it; INFOG on every rank
  bool extractPattern(const CrsMatrix& A);  // true if this rank's pattern changed
  // The values MUMPS reads; true if the kept set grew. Collective with symmetricPart.
  bool keepNonzeros(const CrsMatrix& A, bool fresh, bool newMirrors);
  void analyse(const CrsMatrix& A);
  void computeMetisOrdering();
  double analyseWith(MumpsOptions::Ordering ordering);  // one analysis; returns its estimated flops
  void runFactorization();
  void call(int job, const char* phase);
  int infog(int i) const;  // INFOG(i) of the last call (every rank), 0 before the instance exists

  MumpsOptions options_;
  std::unique_ptr<Impl> impl_;
  bool analysed_ = false, factored_ = false;
  int numAnalyses_ = 0, numOrderingAnalyses_ = 0, numFactorizations_ = 0, numWorkspaceRetries_ = 0;
  // Ordering = Auto: the winner of the last contest and the entries it was
  // decided on, kept for later analyses while the pattern has grown by less
  // than a tenth (contact or friction entries joining).
  MumpsOptions::Ordering autoWinner_ = MumpsOptions::Ordering::Auto;
  double autoWinnerEntries_ = 0;
  double analysisSeconds_ = 0, factorSeconds_ = 0, solveSeconds_ = 0;
  static Counts processCounts_;
};

}  // namespace capstan
