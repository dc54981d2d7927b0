// The rigid core: its follower kinematics (kernels/rigid_core.hpp) and its
// coupling in the assembly (the chain rule at the core's face nodes), checked
// against central differences of the assembled residual with the core's
// translation and rotation free, a capstan pressing with friction, on 1 and 2
// ranks. A rigid motion of body and core leaves no residual.
#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <Teuchos_CommHelpers.hpp>

#include <algorithm>
#include <cmath>

#include "assembly.hpp"
#include "newton.hpp"
#include "pressure_step_check.hpp"
#include "errors.hpp"
#include "roller_scene.hpp"
#include "scene.hpp"
#include "streamline_shift.hpp"
#include "effects/effect.hpp"

using namespace capstan;

namespace {

using capstan::test::kRollerScene;
const char* const kScene = kRollerScene;

// The scene's annulus, distributed over the ranks.
Mesh annulusMesh(const Scene& scene) {
  const auto& m = scene.mesh;
  AnnulusGenerator gen(m.center, m.innerRadius, m.outerRadius, m.length, m.cells);
  return distributeMesh(gen, Tpetra::getDefaultComm());
}

TEST(RigidCoreKernel, FollowerDerivativesMatchCentralDifferences) {
  double d[3] = {0.2, -0.3, 0.9};
  const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (double& x : d) x /= n;
  const double A[3] = {0.3, -0.1, 0.5}, T[3] = {0.05, -0.02, 0.01}, X[3] = {1.2, 0.7, -0.4};
  const double theta = 0.7, h = 1e-6;
  const auto f = kernels::coreFollower(A, d, T, theta, X);
  const auto p = kernels::coreFollower(A, d, T, theta + h, X);
  const auto m = kernels::coreFollower(A, d, T, theta - h, X);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR((p.u[i] - m.u[i]) / (2 * h), f.b[i], 1e-8);
    EXPECT_NEAR((p.b[i] - m.b[i]) / (2 * h), f.w[i], 1e-8);
  }
  // A rotation keeps the distance to the axis and the position along it.
  double r0[3], r[3], along0 = 0, along = 0, l0 = 0, l = 0;
  for (int i = 0; i < 3; ++i) r0[i] = X[i] - A[i], r[i] = X[i] + f.u[i] - T[i] - A[i];
  for (int i = 0; i < 3; ++i) along0 += r0[i] * d[i], along += r[i] * d[i];
  for (int i = 0; i < 3; ++i) l0 += std::pow(r0[i] - along0 * d[i], 2), l += std::pow(r[i] - along * d[i], 2);
  EXPECT_NEAR(along, along0, 1e-14);
  EXPECT_NEAR(l, l0, 1e-13);
  // A whole turn brings the node back (u = T).
  const auto full = kernels::coreFollower(A, d, T, 2 * M_PI, X);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(full.u[i], T[i], 1e-14);
}

// A smooth field on the free dofs, and values for the core's unknowns.
void fill(const Assembly& a, const Mesh& mesh, Vector& v, double scale, double phase) {
  auto d = v.getDataNonConst();
  for (size_t n = 0; n < mesh.numOwnedNodes; ++n)
    for (int i = 0; i < 3; ++i)
      d[3 * n + i] = scale * std::sin(1.3 * mesh.X[3 * n] + 0.7 * mesh.X[3 * n + 1] + 2 * mesh.X[3 * n + 2] + i + phase);
  if (a.ownedCoreDof(0, 0) >= 0) {
    d[a.ownedCoreDof(0, 0)] = 0.4 * scale * std::cos(phase);
    d[a.ownedCoreDof(0, 1)] = -0.3 * scale;
    d[a.ownedCoreDof(0, 3)] = 2 * scale * std::sin(phase + 1);
  }
}

