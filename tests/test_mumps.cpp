// MumpsSolver (src/direct_solver.hpp): solves of a non-symmetric 3D
// convection-diffusion operator with several right-hand sides, against a known
// solution; refactorisation reusing the analysis; a new analysis for a changed
// pattern; entries zero so far kept out of the pattern until they turn
// nonzero (MumpsOptions::nonzeroPattern); non-contiguous maps; the same answer as a one-rank solve of the same
// system; singular matrices throw (and the solver recovers). Run on 1 and 2
// ranks (test_mumps_2ranks). MumpsTiming prints the analysis and factorisation
// times of 3-dof elasticity-like stencils (the 52,728-unknown one is disabled:
// --gtest_also_run_disabled_tests; CAPSTAN_MUMPS_ORDERING=metis|pord|amd|amf|qamd).
#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <Thyra_DefaultLinearOpSource.hpp>
#include <Thyra_LinearOpWithSolveBase.hpp>
#include <Thyra_LinearOpWithSolveFactoryHelpers.hpp>
#include <Thyra_TpetraThyraWrappers.hpp>

#include <dlfcn.h>

#include "direct_solver.hpp"
#include "linear_solver_factories.hpp"
#include "mumps_solve_factory.hpp"

using namespace capstan;
using CrsMatrix = Tpetra::CrsMatrix<>;
using MultiVector = Tpetra::MultiVector<>;

namespace {

constexpr int NX = 6, NY = 5, NZ = 4, N = NX * NY * NZ;

// test_mumps_2ranks_distributed sets CAPSTAN_TEST_MUMPS_DISTRIBUTED: every
// matrix is then factored by all ranks; otherwise these small ones are
// gathered onto rank 0 (MumpsOptions::hostOnlyBelow).
MumpsOptions testOptions() {
  MumpsOptions o;
  if (std::getenv("CAPSTAN_TEST_MUMPS_DISTRIBUTED")) o.hostOnlyBelow = 0;
  return o;
}

RCP<const Comm> worldComm() { return Tpetra::getDefaultComm(); }
RCP<const Comm> selfComm() { return rcp(new Teuchos::MpiComm<int>(MPI_COMM_SELF)); }

RCP<const Map> contiguousMap(GO n, RCP<const Comm> comm) { return rcp(new Map(n, 0, comm)); }

// Round robin over the ranks, each rank's ids in decreasing order: neither
// contiguous nor sorted.
RCP<const Map> cyclicReversedMap(GO n, RCP<const Comm> comm) {
  std::vector<GO> mine;
  for (GO g = n - 1; g >= 0; --g)
    if (g % comm->getSize() == comm->getRank()) mine.push_back(g);
  return rcp(new Map(n, Teuchos::arrayViewFromVector(mine), 0, comm));
}

struct ConvDiff {
  double velocity = 1.0;   // scales the upwinded convection (1, 0.5, 0.25)
  double shift = 0.0;      // added to the diagonal
  bool farCouplings = false;  // couple g and N-1-g (a different pattern)
  double far = 1.0;           // scales those couplings (0: in the pattern, zero)
  bool symmetrised = false;   // (A + A^T) / 2 instead of A
};

// 7-point diffusion plus first-order upwind convection on the 6x5x4 grid,
// unknown g = i + NX (j + NY k); non-symmetric, diagonally dominant.
RCP<CrsMatrix> convectionDiffusion(RCP<const Map> map, const ConvDiff& c) {
  auto A = rcp(new CrsMatrix(map, 8));
  const double v[3] = {1.0 * c.velocity, 0.5 * c.velocity, 0.25 * c.velocity};
  for (LO l = 0; l < LO(map->getNodeNumElements()); ++l) {
    const GO g = map->getGlobalElement(l);
    const int i = g % NX, j = (g / NX) % NY, k = g / (NX * NY);
    std::vector<GO> cols{g};
    std::vector<double> vals{6.0 + v[0] + v[1] + v[2] + c.shift};
    auto add = [&](bool inside, GO col, double val) {
      if (inside) cols.push_back(col), vals.push_back(val);
    };
    // Upwind couplings -1 - v behind, -1 ahead; symmetrised, -1 - v/2 both ways.
    const double h = c.symmetrised ? 0.5 : 1.0;
    add(i > 0, g - 1, -1.0 - h * v[0]);
    add(i < NX - 1, g + 1, -1.0 - (1 - h) * v[0]);
    add(j > 0, g - NX, -1.0 - h * v[1]);
    add(j < NY - 1, g + NX, -1.0 - (1 - h) * v[1]);
    add(k > 0, g - NX * NY, -1.0 - h * v[2]);
    add(k < NZ - 1, g + NX * NY, -1.0 - (1 - h) * v[2]);
    if (c.farCouplings) add(true, N - 1 - g, c.far * (c.symmetrised ? 0.15 : g < N / 2 ? 0.7 : -0.4));
    A->insertGlobalValues(g, Teuchos::arrayViewFromVector(cols), Teuchos::arrayViewFromVector(vals));
  }
  A->fillComplete();
  return A;
}

// Known solutions: column c is x(g) = sin(0.3 g + c) + 0.1 c.
RCP<MultiVector> knownSolution(RCP<const Map> map, int nrhs) {
  auto x = rcp(new MultiVector(map, nrhs));
  for (int c = 0; c < nrhs; ++c) {
    auto xc = x->getDataNonConst(c);
    for (LO l = 0; l < LO(map->getNodeNumElements()); ++l)
      xc[l] = std::sin(0.3 * double(map->getGlobalElement(l)) + c) + 0.1 * c;
  }
  return x;
}

// Solves A x = A x_true and checks every column's relative residual and error.
RCP<MultiVector> solveAndCheck(MumpsSolver& solver, const CrsMatrix& A, int nrhs, double errTol = 1e-10) {
  auto map = A.getRowMap();
  auto xTrue = knownSolution(map, nrhs);
  MultiVector b(map, nrhs), r(map, nrhs);
  A.apply(*xTrue, b);
  auto x = rcp(new MultiVector(map, nrhs));
  solver.solve(b, *x);
  A.apply(*x, r);
  r.update(1.0, b, -1.0);
  std::vector<double> rn(nrhs), bn(nrhs), en(nrhs);
  r.norm2(rn);
  b.norm2(bn);
  MultiVector e(*xTrue, Teuchos::Copy);
  e.update(1.0, *x, -1.0);
  e.normInf(en);
  for (int c = 0; c < nrhs; ++c) {
    EXPECT_LT(rn[c] / bn[c], 1e-12) << "column " << c;
    EXPECT_LT(en[c], errTol) << "column " << c;
  }
  return x;
}

// GMRES (Block GMRES to 1e-13) preconditioned by a MUMPS factorisation, as
// Stratimikos lists it.
Teuchos::ParameterList gmresWithMumps() {
  Teuchos::ParameterList gmres;
  gmres.set("Linear Solver Type", "Belos");
  gmres.set("Preconditioner Type", "MUMPS");
  auto& belos = gmres.sublist("Linear Solver Types").sublist("Belos");
  belos.set("Solver Type", "Block GMRES");
  belos.sublist("Solver Types").sublist("Block GMRES").set("Convergence Tolerance", 1e-13);
  return gmres;
}

// Solves A x = b through the factories (with their preconditioner, if any)
// as NOX does; expects convergence and returns x and the Krylov iterations.
RCP<MultiVector> solveThrough(const LinearSolverFactories& f, const RCP<const CrsMatrix>& A, const MultiVector& b,
                              int& iterations) {
  auto op = Thyra::createConstLinearOp(Teuchos::rcp_implicit_cast<const Tpetra::Operator<>>(A));
  auto space = Thyra::createVectorSpace<double>(A->getRowMap());
  RCP<Thyra::LinearOpWithSolveBase<double>> lows;
  if (f.prec.is_null()) {
    lows = Thyra::linearOpWithSolve<double>(*f.lows, op);
  } else {
    auto prec = f.prec->createPrec();
    f.prec->initializePrec(Thyra::defaultLinearOpSource<double>(op), prec.get());
    lows = f.lows->createOp();
    f.lows->initializePreconditionedOp(Thyra::defaultLinearOpSource<double>(op), prec, lows.get());
  }
  auto x = rcp(new MultiVector(A->getRowMap(), b.getNumVectors()));
  auto xt = Thyra::createMultiVector(x, space);
  auto bt = Thyra::createConstMultiVector(Teuchos::rcpFromRef(b), space);
  const auto status = Thyra::solve<double>(*lows, Thyra::NOTRANS, *bt, xt.ptr());
  EXPECT_EQ(status.solveStatus, Thyra::SOLVE_STATUS_CONVERGED);
  iterations = status.extraParameters.is_null() ? 0 : status.extraParameters->get("Iteration Count", 0);
  return Thyra::TpetraOperatorVectorExtraction<double>::getTpetraMultiVector(xt);
}

// The largest error of x's columns against the known solution's.
double errorAgainst(const MultiVector& xTrue, const MultiVector& x) {
  MultiVector e(xTrue, Teuchos::Copy);
  e.update(1.0, x, -1.0);
  std::vector<double> en(x.getNumVectors());
  e.normInf(en);
  return *std::max_element(en.begin(), en.end());
}

}  // namespace

