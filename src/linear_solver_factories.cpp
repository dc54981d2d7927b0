#include "linear_solver_factories.hpp"

#include <BelosBlockGmresSolMgr.hpp>
#include <BelosPseudoBlockCGSolMgr.hpp>
#include <BelosThyraAdapter.hpp>
#include <Teuchos_AbstractFactoryStd.hpp>
#include <Thyra_BelosLinearOpWithSolveFactory.hpp>
#include <dlfcn.h>

#include <set>
#include <string>

#include "assembly.hpp"
#include "errors.hpp"
#include "mumps_solve_factory.hpp"
#include "program_directory.hpp"

namespace capstan {

namespace {

using Teuchos::ParameterList;
using Teuchos::RCP;
using Teuchos::rcp;

// Only `kind`'s sublist `name` (or nothing) inside `list`'s sublist `kind`.
bool onlySublist(const ParameterList& list, const std::string& kind, const std::string& name) {
  if (!list.isParameter(kind)) return true;
  if (!list.isSublist(kind)) return false;
  for (const auto& entry : list.sublist(kind))
    if (entry.first != name) return false;
  return true;
}

std::string stringOr(const ParameterList& list, const std::string& name) {
  return list.isType<std::string>(name) ? list.get<std::string>(name) : std::string();
}

RCP<ParameterList> copyOf(const ParameterList& list, const std::string& kind, const std::string& name) {
  if (!list.isSublist(kind) || !list.sublist(kind).isSublist(name)) return rcp(new ParameterList(name));
  return rcp(new ParameterList(list.sublist(kind).sublist(name)));
}

// The plugin beside the running program, else where the build put it.
void* openPlugin() {
  const std::string beside = programDirectory() + "libcapstan_krylov.so";
  if (void* handle = dlopen(beside.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
  std::string tried = beside + " (" + dlerror() + ")";
#ifdef CAPSTAN_KRYLOV_PLUGIN
  if (void* handle = dlopen(CAPSTAN_KRYLOV_PLUGIN, RTLD_NOW | RTLD_LOCAL)) return handle;
  tried += std::string(", ") + CAPSTAN_KRYLOV_PLUGIN + " (" + dlerror() + ")";
#endif
  throw PluginError("cannot load capstan's Krylov solver plugin, needed for this scene's linear solver: tried " +
                    tried);
}

BuildFromStratimikos pluginEntry() {
  static BuildFromStratimikos entry = nullptr;  // loaded once, kept for the process
  if (entry) return entry;
  void* handle = openPlugin();
  entry = reinterpret_cast<BuildFromStratimikos>(dlsym(handle, kBuildFromStratimikosName));
  if (!entry) throw PluginError(std::string("capstan's Krylov solver plugin has no ") + kBuildFromStratimikosName);
  return entry;
}

// A point per 3 owned unknowns, as MueLu groups them (number of equations 3),
// for its repartitioning: the owned nodes' reference coordinates, then (rank
// 0) two points per rigid core at its axis point, for its 6 unknowns.
RCP<Tpetra::MultiVector<>> unknownCoordinates(const Assembly& assembly) {
  const Mesh& mesh = assembly.mesh();
  const size_t n = assembly.dofMap()->getNodeNumElements() / 3;
  std::vector<GO> gids(n);
  for (size_t k = 0; k < n; ++k) gids[k] = assembly.dofMap()->getGlobalElement(LO(3 * k)) / 3;
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  auto map = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(gids), 0, mesh.comm));
  auto coords = rcp(new Tpetra::MultiVector<>(map, 3));
  for (size_t k = 0; k < mesh.numOwnedNodes; ++k)
    for (int i = 0; i < 3; ++i) coords->replaceLocalValue(LO(k), i, mesh.X[3 * k + i]);
  const auto& cores = assembly.rigidCores();
  for (size_t k = mesh.numOwnedNodes; k < n; ++k) {
    const auto& core = cores[(k - mesh.numOwnedNodes) / 2];
    for (int i = 0; i < 3; ++i) coords->replaceLocalValue(LO(k), i, core.axisPoint[i]);
  }
  return coords;
}

// The six rigid-body modes of the body at its reference positions (about its
// centroid): the near-null space that smoothed aggregation needs for
// elasticity.
RCP<Tpetra::MultiVector<>> rigidBodyModes(const Assembly& assembly) {
  const Mesh& mesh = assembly.mesh();
  auto modes = rcp(new Tpetra::MultiVector<>(assembly.dofMap(), 6));
  double c[3] = {0, 0, 0}, local[4] = {0, 0, 0, double(mesh.numOwnedNodes)}, global[4];
  for (size_t n = 0; n < mesh.numOwnedNodes; ++n)
    for (int i = 0; i < 3; ++i) local[i] += mesh.X[3 * n + i];
  Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_SUM, 4, local, global);
  for (int i = 0; i < 3; ++i) c[i] = global[i] / std::max(global[3], 1.0);
  for (size_t n = 0; n < mesh.numOwnedNodes; ++n) {
    const double x = mesh.X[3 * n] - c[0], y = mesh.X[3 * n + 1] - c[1], z = mesh.X[3 * n + 2] - c[2];
    const LO d = LO(3 * n);
    for (int i = 0; i < 3; ++i) modes->replaceLocalValue(d + i, i, 1.0);  // translations
    // rotations about x, y, z: omega x r
    modes->replaceLocalValue(d + 1, 3, -z), modes->replaceLocalValue(d + 2, 3, y);
    modes->replaceLocalValue(d + 0, 4, z), modes->replaceLocalValue(d + 2, 4, -x);
    modes->replaceLocalValue(d + 0, 5, -y), modes->replaceLocalValue(d + 1, 5, x);
  }
  // Rigid cores move with the body: translations move T; a rotation omega
  // moves T by omega x (A - c) and turns the core by omega . d.
  const auto& cores = assembly.rigidCores();
  for (size_t k = 0; k < cores.size(); ++k) {
    if (assembly.ownedCoreDof(k, 0) < 0) continue;
    const LO d = assembly.ownedCoreDof(k, 0);
    const auto& A = cores[k].axisPoint;
    const auto& ax = cores[k].axisDirection;
    const double x = A[0] - c[0], y = A[1] - c[1], z = A[2] - c[2];
    for (int i = 0; i < 3; ++i) modes->replaceLocalValue(d + i, i, 1.0);
    modes->replaceLocalValue(d + 1, 3, -z), modes->replaceLocalValue(d + 2, 3, y);
    modes->replaceLocalValue(d + 0, 4, z), modes->replaceLocalValue(d + 2, 4, -x);
    modes->replaceLocalValue(d + 0, 5, -y), modes->replaceLocalValue(d + 1, 5, x);
    for (int m = 0; m < 3; ++m) modes->replaceLocalValue(d + 3, 3 + m, ax[m]);
  }
  return modes;
}

}  // namespace

