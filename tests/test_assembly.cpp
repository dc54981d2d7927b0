// The distributed assembly equals a serial one: on every rank, the same box is
// also assembled alone (a one-rank communicator), and the residual and tangent
// action agree dof by dof. Run on 1 and 2 ranks.
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_XMLParameterListHelpers.hpp>
#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <tuple>

#include "assembly.hpp"
#include "errors.hpp"
#include "newton.hpp"
#include "pressure_step.hpp"
#include "pressure_step_check.hpp"

using namespace capstan;

namespace {

Scene boxScene() {
  Scene s;
  s.mesh.type = MeshSpec::Type::Box;
  s.mesh.min = {0, 0, 0};
  s.mesh.max = {2, 1, 1.5};
  s.mesh.cells = {4, 2, 3};
  s.c = 1.3;
  s.pressurePenalty = 1e-2;
  s.solver = SolverSettings::defaults();
  SupportSpec fixed{"base", "ymin", SupportSpec::Type::Fixed, {true, true, true}, 0, {0, 0, 0}};
  SupportSpec roll{"side", "xmin", SupportSpec::Type::Roller, {true, false, false}, 0, {0, 0, 0}};
  SupportSpec spring{"spring", "zmax", SupportSpec::Type::Foundation, {false, true, true}, 0.7, {0, 0, 0}};
  s.supports = {fixed, roll, spring};
  return s;
}

// A smooth displacement field (zero on ymin and x = 0 on xmin).
double field(const double* X, int i) {
  return 0.05 * X[1] * (i + 1) * std::sin(X[0] + 0.3 * i) * (1 + 0.2 * X[2]) +
         (i == 0 ? 0.0 : 0.0);
}

// u = scale x field on the owned nodes.
void setField(const Mesh& mesh, Vector& u, double scale) {
  auto ud = u.getDataNonConst();
  for (size_t n = 0; n < mesh.numOwnedNodes; ++n)
    for (int i = 0; i < 3; ++i) ud[3 * n + i] = scale * field(&mesh.X[3 * n], i);
}

// A box scene's mesh, assembly and Newton solver, at u = scale x field (constraints applied).
struct BoxProblem {
  BoxProblem(const Scene& s, double scale)
      : scene(s),
        mesh(distributeMesh(BoxGenerator(s.mesh.min, s.mesh.max, s.mesh.cells), Tpetra::getDefaultComm())),
        assembly(mesh, scene),
        newton(assembly, scene.solver),
        u(assembly.dofMap()),
        f(assembly.dofMap()) {
    setField(mesh, u, scale);
    assembly.applyConstraints(u, 0.0);
  }
  Scene scene;
  Mesh mesh;
  Assembly assembly;
  NewtonSolver newton;
  Vector u, f;
};

// gid -> (residual, (K w)) for this communicator's owned dofs.
std::map<GO, std::pair<double, double>> assemble(const RCP<const Comm>& comm) {
  const Scene scene = boxScene();
  BoxGenerator gen(scene.mesh.min, scene.mesh.max, scene.mesh.cells);
  Mesh mesh = distributeMesh(gen, comm);
  Assembly assembly(mesh, scene);
  Vector u(mesh.ownedDofMap), f(mesh.ownedDofMap), w(mesh.ownedDofMap), Kw(mesh.ownedDofMap);
  {
    auto ud = u.getDataNonConst();
    auto wd = w.getDataNonConst();
    for (size_t n = 0; n < mesh.numOwnedNodes; ++n)
      for (int i = 0; i < 3; ++i) {
        ud[3 * n + i] = field(&mesh.X[3 * n], i);
        wd[3 * n + i] = std::cos(mesh.X[3 * n] + i) + mesh.X[3 * n + 2];
      }
  }
  assembly.applyConstraints(u, 0.0);
  auto W = assembly.createMatrix();
  EXPECT_TRUE(assembly.evaluate(u, &f, W.get()));
  W->apply(w, Kw);
  std::map<GO, std::pair<double, double>> out;
  auto fd = f.getData();
  auto kd = Kw.getData();
  for (LO d = 0; d < LO(fd.size()); ++d)
    out[mesh.ownedDofMap->getGlobalElement(LO(d))] = {fd[d], kd[d]};
  return out;
}

TEST(Assembly, DistributedEqualsSerial) {
  auto world = Tpetra::getDefaultComm();
  auto self = rcp(new Teuchos::MpiComm<int>(MPI_COMM_SELF));
  const auto serial = assemble(self);
  const auto dist = assemble(world);
  double scale = 0;
  for (const auto& [gid, v] : serial) scale = std::max({scale, std::fabs(v.first), std::fabs(v.second)});
  ASSERT_GT(scale, 0);
  for (const auto& [gid, v] : dist) {
    const auto& s = serial.at(gid);
    EXPECT_NEAR(v.first, s.first, 1e-12 * scale) << "residual, dof " << gid;
    EXPECT_NEAR(v.second, s.second, 1e-12 * scale) << "tangent action, dof " << gid;
  }
  // Every dof is owned by exactly one rank.
  long count = long(dist.size()), total = 0;
  Teuchos::reduceAll(*world, Teuchos::REDUCE_SUM, count, Teuchos::outArg(total));
  EXPECT_EQ(total, long(serial.size()));
}

// The step predictor's K z (formed by the kernels as they go: no element
// tangent is kept) against the assembled matrix on the free dofs, and, with z
// on the held dofs too (the prescribed increment's case, which the matrix does
// not hold), against central differences of the residual.
TEST(Assembly, PredictorLoadMatchesMatrixAndDifferences) {
  BoxProblem problem(boxScene(), 1.0);
  auto& [scene, mesh, assembly, newton, u, f] = problem;
  auto comm = mesh.comm;
  Vector z(assembly.dofMap()), zFree(assembly.dofMap()), Kz(assembly.dofMap()), Wz(assembly.dofMap());
  {
    auto zd = z.getDataNonConst();
    auto zf = zFree.getDataNonConst();
    for (size_t n = 0; n < mesh.numOwnedNodes; ++n)
      for (int i = 0; i < 3; ++i) {
        const LO d = LO(3 * n + i);
        zd[d] = std::cos(mesh.X[3 * n] + i) + mesh.X[3 * n + 2];
        zf[d] = assembly.ownedConstrained(d) ? 0.0 : zd[d];
      }
  }
  auto W = newton.matrix();
  double largest = 0;
  auto maxAbs = [&](const Vector& v) {
    double m = 0, g = 0;
    for (double x : v.getData()) m = std::max(m, std::fabs(x));
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, m, Teuchos::outArg(g));
    return g;
  };
  // Free z: K z = W z on the free rows.
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get(), &zFree, &Kz));
  W->apply(zFree, Wz);
  largest = maxAbs(Kz);
  ASSERT_GT(largest, 0);
  {
    auto k = Kz.getData();
    auto w = Wz.getData();
    for (LO d = 0; d < LO(k.size()); ++d)
      if (!assembly.ownedConstrained(d)) {
        EXPECT_NEAR(k[d], w[d], 1e-12 * largest) << "dof " << d;
      }
  }
  // z everywhere: (R(u + h z) - R(u - h z)) / 2h on the free rows.
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get(), &z, &Kz));
  const double h = 1e-6;
  Vector up(u, Teuchos::Copy), um(u, Teuchos::Copy), fp(assembly.dofMap()), fm(assembly.dofMap());
  up.update(h, z, 1.0), um.update(-h, z, 1.0);
  ASSERT_TRUE(assembly.evaluate(up, &fp, nullptr));
  ASSERT_TRUE(assembly.evaluate(um, &fm, nullptr));
  largest = maxAbs(Kz);
  double heldPart = 0;  // how much the held columns add: the check must see them
  {
    Vector Kf(assembly.dofMap());
    ASSERT_TRUE(assembly.evaluate(u, &f, W.get(), &zFree, &Kf));
    Kf.update(1.0, Kz, -1.0);
    heldPart = maxAbs(Kf);
  }
  EXPECT_GT(heldPart, 0.01 * largest);
  auto k = Kz.getData();
  auto p = fp.getData();
  auto m = fm.getData();
  for (LO d = 0; d < LO(k.size()); ++d)
    if (!assembly.ownedConstrained(d)) {
      EXPECT_NEAR(k[d], (p[d] - m[d]) / (2 * h), 1e-6 * largest) << "dof " << d;
    }
}