TEST(Mumps, SolvesConvectionDiffusionWithThreeRightHandSides) {
  auto A = convectionDiffusion(contiguousMap(N, worldComm()), ConvDiff{});
  MumpsSolver solver(testOptions());
  solver.factor(*A);
  solveAndCheck(solver, *A, 3);
  EXPECT_EQ(solver.numAnalyses(), 1);
  EXPECT_EQ(solver.numFactorizations(), 1);
  EXPECT_EQ(solver.orderingUsed(), 1);  // the METIS ordering, handed over
  EXPECT_GT(solver.factorEntries(), A->getGlobalNumEntries() / 2);
  EXPECT_GE(solver.peakMemoryMB(), 0);  // whole MB: 0 for this small one
  EXPECT_GE(solver.totalMemoryMB(), solver.peakMemoryMB());
  EXPECT_GE(solver.analysisSeconds(), 0.0);
  EXPECT_GE(solver.factorSeconds(), 0.0);
  EXPECT_GE(solver.solveSeconds(), 0.0);
}

// The layer Newton, the predictor and the pressure step solve through: Thyra
// operators from MumpsSolveFactory. Two operators of one pattern share one
// analysis, each solve uses its own operator's values (refactored when the
// other was factored since), and several right-hand sides solve at once.
TEST(MumpsThyra, OperatorsShareTheAnalysisAndSolveWithTheirOwnValues) {
  using Converter = Thyra::TpetraOperatorVectorExtraction<double>;
  auto map = contiguousMap(N, worldComm());
  auto A = convectionDiffusion(map, ConvDiff{});
  auto B = convectionDiffusion(map, ConvDiff{0.5, 1.0, false});  // same pattern, other values
  auto factory = rcp(new MumpsSolveFactory);
  factory->setParameterList(Teuchos::parameterList());
  auto thyra = [&](const RCP<CrsMatrix>& M) {
    return Thyra::createConstLinearOp(Teuchos::rcp_implicit_cast<const Tpetra::Operator<>>(M));
  };
  auto solveWith = [&](const Thyra::LinearOpWithSolveBase<double>& lows, const CrsMatrix& M) {
    auto xTrue = knownSolution(map, 3);
    auto b = rcp(new MultiVector(map, 3)), x = rcp(new MultiVector(map, 3));
    M.apply(*xTrue, *b);
    auto space = Thyra::createVectorSpace<double>(map);
    auto bt = Thyra::createConstMultiVector(RCP<const MultiVector>(b), space);
    auto xt = Thyra::createMultiVector(x, space);
    const auto status = Thyra::solve<double>(lows, Thyra::NOTRANS, *bt, xt.ptr());
    EXPECT_EQ(status.solveStatus, Thyra::SOLVE_STATUS_CONVERGED);
    MultiVector e(*xTrue, Teuchos::Copy);
    e.update(1.0, *Converter::getTpetraMultiVector(xt), -1.0);
    std::vector<double> en(3);
    e.normInf(en);
    for (int c = 0; c < 3; ++c) EXPECT_LT(en[c], 1e-10) << "column " << c;
  };
  auto lowsA = Thyra::linearOpWithSolve<double>(*factory, thyra(A));
  auto lowsB = Thyra::linearOpWithSolve<double>(*factory, thyra(B));
  const MumpsSolver& solver = *factory->shared()->solver;
  EXPECT_EQ(solver.numAnalyses(), 1) << "one pattern, one analysis";
  EXPECT_EQ(solver.numFactorizations(), 2);
  solveWith(*lowsB, *B);
  EXPECT_EQ(solver.numFactorizations(), 2) << "B is factored: solved as it is";
  solveWith(*lowsA, *A);
  EXPECT_EQ(solver.numFactorizations(), 3) << "A refactored after B";
  solveWith(*lowsA, *A);
  EXPECT_EQ(solver.numFactorizations(), 3);
  // A changed pattern: the next operator gets a new analysis.
  auto C = convectionDiffusion(map, ConvDiff{1.0, 0.0, true});
  auto lowsC = Thyra::linearOpWithSolve<double>(*factory, thyra(C));
  EXPECT_EQ(solver.numAnalyses(), 2);
  solveWith(*lowsC, *C);
  // An unknown ordering is an error naming it.
  auto bad = Teuchos::parameterList();
  bad->set("Ordering", "Nested");
  EXPECT_THROW(factory->setParameterList(bad), std::invalid_argument);
  auto negative = Teuchos::parameterList();  // so is a negative size
  negative->set("Host Only Below", -1);
  EXPECT_THROW(factory->setParameterList(negative), std::invalid_argument);
}