TEST(RigidCore, CoupledTangentMatchesCentralDifferences) {
  const Scene scene = parseScene(kScene, "rigid-core-test.xml", {}, "");
  Mesh mesh = annulusMesh(scene);
  Assembly assembly(mesh, scene);
  const auto map = assembly.dofMap();
  Vector u(map), v(map), f(map), fp(map), fm(map), Wv(map), trial(map);
  fill(assembly, mesh, u, 0.02, 0.0);
  assembly.setInterval(0.0, 0.5);
  assembly.applyConstraints(u, 0.5);
  fill(assembly, mesh, v, 1.0, 0.4);
  {
    auto d = v.getDataNonConst();
    for (LO i = 0; i < LO(d.size()); ++i)
      if (assembly.ownedConstrained(i)) d[i] = 0;
  }
  auto W = assembly.createMatrix();
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get()));
  // The capstan presses and the core carries it: the state is a real test.
  const auto& core = assembly.rigidCores().at(0);
  EXPECT_GT(std::fabs(core.forceOnBody[1]), 1e-3);
  EXPECT_GT(std::fabs(core.torqueOnBody), 1e-4);
  EXPECT_GT(std::fabs(core.rotation), 1e-3);
  // The torque balance's row is a force: the torque over the core's radius, in the residual
  // as in W (the differences below check W's row against it).
  {
    // The core's radius: its face's largest distance from its (skewed) axis, over the ranks.
    double radius = 0, global = 0;
    for (int n : mesh.faceNodes("inner")) {
      double r[3], along = 0, r2 = 0;
      for (int i = 0; i < 3; ++i) r[i] = mesh.X[3 * n + i] - core.axisPoint[i], along += r[i] * core.axisDirection[i];
      for (int i = 0; i < 3; ++i) r2 += std::pow(r[i] - along * core.axisDirection[i], 2);
      radius = std::max(radius, std::sqrt(r2));
    }
    Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_MAX, radius, Teuchos::outArg(global));
    EXPECT_GT(global, scene.mesh.innerRadius);  // the axis is off the mesh's centre
    EXPECT_NEAR(core.radius, global, 1e-12 * global);
  }
  if (assembly.ownedCoreDof(0, 3) >= 0) {
    EXPECT_NEAR(f.getData()[assembly.ownedCoreDof(0, 3)],
                (core.torqueOnBody - core.torqueFactor(0.5) * core.torque) / core.radius,
                1e-12 * std::fabs(core.torqueOnBody) / core.radius);
  }
  W->apply(v, Wv);
  const double h = 1e-6;
  trial.update(1.0, u, h, v, 0.0);
  ASSERT_TRUE(assembly.evaluate(trial, &fp, nullptr));
  trial.update(1.0, u, -h, v, 0.0);
  ASSERT_TRUE(assembly.evaluate(trial, &fm, nullptr));
  Vector diff(map);
  diff.update(1 / (2 * h), fp, -1 / (2 * h), fm, 0.0);
  diff.update(-1.0, Wv, 1.0);
  EXPECT_LT(diff.norm2(), 1e-6 * Wv.norm2()) << "|W v| = " << Wv.norm2();
  // The core's rows on their own (rank 0 owns them).
  double worst = 0, scale = 0;
  {
    auto dd = diff.getData();
    auto wv = Wv.getData();
    for (int j : {0, 1, 3}) {
      const LO d = assembly.ownedCoreDof(0, j);
      if (d < 0) continue;
      worst = std::max(worst, std::fabs(dd[d]));
      scale = std::max(scale, std::fabs(wv[d]));
    }
  }
  if (assembly.ownedCoreDof(0, 0) >= 0) {
    EXPECT_GT(scale, 1e-3);
    EXPECT_LT(worst, 1e-6 * scale);
  }
}