namespace {

// Solver/Belos checked against the Belos solver's own list (Belos' solvers
// read theirs without checking names, so a misspelt one would be lost); an
// int where Belos takes a double is read as one.
ParameterList checkedBelosList(const ParameterList& scene, const std::string& type) {
  const auto valid = Thyra::BelosLinearOpWithSolveFactory<double>().getValidParameters()->sublist("Solver Types").sublist(type);
  ParameterList checked = scene;
  for (const auto& entry : scene) {
    const std::string& name = entry.first;
    if (!valid.isParameter(name))
      throw InputError("parameter 'Solver/Belos/" + name + "': unknown to Belos' " + type + " solver");
    if (valid.isSublist(name) || scene.isSublist(name)) continue;  // e.g. Belos' own output lists
    const auto& want = valid.getEntry(name).getAny(false).type();
    const auto& got = scene.getEntry(name).getAny(false);
    if (got.type() == want) continue;
    if (want == typeid(double) && got.type() == typeid(int)) {
      checked.set(name, double(Teuchos::any_cast<int>(got)));
      continue;
    }
    throw InputError("parameter 'Solver/Belos/" + name + "': Belos' " + type + " solver takes type " +
                     valid.getEntry(name).getAny(false).typeName() + ", got " + got.typeName());
  }
  // The values: the solver reads them as it is built (Num Blocks = 0 and an
  // unknown orthogonalisation ended the run as a failed solve, exit 2).
  if (checked.numParams() > 0) {
    using MV = Thyra::MultiVectorBase<double>;
    using OP = Thyra::LinearOpBase<double>;
    auto list = Teuchos::rcp(new ParameterList(checked));
    try {
      if (type == "Block GMRES") Belos::BlockGmresSolMgr<double, MV, OP>().setParameters(list);
      else Belos::PseudoBlockCGSolMgr<double, MV, OP>().setParameters(list);
    } catch (const std::exception& e) {
      throw InputError("parameter 'Solver/Belos': " + trilinosMessage(e.what()));
    }
  }
  return checked;
}

}  // namespace