// GMRES with the MUMPS preconditioner and the direct solve are built without
// Stratimikos' builder (no MueLu, Ifpack2 or Stratimikos library loaded), and
// give what the builder in the krylov plugin gives for the same list.
TEST(LinearSolverFactories, BuiltInListsMatchTheBuilderWithoutLoadingIt) {
  using capstan::builtWithoutStratimikos;
  using capstan::linearSolverFactories;
  Teuchos::ParameterList direct;
  direct.set("Linear Solver Type", "MUMPS");
  direct.set("Preconditioner Type", "None");
  Teuchos::ParameterList gmres = gmresWithMumps();
  gmres.sublist("Preconditioner Types").sublist("MUMPS").set("Ordering", "AMD");
  EXPECT_TRUE(builtWithoutStratimikos(direct));
  EXPECT_TRUE(builtWithoutStratimikos(gmres));
  auto other = [](Teuchos::ParameterList p, const std::string& path, const std::string& value) {
    if (path.find('/') == std::string::npos) p.set(path, value);
    else p.sublist(path.substr(0, path.find('/'))).sublist(path.substr(path.find('/') + 1));
    return p;
  };
  EXPECT_FALSE(builtWithoutStratimikos(other(gmres, "Preconditioner Type", "MueLu")));
  EXPECT_FALSE(builtWithoutStratimikos(other(gmres, "Preconditioner Type", "Ifpack2")));
  EXPECT_FALSE(builtWithoutStratimikos(other(direct, "Preconditioner Type", "MUMPS")));
  EXPECT_FALSE(builtWithoutStratimikos(other(gmres, "Linear Solver Type", "Amesos2")));
  EXPECT_FALSE(builtWithoutStratimikos(other(gmres, "Enable Delayed Solver Construction", "x")));
  EXPECT_FALSE(builtWithoutStratimikos(other(gmres, "Linear Solver Types/AztecOO", "")));
  EXPECT_FALSE(builtWithoutStratimikos(other(direct, "Preconditioner Types/MUMPS", "")));

  const bool builderLoadedBefore = dlopen("libtrilinos_stratimikos.so.13.2", RTLD_NOW | RTLD_NOLOAD) != nullptr;
  auto map = contiguousMap(N, worldComm());
  auto A = convectionDiffusion(map, ConvDiff{});
  auto xTrue = knownSolution(map, 1);
  MultiVector b(map, 1);
  A->apply(*xTrue, b);
  auto solve = [&](const capstan::LinearSolverFactories& f, int& iterations) { return solveThrough(f, A, b, iterations); };
  int directIts = -1, gmresIts = -1, pluginIts = -1;
  auto xDirect = solve(linearSolverFactories(direct), directIts);
  auto xGmres = solve(linearSolverFactories(gmres), gmresIts);
  if (!builderLoadedBefore) {
    EXPECT_EQ(dlopen("libtrilinos_stratimikos.so.13.2", RTLD_NOW | RTLD_NOLOAD), nullptr)
        << "a built-in list loaded Stratimikos' builder";
  }
  // The same GMRES list through the builder (an unused sublist sends it there).
  auto viaBuilder = linearSolverFactories(other(gmres, "Linear Solver Types/AztecOO", ""));
  EXPECT_NE(dlopen("libtrilinos_stratimikos.so.13.2", RTLD_NOW | RTLD_NOLOAD), nullptr);
  auto xPlugin = solve(viaBuilder, pluginIts);
  EXPECT_EQ(gmresIts, pluginIts);
  EXPECT_GE(gmresIts, 1);
  for (const auto& x : {xDirect, xGmres, xPlugin}) EXPECT_LT(errorAgainst(*xTrue, *x), 1e-10);
  // A bad value in a built-in list is still an error naming it.
  auto bad = gmres;
  bad.sublist("Preconditioner Types").sublist("MUMPS").set("Ordering", "Nested");
  EXPECT_THROW(linearSolverFactories(bad), std::invalid_argument);
}