// The saddle-point step with a free core, quasi-static: a multiplier's column reaches the torque
// balance's row as the residual holds it (over the core's radius), its gradient the rotation's
// column by the lever arm alone (tests/pressure_step_check.hpp).
TEST(RigidCore, SaddlePointStepReachesTheTorqueRow) {
  const Scene scene = parseScene(kScene, "rigid-core-test.xml",
                                 {"Capstans/capstan/Friction/Law=Coulomb", "Capstans/capstan/Friction/Tangential Penalty=0.5",
                                  "Capstans/capstan/Contact/Method=Augmented Lagrangian",
                                  "Capstans/capstan/Friction/Coefficient=5"},
                                 "");
  Mesh mesh = annulusMesh(scene);
  Assembly assembly(mesh, scene);
  NewtonSolver newton(assembly, scene.solver);
  const auto map = assembly.dofMap();
  Vector u(map), f(map);
  fill(assembly, mesh, u, 0.02, 0.0);
  assembly.setInterval(0.0, 0.5);
  assembly.applyConstraints(u, 0.5);
  auto W = newton.matrix();
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get()));
  const test::StepCheck check = test::checkPressureStep(assembly, newton, u, f, *W);
  ASSERT_TRUE(check.columnError.count("brick"));
  for (const auto& [name, error] : check.columnError) {
    std::printf("%s: columns %.2e, rows %.2e\n", name.c_str(), error, check.rowError.at(name));
    EXPECT_LT(error, 1e-8) << name;
  }
}

TEST(RigidCore, RigidMotionLeavesNoResidual) {
  // Without the capstan and loads, turning and moving body and core together
  // is a rigid motion: no stress, no reaction, no residual.
  Scene scene = parseScene(kScene, "rigid-core-test.xml", {"Supports/core/Force={0,0,0}", "Supports/core/Torque=0"}, "");
  scene.capstans.clear();
  Mesh mesh = annulusMesh(scene);
  Assembly assembly(mesh, scene);
  Vector u(assembly.dofMap()), f(assembly.dofMap());
  assembly.setInterval(0.0, 1.0);
  {
    auto d = u.getDataNonConst();
    for (size_t n = 0; n < mesh.numOwnedNodes; ++n) d[3 * n] = 0.3, d[3 * n + 1] = -0.2;
    if (assembly.ownedCoreDof(0, 0) >= 0) d[assembly.ownedCoreDof(0, 0)] = 0.3, d[assembly.ownedCoreDof(0, 1)] = -0.2;
  }
  assembly.rollWithCores(u, {0.9});  // the translated body turned with the core
  ASSERT_TRUE(assembly.evaluate(u, &f, nullptr));
  EXPECT_LT(f.normInf(), 1e-12);
  const auto& core = assembly.rigidCores().at(0);
  EXPECT_NEAR(core.rotation, 0.9, 1e-15);
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::fabs(core.forceOnBody[i]), 1e-12);
  EXPECT_LT(std::fabs(core.torqueOnBody), 1e-12);
}

}  // namespace

// Force and Torque ramp apart (Torque Ramp Time, default Force Ramp Time,
// whose default is the first step's end): a brake sweep is one run.
TEST(RigidCore, TorqueRampsToItsOwnTime) {
  auto core = [](const std::vector<std::string>& sets) {
    return parseScene(kScene, "rigid-core-test.xml", sets, "").supports.at(0);
  };
  EXPECT_EQ(core({}).rampTime, 1.0);
  EXPECT_EQ(core({}).torqueRampTime, 1.0);
  EXPECT_EQ(core({"Supports/core/Force Ramp Time=3"}).torqueRampTime, 3.0);
  const SupportSpec s = core({"Supports/core/Force Ramp Time=2", "Supports/core/Torque Ramp Time=5"});
  EXPECT_EQ(s.rampTime, 2.0);
  EXPECT_EQ(s.torqueRampTime, 5.0);
  EXPECT_THROW(core({"Supports/core/Torque Ramp Time=-1"}), InputError);
  RigidCore c;
  c.rampTime = s.rampTime, c.torqueRampTime = s.torqueRampTime;
  EXPECT_DOUBLE_EQ(c.loadFactor(1.0), 0.5);
  EXPECT_DOUBLE_EQ(c.torqueFactor(1.0), 0.2);
  EXPECT_DOUBLE_EQ(c.loadFactor(4.0), 1.0);
  EXPECT_DOUBLE_EQ(c.torqueFactor(4.0), 0.8);
  EXPECT_DOUBLE_EQ(c.torqueFactor(6.0), 1.0);
}