// NewtonSolver::linearSolve with the factorisation Newton keeps (GMRES with the
// LU preconditioner): Kept builds it, KeptAsBuilt reuses it at another state
// without a rebuild and still solves that state's system, and the iteration
// cap makes a stale factorisation's tight solve fail instead of run on.
TEST(NewtonSolver, KeptFactorisationAsBuilt) {
  Scene scene = boxScene();
  scene.solver.linearSolver = SolverSettings::LinearSolver::GMRES;
  scene.solver.preconditioner = SolverSettings::Preconditioner::LU;
  BoxProblem problem(scene, 1.0);
  auto& [sc, mesh, assembly, newton, u, f] = problem;
  auto W = newton.matrix();
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get()));
  EXPECT_FALSE(newton.keepsFactorisation());
  Vector x(assembly.dofMap());
  EXPECT_GE(newton.linearSolve(f, x, 1e-10, NewtonSolver::Preconditioner::Kept), 0);
  ASSERT_TRUE(newton.keepsFactorisation());
  const int builds = newton.preconditionerBuilds();

  // Another state: its own matrix, solved on the kept factorisation.
  Vector u2(u, Teuchos::Copy);
  setField(mesh, u2, 3.0);
  assembly.applyConstraints(u2, 0.0);
  ASSERT_TRUE(assembly.evaluate(u2, &f, W.get()));
  Vector xKept(assembly.dofMap()), xOwn(assembly.dofMap()), r(assembly.dofMap());
  const int kept = newton.linearSolve(f, xKept, 1e-10, NewtonSolver::Preconditioner::KeptAsBuilt, 200);
  EXPECT_GT(kept, 1);  // stale: more than the one iteration of an exact factorisation
  EXPECT_EQ(newton.preconditionerBuilds(), builds);
  W->apply(xKept, r);
  r.update(-1.0, f, 1.0);
  EXPECT_LT(r.norm2(), 1e-9 * f.norm2());
  ASSERT_TRUE(assembly.evaluate(u2, &f, W.get()));
  EXPECT_GE(newton.linearSolve(f, xOwn, 1e-10), 0);
  xOwn.update(-1.0, xKept, 1.0);
  EXPECT_LT(xOwn.normInf(), 1e-7 * xKept.normInf());

  // The cap: one iteration cannot reach 1e-12 on a stale factorisation.
  Vector xCapped(assembly.dofMap());
  EXPECT_EQ(newton.linearSolve(f, xCapped, 1e-12, NewtonSolver::Preconditioner::KeptAsBuilt, 1), -1);
}