// Precision = Single: the factors in float (smumps). A solve is accurate to
// float's precision only, on every rank count; GMRES with the factorisation as
// its preconditioner restores double precision in a few more iterations; the
// direct solve's factory refuses it.
TEST(Mumps, SinglePrecisionSolvesToFloatAccuracyAndPreconditionsGmresToDouble) {
  auto map = contiguousMap(N, worldComm());
  auto A = convectionDiffusion(map, ConvDiff{});
  MumpsOptions single = testOptions();
  single.precision = MumpsOptions::Precision::Single;
  MumpsSolver solver(single);
  for (double velocity : {1.0, 0.5}) {  // a refactorisation with the same pattern too
    auto Av = convectionDiffusion(map, ConvDiff{velocity});
    solver.factor(*Av);
    auto xTrue = knownSolution(map, 2);
    MultiVector b(map, 2), x(map, 2);
    Av->apply(*xTrue, b);
    solver.solve(b, x);
    x.update(-1.0, *xTrue, 1.0);
    std::vector<double> en(2);
    x.normInf(en);
    for (int c = 0; c < 2; ++c) {
      EXPECT_LT(en[c], 1e-5) << "column " << c;   // float: about 1e-7 x the condition number
      EXPECT_GT(en[c], 1e-12) << "column " << c;  // and not double's accuracy
    }
  }
  EXPECT_EQ(solver.numAnalyses(), 1);
  EXPECT_EQ(solver.numFactorizations(), 2);

  auto xTrue = knownSolution(map, 1);
  MultiVector b(map, 1);
  A->apply(*xTrue, b);
  auto gmresSolve = [&](const std::string& precision, int& iterations) {
    auto list = gmresWithMumps();
    list.sublist("Preconditioner Types").sublist("MUMPS").set("Precision", precision);
    EXPECT_LT(errorAgainst(*xTrue, *solveThrough(capstan::linearSolverFactories(list), A, b, iterations)), 1e-11)
        << precision;
  };
  int doubleIts = 0, singleIts = 0;
  gmresSolve("Double", doubleIts);
  gmresSolve("Single", singleIts);
  EXPECT_GT(singleIts, doubleIts);       // the float factors are not exact
  EXPECT_LE(singleIts, doubleIts + 4);  // but nearly
  Teuchos::ParameterList direct;
  direct.set("Linear Solver Type", "MUMPS");
  direct.set("Preconditioner Type", "None");
  direct.sublist("Linear Solver Types").sublist("MUMPS").set("Precision", "Single");
  EXPECT_THROW(capstan::linearSolverFactories(direct), std::invalid_argument);
}

// Symmetric Part: A's symmetric part (A + A^T) / 2 factored as a symmetric
// matrix (LDL^T): a solve is S's, exact, on every rank count, where each
// rank's rows reach transposes in other ranks' rows (the cyclic map: nearly
// all of them; the far couplings cross the contiguous map's halves). Fewer
// factor entries than A's LU; GMRES on A with it as preconditioner converges
// to double precision; the direct solve's factory refuses it.
TEST(Mumps, SymmetricPartSolvesTheSymmetricPartOnEveryRankCount) {
  for (auto map : {contiguousMap(N, worldComm()), cyclicReversedMap(N, worldComm())}) {
    MumpsOptions o = testOptions();
    o.symmetricPart = true;
    MumpsSolver solver(o), lu(testOptions());
    for (double velocity : {1.0, 0.5}) {  // a refactorisation with the same pattern too
      ConvDiff c{velocity, 0.0, true};
      auto A = convectionDiffusion(map, c);
      c.symmetrised = true;
      auto S = convectionDiffusion(map, c);
      solver.factor(*A);
      solveAndCheck(solver, *S, 3);
      lu.factor(*A);
      EXPECT_LT(solver.factorEntries(), lu.factorEntries());
    }
    EXPECT_EQ(solver.numAnalyses(), 1);
    EXPECT_EQ(solver.numFactorizations(), 2);
    // Zeros in the pattern (the far couplings) turning nonzero: they join it,
    // a new analysis.
    MumpsSolver grows(o);
    grows.factor(*convectionDiffusion(map, ConvDiff{1.0, 0.0, true, 0.0}));
    grows.factor(*convectionDiffusion(map, ConvDiff{1.0, 0.0, true, 1.0}));
    solveAndCheck(grows, *convectionDiffusion(map, ConvDiff{1.0, 0.0, true, 1.0, true}), 1);
    EXPECT_EQ(grows.numAnalyses(), 2);
  }

  auto map = contiguousMap(N, worldComm());
  auto A = convectionDiffusion(map, ConvDiff{1.0, 0.0, true});
  auto xTrue = knownSolution(map, 1);
  MultiVector b(map, 1);
  A->apply(*xTrue, b);
  int luIts = 0, symIts = 0;
  EXPECT_LT(errorAgainst(*xTrue, *solveThrough(capstan::linearSolverFactories(gmresWithMumps()), A, b, luIts)), 1e-11);
  auto list = gmresWithMumps();
  list.sublist("Preconditioner Types").sublist("MUMPS").set("Symmetric Part", true);
  EXPECT_LT(errorAgainst(*xTrue, *solveThrough(capstan::linearSolverFactories(list), A, b, symIts)), 1e-11);
  EXPECT_GT(symIts, luIts);  // not A's inverse
  Teuchos::ParameterList direct;
  direct.set("Linear Solver Type", "MUMPS");
  direct.set("Preconditioner Type", "None");
  direct.sublist("Linear Solver Types").sublist("MUMPS").set("Symmetric Part", true);
  EXPECT_THROW(capstan::linearSolverFactories(direct), std::invalid_argument);
}