// The streamline shift moves the multipliers with the material: each site's
// value becomes the one dTheta downstream along its ring, linear in angle
// (src/streamline_shift.hpp). Pressure anchors (per element), exact contact
// pressures and stick tractions (per nodal point) carry smooth fields of the
// angle about the core's axis; a shift by one cell must hand each site its
// downstream neighbour's value exactly, and a shift by part of a cell the
// field's value there within linear interpolation's error.
TEST(StreamlineShift, MovesMultipliersAlongTheRings) {
  const int cells = 24;
  const Scene scene = parseScene(kScene, "rigid-core-test.xml",
                                 {"Mesh/Cells={2, 24, 2}", "Supports/core/Axis Point={0, 0, 0}",
                                  "Supports/core/Axis Direction={0, 0, 1}",
                                  "Capstans/capstan/Contact/Method=Augmented Lagrangian",
                                  "Capstans/capstan/Friction/Law=Coulomb"},
                                 "");
  Mesh mesh = annulusMesh(scene);
  Assembly assembly(mesh, scene);
  StreamlineShift shift(mesh, assembly.dofMap());
  const auto& core = assembly.rigidCores().at(0);
  auto angleOf = [&](const int* nodes, int count) {
    double sx = 0, sy = 0;
    for (int a = 0; a < count; ++a) {
      const double th = std::atan2(mesh.X[3 * nodes[a] + 1], mesh.X[3 * nodes[a]]);
      sx += std::cos(th), sy += std::sin(th);
    }
    return std::atan2(sy, sx);
  };
  // A smooth positive field (contact pressures are projected onto >= 0).
  auto field = [](double th, int c) { return 2 + std::cos(th + c) + 0.5 * std::sin(2 * th); };
  int shifted = 0;
  for (const auto& e : assembly.effects()) {
    std::vector<int> nodes;
    const int perSite = e->multiplierSites(nodes);
    if (perSite == 0) continue;
    ++shifted;
    const size_t sites = nodes.size() / perSite;
    auto view = e->multipliers();
    const int components = sites ? int(view.extent(0) / sites) : 1;
    for (double dTheta : {2 * M_PI / cells, 0.1}) {
      auto h = Kokkos::create_mirror_view(view);
      for (size_t s = 0; s < sites; ++s)
        for (int c = 0; c < components; ++c)
          h(s * components + c) = nodes[s * perSite] < 0 ? 0.0 : field(angleOf(&nodes[s * perSite], perSite), c);
      Kokkos::deep_copy(view, h);
      shift.shiftMultipliers(*e, core, 0, dTheta);
      Kokkos::deep_copy(h, view);
      // Linear interpolation's error bound, h^2/8 max|f''| (f'' <= 3).
      const double tol = dTheta < 0.2 ? std::pow(2 * M_PI / cells, 2) / 8 * 3 : 1e-12;
      double worst = 0;
      for (size_t s = 0; s < sites; ++s) {
        if (nodes[s * perSite] < 0) continue;
        const double th = angleOf(&nodes[s * perSite], perSite) + dTheta;
        for (int c = 0; c < components; ++c) worst = std::max(worst, std::fabs(h(s * components + c) - field(th, c)));
      }
      EXPECT_LT(worst, tol) << e->name() << " shifted by " << dTheta;
      if (dTheta < 0.2) {
        EXPECT_GT(worst, 1e-4) << "the field is not linear: interpolation must show";
      }
    }
  }
  EXPECT_EQ(shifted, 3);  // bricks, contact, friction
}