// evaluate()'s phases are timed in turn within its total.
TEST(Assembly, PhaseSecondsAddUpWithinTheTotal) {
  BoxProblem problem(boxScene(), 1.0);
  auto& [scene, mesh, assembly, newton, u, f] = problem;
  auto W = newton.matrix();
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get()));
  ASSERT_TRUE(assembly.evaluate(u, &f, nullptr));
  const auto& p = assembly.phaseSeconds();
  for (double s : {p.import, p.launch, p.scatter, p.constraints, p.coreCoupling, p.matrixExport}) EXPECT_GE(s, 0.0);
  EXPECT_GT(p.launch, 0.0);
  const double sum = p.import + p.launch + p.scatter + p.constraints + p.coreCoupling + p.matrixExport;
  EXPECT_LE(sum, assembly.assemblySeconds() * (1 + 1e-12));
}

// A view's values on the host.
std::vector<double> hostCopy(const Kokkos::View<double*>& v) {
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  return std::vector<double>(h.data(), h.data() + h.size());  // (on the host the mirror is v itself)
}

// The bricks' pressure anchors at pbar0 + s dp.
void setAnchors(BrickEffect& bricks, const std::vector<double>& pbar0, const std::vector<double>& dp, double s) {
  auto h = Kokkos::create_mirror_view(bricks.pressureAnchor);
  for (size_t e = 0; e < h.extent(0); ++e) h(e) = pbar0[e] + s * dp[e];
  Kokkos::deep_copy(bricks.pressureAnchor, h);
}