TEST(Mumps, EveryOrderingSolves) {
  auto A = convectionDiffusion(contiguousMap(N, worldComm()), ConvDiff{});
  using O = MumpsOptions::Ordering;
  const std::pair<O, int> orderings[] = {{O::Metis, 1}, {O::Pord, 4}, {O::Amd, 0}, {O::Amf, 2}, {O::Qamd, 6}};
  for (auto [ordering, infog7] : orderings) {
    MumpsOptions options = testOptions();
    options.ordering = ordering;
    MumpsSolver solver(options);
    solver.factor(*A);
    EXPECT_EQ(solver.orderingUsed(), infog7);
    solveAndCheck(solver, *A, 2);
  }
}

// Auto analyses with METIS and QAMD and keeps the one whose factorisation the
// analysis estimates at fewer flops.
TEST(Mumps, AutoOrderingKeepsTheFewerEstimatedFlops) {
  auto A = convectionDiffusion(contiguousMap(N, worldComm()), ConvDiff{});
  using O = MumpsOptions::Ordering;
  std::map<int, double> flops;  // INFOG(7) -> estimate
  for (O ordering : {O::Metis, O::Qamd}) {
    MumpsOptions options = testOptions();
    options.ordering = ordering;
    MumpsSolver solver(options);
    solver.factor(*A);
    flops[solver.orderingUsed()] = solver.estimatedFlops();
  }
  ASSERT_EQ(flops.size(), 2u);
  ASSERT_NE(flops[1], flops[6]) << "the two orderings must differ for the check to mean anything";
  MumpsOptions options = testOptions();
  options.ordering = O::Auto;
  MumpsSolver solver(options);
  solver.factor(*A);
  const int expected = flops[1] < flops[6] ? 1 : 6;
  EXPECT_EQ(solver.orderingUsed(), expected) << "METIS " << flops[1] << " flops, QAMD " << flops[6];
  EXPECT_DOUBLE_EQ(solver.estimatedFlops(), std::min(flops[1], flops[6]));
  EXPECT_EQ(solver.numAnalyses(), 1);
  solveAndCheck(solver, *A, 2);
}

TEST(Mumps, RefactorisationWithTheSamePatternReusesTheAnalysis) {
  auto map = contiguousMap(N, worldComm());
  MumpsSolver solver(testOptions());
  auto A1 = convectionDiffusion(map, ConvDiff{});
  solver.factor(*A1);
  solveAndCheck(solver, *A1, 3);
  // New values, same pattern, a new matrix object: only a factorisation.
  auto A2 = convectionDiffusion(map, ConvDiff{3.0, 0.5, false});
  solver.factor(*A2);
  EXPECT_EQ(solver.numAnalyses(), 1);
  EXPECT_EQ(solver.numFactorizations(), 2);
  auto x2 = solveAndCheck(solver, *A2, 3);
  // The old operator's solution is no longer what comes out.
  auto xTrue = knownSolution(map, 3);
  MultiVector b1(map, 3);
  A1->apply(*xTrue, b1);
  solver.solve(b1, *x2);
  x2->update(-1.0, *xTrue, 1.0);
  std::vector<double> d(3);
  x2->normInf(d);
  EXPECT_GT(d[0], 1e-3);
  // The same matrix again (values changed in place): still one analysis.
  A2->resumeFill();
  A2->scale(2.0);
  A2->fillComplete();
  solver.factor(*A2);
  EXPECT_EQ(solver.numAnalyses(), 1);
  solveAndCheck(solver, *A2, 1);
}

TEST(Mumps, ChangedPatternGetsANewAnalysis) {
  auto map = contiguousMap(N, worldComm());
  MumpsSolver solver(testOptions());
  auto A1 = convectionDiffusion(map, ConvDiff{});
  solver.factor(*A1);
  auto A2 = convectionDiffusion(map, ConvDiff{1.0, 1.0, true});
  solver.factor(*A2);
  EXPECT_EQ(solver.numAnalyses(), 2);
  solveAndCheck(solver, *A2, 3);
  // And back: a third analysis, the right answer for the first operator.
  solver.factor(*A1);
  EXPECT_EQ(solver.numAnalyses(), 3);
  EXPECT_EQ(solver.numFactorizations(), 3);
  solveAndCheck(solver, *A1, 2);
}