Teuchos::ParameterList stratimikosList(const SolverSettings& solver, const Assembly& assembly) {
  const int ranks = assembly.dofMap()->getComm()->getSize();
  Teuchos::ParameterList p("Stratimikos");
  using S = SolverSettings;
  const S::LinearSolver method = solver.linearSolver;
  const std::string belosType = method == S::LinearSolver::CG ? "Pseudo Block CG" : "Block GMRES";
  const ParameterList belosScene = checkedBelosList(solver.belos, belosType);
  // Direct: MUMPS on any number of ranks (src/mumps_solve_factory.hpp).
  // Amesos2's KLU2, still selectable through Solver/Stratimikos, solves our
  // matrices wrongly on several ranks in Trilinos 13.2.
  if (method == S::LinearSolver::Direct) {
    p.set("Linear Solver Type", "MUMPS");
    p.set("Preconditioner Type", "None");
  } else {
    p.set("Linear Solver Type", "Belos");
    auto& belos = p.sublist("Linear Solver Types").sublist("Belos");
    const std::string& type = belosType;
    belos.set("Solver Type", type);
    auto& st = belos.sublist("Solver Types").sublist(type);
    st.set("Convergence Tolerance", solver.linearTolerance);
    st.set("Maximum Iterations", solver.maxLinearIterations);
    if (type == "Block GMRES") {
      st.set("Num Blocks", 200);
      st.set("Maximum Restarts", 20);
    }
    st.setParameters(belosScene);
    const S::Preconditioner prec = solver.preconditioner;
    if (prec == S::Preconditioner::None) {
      p.set("Preconditioner Type", "None");
    } else if (prec == S::Preconditioner::LU) {
      p.set("Preconditioner Type", "MUMPS");  // src/mumps_solve_factory.hpp
      // Factored in single precision (with flexible GMRES): G1 2x 1.97-2.19 s
      // against 2.86-3.17 s, the 126k-dof steady drive on 2 ranks 100 s and
      // 0.9 GB a rank against 135 s and 1.3 GB, the same Newton iterations
      // and answers to 1e-8 (docs/performance.md, "Defaults and why").
      p.sublist("Preconditioner Types").sublist("MUMPS").set("Precision", "Single");
      // Without friction, its symmetric part in LDL^T (G1 2x 1.51-1.56 s against
      // 2.22-2.25 s on 1 rank, 1.08-1.10 against 1.44-1.54 s on 2), with the
      // nonzero pattern by node blocks (one analysis: 1.40-1.43 s, 0.97-1.00 s on
      // 2 ranks; docs/performance.md, src/direct_solver.hpp).
      if (!solver.unsymmetric) {
        auto& mumps = p.sublist("Preconditioner Types").sublist("MUMPS");
        mumps.set("Symmetric Part", true);
        mumps.set("Nonzero Node Blocks", true);
      }
    } else if (prec == S::Preconditioner::MueLu) {
      // Smoothed aggregation with the rigid-body modes, Chebyshev smoothing.
      p.set("Preconditioner Type", "MueLu");
      auto& ml = p.sublist("Preconditioner Types").sublist("MueLu");
      ml.set("verbosity", "none");
      ml.set("number of equations", 3);
      ml.set("multigrid algorithm", "sa");
      // capstan's smoother, unless the scene picks another in
      // Solver/Stratimikos/Preconditioner Types/MueLu/smoother: type (then
      // that smoother's defaults: MueLu rejects a Chebyshev degree for it).
      std::string userSmoother = "CHEBYSHEV";
      const auto& strat = solver.stratimikos;
      if (strat.isSublist("Preconditioner Types") && strat.sublist("Preconditioner Types").isSublist("MueLu")) {
        const auto& user = strat.sublist("Preconditioner Types").sublist("MueLu");
        if (user.isType<std::string>("smoother: type")) userSmoother = user.get<std::string>("smoother: type");
      }
      if (userSmoother == "CHEBYSHEV" && solver.gradedRings) {
        // Graded rings (an annulus): symmetric Gauss-Seidel, two sweeps, and
        // weak connections dropped. The Hertz ring: 654 Krylov iterations
        // against 2,746 with Chebyshev, 2.6-2.8x faster (docs/performance.md).
        ml.set("smoother: type", "RELAXATION");
        ml.sublist("smoother: params").set("relaxation: type", "Symmetric Gauss-Seidel");
        ml.sublist("smoother: params").set("relaxation: sweeps", 2);
        ml.set("aggregation: drop tol", 0.05);
      } else if (userSmoother == "CHEBYSHEV") {
        ml.set("smoother: type", "CHEBYSHEV");
        ml.sublist("smoother: params").set("chebyshev: degree", 2);
      }
      ml.set("coarse: max size", 1500);
      // Restriction applied as P^T instead of a stored R: the same iterations
      // and time, 5% less memory (docs/performance.md, "Defaults and why").
      ml.set("transpose: use implicit", true);
      ml.set("Nullspace", rigidBodyModes(assembly));
      // On several ranks the coarse levels (below 2000 unknowns per rank) move
      // onto one rank, so that the coarsest solve is a serial KLU2: Amesos2's
      // KLU2 on a distributed matrix solves wrongly in Trilinos 13.2, and a
      // wrong coarse solve doubles MueLu's iterations (docs/performance.md).
      if (ranks > 1) {
        ml.set("repartition: enable", true);
        ml.set("repartition: partitioner", "zoltan2");
        ml.set("repartition: start level", 1);
        ml.set("repartition: min rows per proc", 2000);
        ml.set("Coordinates", unknownCoordinates(assembly));
      }
    } else {
      p.set("Preconditioner Type", "Ifpack2");
      auto& ifp = p.sublist("Preconditioner Types").sublist("Ifpack2");
      if (prec == S::Preconditioner::ILU) {
        // ILU(k) of each rank's diagonal block (Ifpack2 filters out the
        // off-rank columns itself): block Jacobi between ranks.
        ifp.set("Prec Type", "RILUK");
        ifp.sublist("Ifpack2 Settings").set("fact: iluk level-of-fill", solver.iluLevel);
      } else {
        ifp.set("Prec Type", "RELAXATION");
        ifp.sublist("Ifpack2 Settings").set("relaxation: type", "Jacobi");
      }
      ifp.sublist("Ifpack2 Settings").setParameters(solver.ifpack2);
    }
  }
  p.setParameters(solver.stratimikos);
  return p;
}