// G^T d: the element volumes' rate along d at u, (v(u + h d) - v(u - h d)) / 2h
// (v is cubic in x: the difference's error goes as h^2; seen 3.7e-5, 3.7e-7 of
// max |V - v| = 0.02 at h = 1e-3, 1e-4 along a long step, far from equilibrium).
std::vector<double> volumeRate(Assembly& assembly, const Vector& u, const Vector& d) {
  const double h = 1e-5;
  std::vector<double> vp, vm;
  for (double sign : {1.0, -1.0}) {
    Vector us(u, Teuchos::Copy);
    us.update(sign * h, d, 1.0);
    EXPECT_TRUE(assembly.evaluate(us, nullptr, nullptr));
    (sign > 0 ? vp : vm) = hostCopy(assembly.bricks().volume);
  }
  for (size_t e = 0; e < vp.size(); ++e) vp[e] = (vp[e] - vm[e]) / (2 * h);
  return vp;
}

// The saddle-point pressure step solves the mixed problem's Newton system
//   K dx - G dp = -R,   G^T dx = V - v      (G: column e = d v_e / d x)
// checked with the assembly's own residual and volumes, not the step's G:
// R is linear in the anchors, so R(pbar + dp) - R(pbar) = -G dp exactly, and
// G^T dx is a central difference of the volumes along dx.
TEST(PressureStep, SolvesTheMixedNewtonSystem) {
  auto comm = Tpetra::getDefaultComm();
  BoxProblem problem(boxScene(), 1.0);
  auto& [scene, mesh, assembly, newton, u, f] = problem;
  BrickEffect& bricks = assembly.bricks();
  auto W = newton.matrix();
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get()));
  const std::vector<double> v0 = hostCopy(bricks.volume), V = hostCopy(bricks.referenceVolume);
  const std::vector<double> pbar0 = hostCopy(bricks.pressureAnchor);
  Vector dx(assembly.dofMap());
  std::vector<Kokkos::View<double*>> dmu;
  PressureStep step(assembly);
  const auto result = step.solve(*W, newton.approximateInverse(), f, 1e-12, 0.0, 500, dx, dmu);
  EXPECT_LT(result.reduction, 1e-11);
  ASSERT_EQ(dmu.size(), assembly.effects().size());
  const std::vector<double> dph = hostCopy(dmu[0]);
  ASSERT_EQ(assembly.effects()[0].get(), &bricks);

  // Momentum rows: K dx + (R(pbar + dp) - R(pbar)) + R = 0.
  Vector Kdx(assembly.dofMap()), fp(assembly.dofMap());
  W->apply(dx, Kdx);
  setAnchors(bricks, pbar0, dph, 1);
  ASSERT_TRUE(assembly.evaluate(u, &fp, nullptr));
  setAnchors(bricks, pbar0, dph, 0);
  Kdx.update(1.0, fp, 1.0);  // K dx + R(pbar + dp) - R(pbar) + R = K dx + R(pbar + dp)
  const double momentum = Kdx.norm2(), scale = fp.norm2() + f.norm2();
  ASSERT_GT(scale, 0);
  EXPECT_LT(momentum, 1e-9 * scale) << "|K dx - G dp + R| = " << momentum;

  // Volume rows: G^T dx = V - v.
  const std::vector<double> rate = volumeRate(assembly, u, dx);
  double worst = 0, largest = 0;
  for (size_t e = 0; e < V.size(); ++e) {
    worst = std::max(worst, std::fabs(rate[e] - (V[e] - v0[e])));
    largest = std::max(largest, std::fabs(V[e] - v0[e]));
  }
  double w = 0, l = 0;
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, worst, Teuchos::outArg(w));
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, largest, Teuchos::outArg(l));
  ASSERT_GT(l, 0);
  EXPECT_LT(w, 1e-6 * l) << "max |G^T dx - (V - v)| = " << w << ", max |V - v| = " << l;
  // Held dofs do not move.
  auto d = dx.getData();
  for (LO i = 0; i < LO(d.size()); ++i)
    if (assembly.ownedConstrained(i)) {
      EXPECT_EQ(d[i], 0.0);
    }
}