// Ordering = Auto runs its contest (QAMD, METIS, QAMD again where it won) at
// the first analysis, and again once the pattern has grown by a tenth or more;
// a pattern a little larger keeps the winner: one MUMPS analysis.
TEST(Mumps, AutoOrderingKeepsItsWinnerWhileThePatternGrowsLittle) {
  auto map = contiguousMap(N, worldComm());
  auto A = convectionDiffusion(map, ConvDiff{1.0, 0.5, true, 0.0});
  MumpsSolver solver(testOptions());  // Ordering Auto, the nonzero pattern
  solver.factor(*A);
  const int contest = solver.numOrderingAnalyses();
  EXPECT_GE(contest, 2);
  EXPECT_LE(contest, 3);
  // Far couplings turn nonzero in rows below `rows` (each one entry more).
  auto setFar = [&](GO rows) {
    A->resumeFill();
    for (LO l = 0; l < LO(map->getNodeNumElements()); ++l) {
      const GO g = map->getGlobalElement(l);
      if (g < rows) A->replaceGlobalValues(g, Teuchos::tuple<GO>(N - 1 - g), Teuchos::tuple<double>(0.3));
    }
    A->fillComplete();
  };
  setFar(4);  // 4 entries more, under 1%
  solver.factor(*A);
  EXPECT_EQ(solver.numAnalyses(), 2);
  EXPECT_EQ(solver.numOrderingAnalyses(), contest + 1);
  solveAndCheck(solver, *A, 2);
  setFar(N);  // every row: more than a tenth
  solver.factor(*A);
  EXPECT_EQ(solver.numAnalyses(), 3);
  EXPECT_GE(solver.numOrderingAnalyses(), contest + 1 + 2);
  solveAndCheck(solver, *A, 2);
}

// Zero entries of the graph stay out of MUMPS' pattern (fewer factor
// entries), join it when they turn nonzero (one more analysis) and stay in it
// when they are zero again (no analysis).
TEST(Mumps, ZeroEntriesJoinThePatternWhenTheyTurnNonzero) {
  auto map = contiguousMap(N, worldComm());
  auto A = convectionDiffusion(map, ConvDiff{1.0, 0.5, true, 0.0});
  MumpsOptions all = testOptions();
  all.nonzeroPattern = false;
  MumpsSolver whole(all), nonzeros(testOptions());
  whole.factor(*A);
  nonzeros.factor(*A);
  EXPECT_LT(nonzeros.factorEntries(), whole.factorEntries() * 3 / 4);
  solveAndCheck(nonzeros, *A, 2);
  auto setFar = [&](double far) {
    A->resumeFill();
    for (LO l = 0; l < LO(map->getNodeNumElements()); ++l) {
      const GO g = map->getGlobalElement(l);
      const GO col = N - 1 - g;
      const double v = far * (g < N / 2 ? 0.7 : -0.4);
      A->replaceGlobalValues(g, Teuchos::tuple<GO>(col), Teuchos::tuple<double>(v));
    }
    A->fillComplete();
  };
  setFar(1.0);
  nonzeros.factor(*A);
  whole.factor(*A);
  EXPECT_EQ(nonzeros.numAnalyses(), 2);
  EXPECT_EQ(whole.numAnalyses(), 1);
  EXPECT_EQ(nonzeros.factorEntries(), whole.factorEntries());
  solveAndCheck(nonzeros, *A, 2);
  setFar(0.0);
  nonzeros.factor(*A);
  EXPECT_EQ(nonzeros.numAnalyses(), 2);
  EXPECT_EQ(nonzeros.numFactorizations(), 3);
  solveAndCheck(nonzeros, *A, 2);
}

TEST(Mumps, NonContiguousMapAndOneRankAgree) {
  // The distributed solve on a round-robin, reversed map, and every rank's own
  // one-rank solve of the same system on MPI_COMM_SELF: the same x.
  const ConvDiff c{2.0, 0.0, true};
  auto A = convectionDiffusion(cyclicReversedMap(N, worldComm()), c);
  MumpsSolver solver(testOptions());
  solver.factor(*A);
  auto x = solveAndCheck(solver, *A, 3);

  auto selfMap = contiguousMap(N, selfComm());
  auto Aself = convectionDiffusion(selfMap, c);
  MumpsSolver selfSolver;
  selfSolver.factor(*Aself);
  auto xSelf = solveAndCheck(selfSolver, *Aself, 3);
  const auto& map = *A->getRowMap();
  for (int col = 0; col < 3; ++col) {
    const auto xc = x->getData(col);
    const auto sc = xSelf->getData(col);
    for (LO l = 0; l < LO(map.getNodeNumElements()); ++l)
      EXPECT_NEAR(xc[l], sc[map.getGlobalElement(l)], 1e-12);
  }
}