bool builtWithoutStratimikos(const ParameterList& p) {
  static const std::set<std::string> known = {"Linear Solver Type", "Preconditioner Type", "Linear Solver Types",
                                              "Preconditioner Types"};
  for (const auto& entry : p)
    if (!known.count(entry.first)) return false;
  const std::string lows = stringOr(p, "Linear Solver Type"), prec = stringOr(p, "Preconditioner Type");
  if (lows != "MUMPS" && lows != "Belos") return false;
  if (prec != "None" && prec != "MUMPS") return false;
  if (lows == "MUMPS" && prec != "None") return false;  // the builder would build it unused
  return onlySublist(p, "Linear Solver Types", lows) &&
         onlySublist(p, "Preconditioner Types", prec == "None" ? std::string() : prec);
}

namespace {

// Factors in single precision make the preconditioner linear only to about
// 1e-7: Block GMRES then keeps the preconditioned vectors (flexible GMRES), or
// its answer is no better than that (test_mumps).
ParameterList withFlexibleGmresForSingleFactors(const ParameterList& list) {
  ParameterList p = list;
  if (p.get<std::string>("Linear Solver Type", "") != "Belos" || p.get<std::string>("Preconditioner Type", "") != "MUMPS")
    return p;
  if (!p.isSublist("Preconditioner Types") || !p.sublist("Preconditioner Types").isSublist("MUMPS")) return p;
  if (p.sublist("Preconditioner Types").sublist("MUMPS").get<std::string>("Precision", "Double") != "Single") return p;
  auto& belos = p.sublist("Linear Solver Types").sublist("Belos");
  const std::string type = belos.get<std::string>("Solver Type", "Block GMRES");
  if (type == "Block GMRES") belos.sublist("Solver Types").sublist(type).set("Flexible Gmres", true);
  return p;
}

}  // namespace

LinearSolverFactories linearSolverFactories(const ParameterList& list) {
  const ParameterList p = withFlexibleGmresForSingleFactors(list);
  LinearSolverFactories f;
  if (!builtWithoutStratimikos(p)) {
    StratimikosRequest request;
    request.list = &p;
    request.mumpsSolve =
        Teuchos::abstractFactoryStd<Thyra::LinearOpWithSolveFactoryBase<double>, MumpsSolveFactory>();
    request.mumpsPreconditioner =
        Teuchos::abstractFactoryStd<Thyra::PreconditionerFactoryBase<double>, MumpsPreconditionerFactory>();
    pluginEntry()(request);
    return request.built;
  }
  // As Stratimikos' builder does it: the preconditioner factory first, then
  // the solver's own parameters (which may override the preconditioner's).
  const std::string lows = p.get<std::string>("Linear Solver Type");
  if (p.get<std::string>("Preconditioner Type") == "MUMPS") {
    f.prec = rcp(new MumpsPreconditionerFactory());
    f.prec->setParameterList(copyOf(p, "Preconditioner Types", "MUMPS"));
  }
  if (lows == "MUMPS")
    f.lows = rcp(new MumpsSolveFactory());
  else
    f.lows = rcp(new Thyra::BelosLinearOpWithSolveFactory<double>());
  if (!f.prec.is_null() && f.lows->acceptsPreconditionerFactory()) {
    auto own = rcp(new MumpsPreconditionerFactory());  // the builder gives the solver its own
    own->setParameterList(copyOf(p, "Preconditioner Types", "MUMPS"));
    f.lows->setPreconditionerFactory(own, "MUMPS");
  }
  f.lows->setParameterList(copyOf(p, "Linear Solver Types", lows));
  return f;
}

}  // namespace capstan