// Stopped early, the step predicts the volume error that the next Newton
// solve leaves: after the step, R = -r_u and the volumes' error is its own
// residual; Newton (multipliers held) then moves x by K^-1 r_u, which the
// prediction takes as K~^-1 r_u. With the direct solver (1 rank) K~^-1 = K^-1
// and the prediction is exact to first order; on 2 ranks K~^-1 is GMRES's
// preconditioner, and the check is of the formula. Checked with the
// assembly's own residual and volumes: r_u from R(pbar + dp) (R is linear in
// the anchors), the volumes along dx + K~^-1 r_u by a central difference.
TEST(PressureStep, PredictsTheVolumeErrorAfterNewton) {
  auto comm = Tpetra::getDefaultComm();
  BoxProblem problem(boxScene(), 1.0);
  auto& [scene, mesh, assembly, newton, u, f] = problem;
  // (1 rank: the direct solver; 2 ranks: GMRES, and K~^-1 its preconditioner)
  if (comm->getSize() == 1) {
    EXPECT_FALSE(newton.iterative());
  }
  BrickEffect& bricks = assembly.bricks();
  auto W = newton.matrix();
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get()));
  const auto Kinv = newton.approximateInverse();  // of W as it is now
  const std::vector<double> v0 = hostCopy(bricks.volume), V = hostCopy(bricks.referenceVolume);
  const std::vector<double> pbar0 = hostCopy(bricks.pressureAnchor);
  auto maxRelative = [&](const std::vector<double>& v) {
    double local = 0, global = 0;
    for (size_t e = 0; e < V.size(); ++e) local = std::max(local, std::fabs(v[e] - V[e]) / V[e]);
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, local, Teuchos::outArg(global));
    return global;
  };
  const double initial = maxRelative(v0);
  ASSERT_GT(initial, 1e-3);
  // A target the step meets long before its residual tolerance.
  const double target = 1e-4 * initial;
  Vector dx(assembly.dofMap());
  std::vector<Kokkos::View<double*>> dmu;
  PressureStep step(assembly);
  const auto result = step.solve(*W, Kinv, f, 1e-12, target, 500, dx, dmu);
  ASSERT_GT(result.volumePredicted, 0) << "the step must stop on its prediction";
  EXPECT_LE(result.volumePredicted, target);
  EXPECT_GT(result.reduction, 1e-10) << "stopped early";
  EXPECT_GE(result.predictions, 1);

  // r_u = -(R(pbar + dp) + K dx), then Newton's du = K^-1 r_u (here K~^-1 r_u).
  const std::vector<double> dph = hostCopy(dmu[0]);
  Vector ru(assembly.dofMap()), du(assembly.dofMap());
  setAnchors(bricks, pbar0, dph, 1);
  ASSERT_TRUE(assembly.evaluate(u, &ru, nullptr));
  setAnchors(bricks, pbar0, dph, 0);
  W->apply(dx, ru, Teuchos::NO_TRANS, -1.0, -1.0);
  Kinv(ru, du);
  {  // held dofs stay put
    auto d = du.getDataNonConst();
    for (LO i = 0; i < LO(d.size()); ++i)
      if (assembly.ownedConstrained(i)) d[i] = 0;
  }
  // The volumes after both, to first order: v0 + G^T (dx + du).
  Vector move(dx, Teuchos::Copy);
  move.update(1.0, du, 1.0);
  const std::vector<double> rate = volumeRate(assembly, u, move);
  std::vector<double> after(V.size());
  for (size_t e = 0; e < V.size(); ++e) after[e] = v0[e] + rate[e];
  const double measured = maxRelative(after);
  std::printf("volume error: initial %.3e, left by the step %.3e, predicted after Newton %.3e, measured %.3e\n",
              initial, result.volumeResidual, result.volumePredicted, measured);
  // The central difference's error is ~1e-9 of the initial error (above).
  EXPECT_NEAR(measured, result.volumePredicted, 1e-2 * result.volumePredicted + 1e-8 * initial);
}