TEST(Mumps, SingularMatricesThrowAndTheSolverRecovers) {
  auto map = contiguousMap(N, worldComm());
  MumpsSolver solver(testOptions());
  {
    // Numerically singular: one row's values all zero, the pattern intact.
    auto A = convectionDiffusion(map, ConvDiff{});
    A->resumeFill();
    const GO g0 = 37;
    if (map->isNodeGlobalElement(g0)) {
      CrsMatrix::global_inds_host_view_type cols;
      CrsMatrix::values_host_view_type vals;
      std::vector<GO> c;
      const LO l = map->getLocalElement(g0);
      CrsMatrix::local_inds_host_view_type lc;
      A->getLocalRowView(l, lc, vals);
      for (std::size_t k = 0; k < lc.extent(0); ++k) c.push_back(A->getColMap()->getGlobalElement(lc(k)));
      std::vector<double> zeros(c.size(), 0.0);
      A->replaceGlobalValues(g0, Teuchos::arrayViewFromVector(c), Teuchos::arrayViewFromVector(zeros));
    }
    A->fillComplete();
    try {
      solver.factor(*A);
      ADD_FAILURE() << "no exception for a singular matrix";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("factorisation"), std::string::npos) << what;
      EXPECT_NE(what.find("INFOG(1) = -10"), std::string::npos) << what;
      EXPECT_NE(what.find("INFOG(2)"), std::string::npos) << what;
      EXPECT_NE(what.find("singular"), std::string::npos) << what;
    }
    MultiVector b(map, 1), x(map, 1);
    EXPECT_THROW(solver.solve(b, x), std::logic_error);
  }
  {
    // Structurally singular: an empty row.
    auto A = rcp(new CrsMatrix(map, 8));
    auto good = convectionDiffusion(map, ConvDiff{});
    for (LO l = 0; l < LO(map->getNodeNumElements()); ++l) {
      const GO g = map->getGlobalElement(l);
      if (g == 11) continue;
      CrsMatrix::local_inds_host_view_type lc;
      CrsMatrix::values_host_view_type vals;
      good->getLocalRowView(l, lc, vals);
      for (std::size_t k = 0; k < lc.extent(0); ++k) {
        const GO col = good->getColMap()->getGlobalElement(lc(k));
        const double v = vals(k);
        if (col != 11) A->insertGlobalValues(g, Teuchos::tuple(col), Teuchos::tuple(v));
      }
    }
    A->fillComplete();
    try {
      solver.factor(*A);
      ADD_FAILURE() << "no exception for a structurally singular matrix";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("INFOG(1) = -"), std::string::npos) << what;
      EXPECT_NE(what.find("singular"), std::string::npos) << what;
      if (worldComm()->getRank() == 0) std::printf("  structurally singular: %s\n", what.c_str());
    }
  }
  // A good matrix afterwards: factorised and solved.
  auto A = convectionDiffusion(map, ConvDiff{});
  solver.factor(*A);
  solveAndCheck(solver, *A, 2);
}

// [K B; B^T 0]: zero diagonal in the second block (as a mixed formulation
// without a pressure penalty), K small against B: the factorisation must pivot
// off the diagonal (distributed input gets no maximum transversal, ICNTL(6)).
// With no workspace margin (ICNTL(14) = 0) MUMPS could stop with -9 and the
// solver would retry once with more; at this size it has not needed to (the
// retry path is not exercised here).
RCP<CrsMatrix> saddlePoint(RCP<const Map> map) {
  const GO nu = N;
  const double kScale = 1e-2;  // K's diagonal below the pivot threshold times B's entries
  auto A = rcp(new CrsMatrix(map, 12));
  auto K = convectionDiffusion(contiguousMap(nu, selfComm()), ConvDiff{});
  for (LO l = 0; l < LO(map->getNodeNumElements()); ++l) {
    const GO g = map->getGlobalElement(l);
    std::vector<GO> cols;
    std::vector<double> vals;
    if (g < nu) {
      CrsMatrix::local_inds_host_view_type lc;
      CrsMatrix::values_host_view_type kv;
      K->getLocalRowView(LO(g), lc, kv);
      for (std::size_t k = 0; k < lc.extent(0); ++k)
        cols.push_back(K->getColMap()->getGlobalElement(lc(k))), vals.push_back(kScale * kv(k));
      cols.push_back(nu + g / 4), vals.push_back(1.0 + 0.1 * (g % 4));
    } else {
      for (GO u = 4 * (g - nu); u < 4 * (g - nu) + 4; ++u) cols.push_back(u), vals.push_back(1.0 - 0.05 * (u % 4));
    }
    A->insertGlobalValues(g, Teuchos::arrayViewFromVector(cols), Teuchos::arrayViewFromVector(vals));
  }
  A->fillComplete();
  return A;
}

TEST(Mumps, ZeroDiagonalBlockSolvesWithoutWorkspaceMargin) {
  auto A = saddlePoint(contiguousMap(N + N / 4, worldComm()));
  MumpsOptions options = testOptions();
  options.workspaceIncreasePercent = 0;
  MumpsSolver solver(options);
  solver.factor(*A);
  solveAndCheck(solver, *A, 2, 1e-9);
  if (worldComm()->getRank() == 0)
    std::printf("  saddle point, ICNTL(14) = 0: %d workspace retries\n", solver.numWorkspaceRetries());
}

