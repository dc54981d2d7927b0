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

#include "types.hpp"

namespace capstan {

struct MumpsOptions {
  // Fill-reducing ordering of the (sequential) analysis. Debian's libmumps has
  // neither METIS nor SCOTCH compiled in (ICNTL(7) = 5 silently falls back to
  // AMF), so Metis computes METIS_NodeND's ordering here, on rank 0 from the
  // gathered pattern of A + A^T, and hands it to MUMPS (ICNTL(7) = 1, PERM_IN).
  // Measured on a 3D 27-point, 3-dof elasticity-like stencil, 52,728 unknowns,
  // 1 rank, Debian's reference BLAS (test_mumps, MumpsTiming; factor entries,
  // factorisation time): Metis 78 M, 34-36 s; Pord 91 M, 58-61 s; AMF 112 M,
  // 113-120 s; AMD and QAMD 120 M, 103-155 s. The analysis takes 0.2-0.6 s
  // with any of them (Metis' includes gathering the pattern and METIS_NodeND).
  // The factorisation is BLAS-bound: with OpenBLAS (one thread) in place of the
  // reference BLAS, Metis 3.8 s, Pord 5.4 s, AMF 7.8 s (2 ranks, Metis: 2.3 s).
  // Auto (the default): METIS and QAMD both analysed, the one the analysis
  // estimates at fewer factorisation flops kept. The 3D drive (4,806
  // unknowns, a thin ring): QAMD 1.38e8 flops against METIS 2.03e8, 8% less
  // time per Newton iteration; the Hertz ring (15,126): METIS 8.4e8 against
  // 1.07e9 (docs/performance.md, "Linear solvers").
  enum class Ordering { Auto, Metis, Pord, Amd, Amf, Qamd };
  Ordering ordering = Ordering::Auto;
  // ICNTL(14): percentage by which the working space may grow over the
  // analysis' estimate (delayed pivots); < 0 keeps MUMPS' default. On
  // INFOG(1) = -8 or -9 it is raised and the factorisation retried once.
  int workspaceIncreasePercent = -1;
  // MUMPS' own printing (ICNTL(1..4)); silent by default.
  bool verbose = false;
  // Row and column scaling before each factorisation (ICNTL(8) = 77, MUMPS'
  // automatic choice) or none (ICNTL(8) = 0). Off: the 3D drive's 422
  // factorisations (pinch-roller.xml, 2 steps) took 23.6 ms each against
  // 32.9 ms with scaling, with the same Newton iterations and answers (the
  // core's rotation 5.5e-12 apart); threshold pivoting still guards the
  // pivots (tests/integration/direct_solvers.py checks the answers).
  bool scaling = false;
  // Matrices with fewer rows than this are gathered onto rank 0 and factored
  // there alone (MUMPS on a communicator of one, centralised input); larger
  // ones are factored by all ranks. Time per Newton iteration on 2 ranks,
  // rank 0 alone against both (docs/performance.md, "Linear solvers"): the
  // slice (1,926 unknowns) 6.2-6.8 against 7.1-7.4 ms, G1 1x (1,575) 11.5-11.8
  // against 9.4-9.6 ms, the 3D drive (4,806) 26.1-27.3 against 17.3-19.1 ms
  // (1 rank: 27.1), the Hertz ring (15,126) 131-143 against 93-99 ms (1 rank:
  // 150). Below 2,000 it goes either way by up to 20%. 0: always all ranks.
  // Scene: Solver/Stratimikos/Linear Solver Types/MUMPS/Host Only Below.
  long hostOnlyBelow = 2000;
  // MUMPS sees only the entries that have been nonzero since the matrix graph
  // was built (and the diagonal); a zero entry that becomes nonzero joins the
  // pattern and the analysis is redone. Why: an effect's entity may couple
  // nodes that only act together where it is active. Steady rolling's friction couples each contact face to the
  // nodes upstream of it all around the roller, but only the faces in the nip
  // are active: with every entry the steady 3D drive's factors hold 1.81 M
  // entries (3.8e8 flops), with the nonzeros 0.68-0.85 M (0.7-1.2e8), and the
  // steady solve takes 1.55-1.68 s against 2.98 s. The quasi-static drive's
  // matrix has zeros too (MUMPS' graph: 197,760 edges against 285,602): its
  // factors 0.68 M entries against 1.10 M, 22.5-25.5 against 27.5-29.1 ms per
  // Newton iteration. The analyses it adds (4-7 a run, as the contact
  // zone settles) cost 3-24 ms each (docs/performance.md, "Linear solvers").
  // Off: the matrix graph's pattern, zeros and all.
  bool nonzeroPattern = true;
  // With nonzeroPattern: the entries of a row in one node's columns (its 3
  // unknowns) join the pattern together, once any of them is nonzero. A zero
  // inside a coupled node pair is then an accident of the values (an
  // undeformed regular mesh's symmetry), not an entity at rest, and its
  // turning nonzero later need not redo the analysis. capstan sets it with
  // symmetricPart (no friction): G1 2x one analysis against two, 1.40-1.43
  // against 1.53-1.62 s on 1 rank, 0.97-1.00 against 1.12-1.27 s on 2. Not
  // with friction: the steady 3D drive's factors grew from 0.73 to 0.84 M
  // entries (5 analyses against 7, the same run time).
  bool nonzeroNodeBlocks = false;
  // The factorisation's arithmetic. Single (smumps): half the factors' memory
  // and traffic, a factorisation accurate to about 1e-7 x the condition
  // number: a preconditioner for GMRES, which restores double precision, not
  // a solve of its own (the direct solve's factory refuses it).
  enum class Precision { Double, Single };
  Precision precision = Precision::Double;
  // Factor the symmetric part (A + A^T) / 2 as a symmetric matrix (LDL^T,
  // SYM = 2): about half the factors' entries and work, and a preconditioner
  // for GMRES only (not A's solve; the direct solve's factory refuses it).
  // capstan's frictionless tangents are nearly symmetric (Cauchy stress
  // 2c(B - I) is not hyperelastic off J = 1: |A - A^T| about 3e-3 of |A| on
  // G1). Transposes in other ranks' rows are exchanged at each
  // factorisation. G1 2x: docs/performance.md.
  bool symmetricPart = false;
};

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

  // Factorises A (fill complete, square, row map = domain map = range map, one
  // to one; any GIDs, contiguous or not). The first call, and any call whose
  // global sparsity pattern differs from the last one's (with nonzeroPattern:
  // whose nonzeros are not all in it), runs MUMPS' analysis; otherwise the
  // analysis is reused and only the numeric factorisation runs.
  // A must live on the communicator of the first call.
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
};

}  // namespace capstan