// The Schur approximation changes how GMRES gets there, not where: both give
// the same step. The Laplacian one, which holds Q1P0's nearly spurious modes,
// takes fewer iterations (on a finer box, with MueLu as K~^-1: printed).
TEST(PressureStep, SchurModelsGiveTheSameStep) {
  Scene fine = boxScene();
  fine.mesh.cells = {16, 8, 12};
  fine.solver.linearSolver = SolverSettings::LinearSolver::GMRES;
  fine.solver.preconditioner = SolverSettings::Preconditioner::MueLu;
  fine.solver.minimumSolvePenalty = 3e-2;  // as Auto sets it for the saddle-point step
  BoxProblem problem(fine, 0.2);
  auto& [scene, mesh, assembly, newton, u, f] = problem;
  auto W = newton.matrix();
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get()));
  struct Outcome {
    PressureStep::Result result;
    RCP<Vector> dx;
    std::vector<double> dp;
  };
  auto run = [&](PressureStep::Schur schur) {
    Outcome o;
    o.dx = rcp(new Vector(assembly.dofMap()));
    std::vector<Kokkos::View<double*>> dmu;
    PressureStep step(assembly, schur);
    o.result = step.solve(*W, newton.approximateInverse(), f, 1e-12, 0.0, 500, *o.dx, dmu);
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), dmu[0]);
    o.dp.assign(h.data(), h.data() + h.size());
    return o;
  };
  const Outcome diagonal = run(PressureStep::Schur::Diagonal), laplacian = run(PressureStep::Schur::Laplacian);
  EXPECT_LT(diagonal.result.reduction, 1e-11);
  EXPECT_LT(laplacian.result.reduction, 1e-11);
  std::printf("pressure step iterations: diagonal %d, Laplacian %d\n", diagonal.result.iterations,
              laplacian.result.iterations);
  EXPECT_LT(laplacian.result.iterations, diagonal.result.iterations);
  Vector diff(*laplacian.dx, Teuchos::Copy);
  diff.update(-1.0, *diagonal.dx, 1.0);
  EXPECT_LT(diff.norm2(), 1e-9 * diagonal.dx->norm2());
  double worst = 0, largest = 0;
  for (size_t e = 0; e < diagonal.dp.size(); ++e) {
    worst = std::max(worst, std::fabs(laplacian.dp[e] - diagonal.dp[e]));
    largest = std::max(largest, std::fabs(diagonal.dp[e]));
  }
  auto comm = Tpetra::getDefaultComm();
  double w = 0, l = 0;
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, worst, Teuchos::outArg(w));
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, largest, Teuchos::outArg(l));
  ASSERT_GT(l, 0);
  EXPECT_LT(w, 1e-8 * l) << "max |dp_L - dp_D| = " << w << " of max |dp| = " << l;
}

}  // namespace

namespace {

using test::StepCheck;

// A box under a capstan that presses its top face (exact contact), with the
// capstan's friction law, solved by the saddle-point step at the box's field
// state, over the increment (0, dt): tests/pressure_step_check.hpp.
// The capstan's axis (along z) and radius: it presses the box's top face 0.08 deep.
constexpr double kPressAxisX = 1.1, kPressAxisY = 1 + 1 - 0.08, kPressRadius = 1;

Scene pressedBoxScene(const FrictionSettings& friction) {
  Scene scene = boxScene();
  CapstanSpec cap;
  cap.name = "capstan";
  cap.radius = kPressRadius;
  cap.axisPoint = {kPressAxisX, kPressAxisY, 0}, cap.axisDirection = {0, 0, 1};
  cap.angularVelocity = 1;
  cap.contactFaces = {"ymax"};
  cap.contact.method = ContactSettings::Method::AugmentedLagrangian;
  cap.contact.penalty = 1e-2, cap.contact.maxAugmentations = 50;
  cap.contact.minimumSolvePenalty = -1;
  cap.contact.quadrature = ContactSettings::Quadrature::Nodal;  // as exact contact requires
  cap.friction = friction;
  scene.capstans = {cap};
  return scene;
}

StepCheck checkStepOnPressedBox(const FrictionSettings& friction, double dt,
                                PressureStep::Preconditioner preconditioner = PressureStep::Preconditioner::Block,
                                Vector* dx = nullptr) {
  BoxProblem problem(pressedBoxScene(friction), 0.3);
  auto& [sc, mesh, assembly, newton, u, f] = problem;
  assembly.setInterval(0.0, dt);
  auto W = newton.matrix();
  if (!assembly.evaluate(u, &f, W.get())) {
    ADD_FAILURE() << "box state not valid";
    return {};
  }
  if (dx) *dx = Vector(assembly.dofMap());
  return test::checkPressureStep(assembly, newton, u, f, *W, preconditioner, dx);
}

}  // namespace