TEST(Mumps, MismatchedVectorsThrow) {
  auto map = contiguousMap(N, worldComm());
  auto A = convectionDiffusion(map, ConvDiff{});
  MumpsSolver solver(testOptions());
  MultiVector b(map, 2), x(map, 3);
  EXPECT_THROW(solver.solve(b, b), std::logic_error);  // nothing factorised
  solver.factor(*A);
  EXPECT_THROW(solver.solve(b, x), std::invalid_argument);
  MultiVector other(contiguousMap(N + 1, worldComm()), 2);
  EXPECT_THROW(solver.solve(b, other), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// Timing on an elasticity-like stencil: n^3 nodes, 3 dofs each, every node
// coupled to its 26 neighbours by 3x3 blocks -w (I + d d^T / |d|^2), w = 1/|d|^2,
// plus a small non-symmetric (friction-like) part; diagonal blocks make the rows
// sum to a small shift. Contiguous map, node by node.

namespace {

RCP<CrsMatrix> elasticityLike(int n, RCP<const Comm> comm) {
  const GO nDof = 3 * GO(n) * n * n;
  auto map = contiguousMap(nDof, comm);
  auto A = rcp(new CrsMatrix(map, 81));
  std::vector<GO> cols;
  std::vector<double> vals;
  for (LO l = 0; l < LO(map->getNodeNumElements()); ++l) {
    const GO row = map->getGlobalElement(l);
    const GO node = row / 3;
    const int a = row % 3;
    const int i = node % n, j = (node / n) % n, k = node / (GO(n) * n);
    cols.clear();
    vals.clear();
    double diag[3] = {0, 0, 0};
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          if (!di && !dj && !dk) continue;
          if (i + di < 0 || i + di >= n || j + dj < 0 || j + dj >= n || k + dk < 0 || k + dk >= n) continue;
          const double d[3] = {double(di), double(dj), double(dk)};
          const double d2 = di * di + dj * dj + dk * dk, w = 1.0 / d2;
          const GO nb = node + di + GO(n) * (dj + GO(n) * dk);
          for (int b = 0; b < 3; ++b) {
            double v = -w * ((a == b) + d[a] * d[b] / d2);
            v += 0.05 * w * (d[(a + 1) % 3] - d[(b + 1) % 3]);  // non-symmetric
            cols.push_back(3 * nb + b);
            vals.push_back(v);
            diag[b] -= v;
          }
        }
    for (int b = 0; b < 3; ++b) {
      cols.push_back(3 * node + b);
      vals.push_back(diag[b] + (a == b ? 1e-2 : 0.0));
    }
    A->insertGlobalValues(row, Teuchos::arrayViewFromVector(cols), Teuchos::arrayViewFromVector(vals));
  }
  A->fillComplete();
  return A;
}

// Nonzero Node Blocks: a row's entries in one node's columns join the pattern
// together, so zeros inside a coupled node pair (here the axis-aligned
// neighbours' cross terms) are in it from the start, and their turning nonzero
// does not redo the analysis; entry by entry it does.
TEST(Mumps, NodeBlocksKeepZerosInsideCoupledNodes) {
  auto A = elasticityLike(4, worldComm());
  auto filled = rcp(new CrsMatrix(*A, Teuchos::Copy));  // every stored zero made 1e-3
  filled->resumeFill();
  long zeros = 0;
  for (LO r = 0; r < LO(A->getNodeNumRows()); ++r) {
    CrsMatrix::local_inds_host_view_type inds;
    CrsMatrix::values_host_view_type vals;
    A->getLocalRowView(r, inds, vals);
    for (std::size_t k = 0; k < vals.extent(0); ++k)
      if (vals(k) == 0) {
        ++zeros;
        const LO col = inds(k);
        filled->replaceLocalValues(r, Teuchos::tuple<LO>(col), Teuchos::tuple<double>(1e-3));
      }
  }
  filled->fillComplete();
  long allZeros = 0;
  Teuchos::reduceAll(*worldComm(), Teuchos::REDUCE_SUM, zeros, Teuchos::outArg(allZeros));
  ASSERT_GT(allZeros, 0);
  MumpsOptions blocks = testOptions();
  blocks.nonzeroNodeBlocks = true;
  MumpsSolver byNode(blocks), byEntry(testOptions());
  byNode.factor(*A);
  byEntry.factor(*A);
  solveAndCheck(byNode, *A, 1);
  byNode.factor(*filled);
  byEntry.factor(*filled);
  EXPECT_EQ(byNode.numAnalyses(), 1);
  EXPECT_EQ(byEntry.numAnalyses(), 2);
  solveAndCheck(byNode, *filled, 2);
  solveAndCheck(byEntry, *filled, 2);
}

MumpsOptions::Ordering orderingFromEnv() {
  using O = MumpsOptions::Ordering;
  const char* s = std::getenv("CAPSTAN_MUMPS_ORDERING");
  const std::string o = s ? s : "";
  if (o == "pord") return O::Pord;
  if (o == "amd") return O::Amd;
  if (o == "amf") return O::Amf;
  if (o == "qamd") return O::Qamd;
  return O::Metis;
}

void timeElasticity(int n) {
  auto A = elasticityLike(n, worldComm());
  MumpsOptions options = testOptions();
  options.ordering = orderingFromEnv();
  MumpsSolver solver(options);
  solver.factor(*A);
  const double analysis = solver.analysisSeconds(), first = solver.factorSeconds();
  solver.factor(*A);  // analysis reused
  EXPECT_EQ(solver.numAnalyses(), 1);
  auto map = A->getRowMap();
  auto xTrue = knownSolution(map, 1);
  MultiVector b(map, 1), x(map, 1), r(map, 1);
  A->apply(*xTrue, b);
  solver.solve(b, x);
  A->apply(x, r);
  r.update(1.0, b, -1.0);
  const double rel = r.getVector(0)->norm2() / b.getVector(0)->norm2();
  EXPECT_LT(rel, 1e-10);
  EXPECT_GT(solver.peakMemoryMB(), 0);
  EXPECT_GT(solver.factorEntries(), std::int64_t(A->getGlobalNumEntries()));
  if (worldComm()->getRank() == 0)
    std::printf("  elasticity-like %d^3 nodes: %zu unknowns, %zu entries, %d rank(s), ordering INFOG(7) = %d:\n"
                "    analysis %.3f s, factorisation %.3f s (again %.3f s), solve %.3f s,\n"
                "    factor entries %lld, peak memory %d MB (all ranks %d MB), residual %.1e\n",
                n, A->getGlobalNumRows(), A->getGlobalNumEntries(), worldComm()->getSize(),
                solver.orderingUsed(), analysis, first, solver.factorSeconds(), solver.solveSeconds(),
                (long long)solver.factorEntries(), solver.peakMemoryMB(), solver.totalMemoryMB(), rel);
}

}  // namespace

TEST(MumpsTiming, Elasticity5k) { timeElasticity(12); }          // 5,184 unknowns
TEST(MumpsTiming, DISABLED_Elasticity50k) { timeElasticity(26); }  // 52,728 unknowns