// With exact contact the step also moves the contact multipliers: the points in
// contact (t_n > 0) get rows c_q = g_q next to the volumes'.
TEST(PressureStep, MovesContactMultipliersWithTheVolumes) {
  const StepCheck check = checkStepOnPressedBox(FrictionSettings(), 0.0);
  EXPECT_GT(check.result.contactRows, 8) << "the capstan must press the top face";
  ASSERT_EQ(check.rowError.size(), 2u) << "rows of the bricks and the contact";
  for (const auto& [name, error] : check.rowError) {
    EXPECT_LT(error, 1e-5) << name << " rows: max |c + dc/dx dx| / max |c|";
    EXPECT_LT(check.columnError.at(name), 1e-8) << name << " columns";
  }
}

// With Coulomb friction (augmented Lagrangian) the sticking points get two rows
// each, the slip along the capstan's tangents, and the stick tractions move
// with the volumes and contact. A stick row's gradient leaves out the slip's
// curvature terms (of the order of the capstan's travel over its radius, here
// 0.02): its linearisation holds to that, the others' to round-off.
TEST(PressureStep, MovesStickTractionsWithTheVolumes) {
  FrictionSettings coulomb;
  coulomb.law = FrictionSettings::Law::Coulomb;
  coulomb.coefficient = 5;  // every point in contact sticks
  const StepCheck check = checkStepOnPressedBox(coulomb, 0.02);
  ASSERT_EQ(check.rowError.size(), 3u) << "rows of the bricks, the contact and the stick points";
  const long contact = check.rows.at("contact:capstan"), stick = check.rows.at("friction:capstan");
  EXPECT_GT(contact, 8);
  EXPECT_EQ(stick, 2 * contact) << "two tangents per point in contact";
  for (const auto& [name, error] : check.rowError) {
    std::printf("%s rows: max |c + dc/dx dx| / max |c| = %.2e; columns %.2e\n", name.c_str(), error,
                check.columnError.at(name));
    EXPECT_LT(error, name == "friction:capstan" ? 5e-2 : 1e-5) << name;
    EXPECT_LT(check.columnError.at(name), 1e-8) << name << " columns";
  }
}

// The step's whole block matrix factored (SaddlePointLU) as GMRES's
// preconditioner: the same step as the block-triangular one in 1-3 iterations,
// though a node's stick and contact rows repeat once per face at it (the
// factored matrix is regularised for that, and GMRES removes the difference).
TEST(PressureStep, FactoredBlockMatrixGivesTheSameStep) {
  FrictionSettings coulomb;
  coulomb.law = FrictionSettings::Law::Coulomb;
  coulomb.coefficient = 5;  // every point in contact sticks
  Vector block, lu;
  const StepCheck b = checkStepOnPressedBox(coulomb, 0.02, PressureStep::Preconditioner::Block, &block);
  const StepCheck l = checkStepOnPressedBox(coulomb, 0.02, PressureStep::Preconditioner::LU, &lu);
  std::printf("pressure step iterations: block-triangular %d, factored block matrix %d\n", b.result.iterations,
              l.result.iterations);
  EXPECT_TRUE(l.result.lu && !b.result.lu);
  EXPECT_LE(l.result.iterations, 3);
  EXPECT_GT(b.result.iterations, l.result.iterations);
  EXPECT_GT(l.rows.at("friction:capstan"), 16) << "stick rows in the step";
  Vector diff(lu, Teuchos::Copy);
  diff.update(-1.0, block, 1.0);
  EXPECT_LT(diff.norm2(), 1e-8 * block.norm2()) << "|dx_LU - dx_block| against |dx_block| = " << block.norm2();
  for (const auto& [name, error] : l.rowError) {
    EXPECT_LT(error, name == "friction:capstan" ? 5e-2 : 1e-5) << name;
    EXPECT_LT(l.columnError.at(name), 1e-8) << name << " columns";
  }
}

// The step's constraint pattern may change on one rank only, with every rank's
// row count unchanged (there a point leaves contact and another comes in).
// Every rank must still take the same path through the gradient's
// fillComplete: it is collective for a new pattern and not for a refilled one.
// Deciding per rank deadlocked the 126k-dof steady drive on 2 ranks. (Under
// the bug this test hangs; ctest's timeout fails it.)
TEST(PressureStep, ContactPatternChangingOnOneRankOnly) {
  BoxProblem problem(pressedBoxScene(FrictionSettings()), 0.3);
  auto& [sc, mesh, assembly, newton, u, f] = problem;
  auto W = newton.matrix();
  PressureStep step(assembly);
  std::vector<Kokkos::View<double*>> dmu;
  Vector dx(assembly.dofMap());
  const auto solveStep = [&] {
    EXPECT_TRUE(assembly.evaluate(u, &f, W.get()));
    return step.solve(*W, newton.approximateInverse(), f, 1e-6, 0.0, 200, dx, dmu);
  };
  const PressureStep::Result first = solveStep();
  ASSERT_GT(first.contactRows, 2);
  // Each rank's contact rows (one per face point in contact, nodal points).
  const auto localRows = [&] {
    ConstraintRows rows;
    long n = 0;
    for (const auto& e : assembly.effects())
      if (e->constraintName().rfind("contact", 0) == 0) e->constraintRows(assembly.positions(), rows), n += long(rows.size());
    return n;
  };
  const long rowsBefore = localRows();
  // On the lowest rank that owns both: a top node inside the capstan on a z
  // edge (2 faces) moves out of it, and one on x = 2 inside the z range (2
  // faces), beyond the footprint, moves into it: the same number of rows.
  auto ud = u.getDataNonConst();
  long leaving = -1, entering = -1;
  for (size_t n = 0; n < mesh.numOwnedNodes; ++n) {
    const double* X = &mesh.X[3 * n];
    if (std::fabs(X[1] - 1) > 1e-12) continue;
    const bool zEdge = X[2] < 1e-12 || X[2] > 1.5 - 1e-12;
    const double x = X[0] + ud[3 * n], y = X[1] + ud[3 * n + 1];
    if (leaving < 0 && zEdge && std::hypot(x - kPressAxisX, y - kPressAxisY) < kPressRadius - 1e-3) leaving = long(n);
    if (entering < 0 && !zEdge && std::fabs(X[0] - 2) < 1e-12) entering = long(n);
  }
  const auto comm = assembly.dofMap()->getComm();
  const int mine = leaving >= 0 && entering >= 0 ? comm->getRank() : comm->getSize();
  int mover = 0;
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MIN, mine, Teuchos::outArg(mover));
  ASSERT_LT(mover, comm->getSize()) << "no rank owns a top node in contact and one beyond the footprint";
  if (comm->getRank() == mover) {
    ud[3 * leaving + 1] -= 0.3;   // y ~ 0.7, below the capstan's lowest point 0.92
    ud[3 * entering + 1] += 0.6;  // y ~ 1.6, above the capstan's surface at x = 2 (1.48)
  }
  const PressureStep::Result second = solveStep();
  int sameCount = localRows() == rowsBefore, everywhere = 0;
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MIN, sameCount, Teuchos::outArg(everywhere));
  EXPECT_EQ(everywhere, 1) << "every rank keeps its number of contact rows";
  EXPECT_EQ(second.contactRows, first.contactRows) << "two face points out, two in";
  EXPECT_TRUE(std::isfinite(second.reduction));
  EXPECT_LT(second.reduction, 1e-3);
}
