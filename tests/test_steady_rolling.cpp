// Steady rolling (formulation.md §8): the assembled tangent of a scene with
// steady friction (the slip rate from upwind differences along the rings, the
// core's angular velocity an unknown) against central differences of the
// assembled residual, for each friction law and upwind order, on 1 and 2
// ranks; omega's column on its own; the scene checks of Analysis/Type.
#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <Teuchos_CommHelpers.hpp>

#include <cmath>
#include <limits>
#include <string>

#include "assembly.hpp"
#include "errors.hpp"
#include "newton.hpp"
#include "pressure_step_check.hpp"
#include "roller_scene.hpp"
#include "rolling.hpp"
#include "scene.hpp"

using namespace capstan;

namespace {

// The rigid-core test roller (tests/roller_scene.hpp) made a steady-rolling
// scene: its core on the annulus axis, a fine sector at the nip, a sharper Tanh.
const std::vector<std::string> kSteady = {
    "Analysis/Type=Steady Rolling",           "Supports/core/Axis Point={0, 0, 0}",
    "Supports/core/Axis Direction={0, 0, 1}", "Mesh/Cells={2, 16, 2}",
    "Mesh/Fine Sector={-90, 80, 0.5}",        "Capstans/capstan/Friction/Regularization=0.05"};

Scene steadyScene(std::vector<std::string> sets) {
  sets.insert(sets.begin(), kSteady.begin(), kSteady.end());
  return parseScene(test::kRollerScene, "steady-test.xml", sets, "");
}

// A smooth field on the free dofs; the core's translation and angular velocity.
void fill(const Assembly& a, const Mesh& mesh, Vector& v, double scale, double phase, double omega) {
  auto d = v.getDataNonConst();
  for (size_t n = 0; n < mesh.numOwnedNodes; ++n)
    for (int i = 0; i < 3; ++i)
      d[3 * n + i] = scale * std::sin(1.3 * mesh.X[3 * n] + 0.7 * mesh.X[3 * n + 1] + 2 * mesh.X[3 * n + 2] + i + phase);
  if (a.ownedCoreDof(0, 0) >= 0) {
    d[a.ownedCoreDof(0, 0)] = 0.4 * scale * std::cos(phase);
    d[a.ownedCoreDof(0, 1)] = -0.3 * scale;
    d[a.ownedCoreDof(0, 3)] = omega;
  }
}

// fill() with the held dofs left at zero: a direction the constraints allow.
void fillFree(const Assembly& a, const Mesh& mesh, Vector& v, double scale, double phase, double omega) {
  fill(a, mesh, v, scale, phase, omega);
  auto d = v.getDataNonConst();
  for (LO i = 0; i < LO(d.size()); ++i)
    if (a.ownedConstrained(i)) d[i] = 0;
}

struct Case {
  const char* name;
  std::vector<std::string> sets;
};

class SteadyTangent : public ::testing::TestWithParam<Case> {};

// Relative error of W v against the central difference of the residual along v.
double tangentError(Assembly& assembly, const Vector& u, const Vector& v, double& scale) {
  const auto map = assembly.dofMap();
  Vector f(map), fp(map), fm(map), Wv(map), trial(map);
  auto W = assembly.createMatrix();
  EXPECT_TRUE(assembly.evaluate(u, &f, W.get()));
  W->apply(v, Wv);
  const double h = 1e-6;
  trial.update(1.0, u, h, v, 0.0);
  EXPECT_TRUE(assembly.evaluate(trial, &fp, nullptr));
  trial.update(1.0, u, -h, v, 0.0);
  EXPECT_TRUE(assembly.evaluate(trial, &fm, nullptr));
  Vector diff(map);
  diff.update(1 / (2 * h), fp, -1 / (2 * h), fm, 0.0);
  diff.update(-1.0, Wv, 1.0);
  scale = Wv.norm2();
  return diff.norm2() / scale;
}

TEST_P(SteadyTangent, MatchesCentralDifferences) {
  const Case k = GetParam();
  const Scene scene = steadyScene(k.sets);
  const auto& m = scene.mesh;
  AnnulusGenerator gen(m.center, m.innerRadius, m.outerRadius, m.length, m.cells, m.outerCellRatio, m.fineSector);
  Mesh mesh = distributeMesh(gen, Tpetra::getDefaultComm(), Partition::Metis, {"outer"});
  Assembly assembly(mesh, scene);
  ASSERT_EQ(assembly.frictions().size(), 1u);
  ASSERT_NE(dynamic_cast<const SteadyFrictionEffect*>(assembly.frictions()[0]), nullptr);
  const auto map = assembly.dofMap();
  Vector u(map), v(map);
  // Near the no-slip angular velocity -omega_c R_c / R = -0.25: some points
  // stick, some slip.
  fill(assembly, mesh, u, 0.02, 0.0, -0.23);
  assembly.setInterval(0.0, 0.5);
  assembly.applyConstraints(u, 0.5);
  fillFree(assembly, mesh, v, 1.0, 0.4, 0.7);
  double scale = 0;
  const double err = tangentError(assembly, u, v, scale);
  const auto ff = assembly.frictions()[0]->figures();
  long stick = ff.stick, slip = ff.slip;
  Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_SUM, ff.stick, Teuchos::outArg(stick));
  Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_SUM, ff.slip, Teuchos::outArg(slip));
  EXPECT_GT(stick + slip, 4) << k.name << ": the capstan must press";
  EXPECT_LT(err, 1e-6) << k.name << " |W v| = " << scale;
  // omega's column alone, where omega is an unknown: friction is the only
  // thing that sees it.
  if (!assembly.rigidCores().at(0).free[3]) return;
  Vector e(map);
  if (assembly.ownedCoreDof(0, 3) >= 0) e.getDataNonConst()[assembly.ownedCoreDof(0, 3)] = 1.0;
  const double errOmega = tangentError(assembly, u, e, scale);
  EXPECT_GT(scale, 1e-4) << k.name << ": omega's column is empty";
  EXPECT_LT(errOmega, 1e-6) << k.name << " (omega's column)";
}

INSTANTIATE_TEST_SUITE_P(
    Steady, SteadyTangent,
    ::testing::Values(Case{"tanh, second order", {}},
                      Case{"tanh, first order", {"Analysis/Upwind Order=1"}},
                      Case{"arctan, second order", {"Capstans/capstan/Friction/Law=Arctan"}},
                      Case{"coulomb, second order",
                           {"Capstans/capstan/Friction/Law=Coulomb", "Capstans/capstan/Friction/Tangential Penalty=0.5"}},
                      Case{"tanh, braked by a prescribed rotation",
                           {"Supports/core/Rotation=Prescribed", "Supports/core/Angular Velocity=-0.2",
                            "Supports/core/Torque=0"}}));

// Coulomb's sticking points in the saddle-point step, steady: two rows each,
// whose slip spans the upstream nodes and omega while the traction acts on the
// face's nodes (ConstraintRows::column). The momentum rows hold to 1e-8 and the
// other rows' linearisations to 1e-5 (tests/pressure_step_check.hpp); a stick
// row's gradient leaves out the slip's curvature terms (the tangent plane
// turning with the point), to which its linearisation holds.
TEST(SteadyStick, SaddlePointStepMovesStickTractions) {
  const Scene scene = steadyScene({"Capstans/capstan/Friction/Law=Coulomb",
                                   "Capstans/capstan/Friction/Tangential Penalty=0.5",
                                   "Capstans/capstan/Contact/Method=Augmented Lagrangian",
                                   "Capstans/capstan/Friction/Coefficient=5"});
  const auto& m = scene.mesh;
  AnnulusGenerator gen(m.center, m.innerRadius, m.outerRadius, m.length, m.cells, m.outerCellRatio, m.fineSector);
  Mesh mesh = distributeMesh(gen, Tpetra::getDefaultComm(), Partition::Metis, {"outer"});
  Assembly assembly(mesh, scene);
  NewtonSolver newton(assembly, scene.solver);
  const auto map = assembly.dofMap();
  Vector u(map), f(map);
  fill(assembly, mesh, u, 0.02, 0.0, -0.23);
  assembly.setInterval(0.0, 0.5);
  assembly.applyConstraints(u, 0.5);
  auto W = newton.matrix();
  ASSERT_TRUE(assembly.evaluate(u, &f, W.get()));
  const test::StepCheck check = test::checkPressureStep(assembly, newton, u, f, *W);
  const std::string friction = assembly.frictions()[0]->name(), contact = assembly.contacts()[0]->name();
  ASSERT_TRUE(check.rows.count(friction) && check.rows.at(friction) > 4) << "sticking points";
  for (const auto& [name, error] : check.rowError) {
    std::printf("%s rows (%ld): max |c + dc/dx dx| / max |c| = %.2e; columns %.2e\n", name.c_str(),
                check.rows.at(name), error, check.columnError.at(name));
    EXPECT_LT(error, name == friction ? 2e-2 : 1e-5) << name;
    // Every column to 1e-8, the bricks' with the torque balance's row: their
    // entries on the core's face nodes reach it by the lever arm, though omega
    // moves no face node (before, that entry was missing: 4e-3).
    EXPECT_LT(check.columnError.at(name), 1e-8) << name;
  }
}

// The step predictor's K z (the kernels' products, the cores' rows summed from
// their face nodes) against the assembled matrix on every free row, the core's
// included, with omega free and with it held at the start's value (its row
// omega - held = 0, whose K z is then 0, not the torque balance's).
TEST(SteadyCore, PredictorLoadMatchesMatrixOnTheCoreRows) {
  const Scene scene = steadyScene({});
  const auto& m = scene.mesh;
  AnnulusGenerator gen(m.center, m.innerRadius, m.outerRadius, m.length, m.cells, m.outerCellRatio, m.fineSector);
  Mesh mesh = distributeMesh(gen, Tpetra::getDefaultComm(), Partition::Metis, {"outer"});
  Assembly assembly(mesh, scene);
  const auto map = assembly.dofMap();
  Vector u(map), z(map), Kz(map), Wz(map), f(map);
  fill(assembly, mesh, u, 0.02, 0.0, -0.23);
  assembly.setInterval(0.0, 0.5);
  assembly.applyConstraints(u, 0.5);
  fillFree(assembly, mesh, z, 1.0, 0.4, 0.0);
  for (int j = 0; j < 6; ++j)  // node dofs only, as the predictor's z on a free core
    if (assembly.ownedCoreDof(0, j) >= 0) z.getDataNonConst()[assembly.ownedCoreDof(0, j)] = 0;
  for (const bool hold : {false, true}) {
    assembly.cores().holdAngularVelocity(0, hold ? -0.25 : std::numeric_limits<double>::quiet_NaN());
    auto W = assembly.createMatrix();
    ASSERT_TRUE(assembly.evaluate(u, &f, W.get(), &z, &Kz));
    W->apply(z, Wz);
    const double scale = Wz.normInf();
    Vector diff(map);
    diff.update(1.0, Kz, -1.0, Wz, 0.0);
    {
      auto d = diff.getDataNonConst();
      for (LO i = 0; i < LO(d.size()); ++i)
        if (assembly.ownedConstrained(i)) d[i] = 0;
    }
    // The torque row's own entry, where this rank owns it.
    double torqueRow = 0, torqueRowAll = 0;
    if (assembly.ownedCoreDof(0, 3) >= 0) torqueRow = std::fabs(Wz.getData()[assembly.ownedCoreDof(0, 3)]);
    Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_MAX, torqueRow, Teuchos::outArg(torqueRowAll));
    std::printf("omega %s: max |K z - W z| / max |W z| = %.2e, |W z| on the torque row %.2e\n",
                hold ? "held" : "free", diff.normInf() / scale, torqueRowAll);
    EXPECT_LT(diff.normInf(), 1e-12 * scale) << (hold ? "held" : "free");
    if (hold) {
      EXPECT_EQ(torqueRowAll, 0.0) << "the held row: omega - held";
    } else {
      EXPECT_GT(torqueRowAll, 1e-6 * scale) << "the torque balance sees the face nodes";
    }
  }
}

// Analysis/Type = Steady Rolling needs an annulus about its own axis on a
// Rigid Core or Fixed inner face, and capstans parallel to it that stay put.
TEST(SteadyScene, RejectsWhatItCannotSolve) {
  auto fails = [](const std::vector<std::string>& sets, const std::string& path) {
    try {
      steadyScene(sets);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "accepted: " << path;
  };
  EXPECT_NO_THROW(steadyScene({}));
  fails({"Capstans/capstan/Axis Direction={0.1,0,1}"}, "Capstans/capstan/Axis Direction");
  fails({"Capstans/capstan/Velocity={0.1,0,0}"}, "Capstans/capstan/Velocity");
  fails({"Capstans/capstan/Angular Velocity=0"}, "Capstans/capstan/Angular Velocity");
  fails({"Supports/core/Axis Point={0.1,0,0}"}, "Supports/core/Axis Point");
  fails({"Supports/core/Axis Direction={0,1,1}"}, "Supports/core/Axis Direction");
  fails({"Analysis/Upwind Order=3"}, "Analysis/Upwind Order");
  fails({"Analysis/Start Slip Scales={0.02, 0.04}"}, "Analysis/Start Slip Scales");  // widest first
  fails({"Analysis/Start Slip Scales={0.02, 0}"}, "Analysis/Start Slip Scales");
  EXPECT_EQ(steadyScene({"Analysis/Start Slip Scales={0.5}"}).analysis.startSlipScales, std::vector<double>{0.5});
  fails({"Analysis/Type=Steady"}, "Analysis/Type");
  // MueLu and Jacobi divide by omega's empty diagonal: refused where a Krylov
  // solve would build them, a warning where Auto solves the mesh directly.
  fails({"Solver/Linear Solver=GMRES", "Solver/Preconditioner=MueLu"}, "Solver/Preconditioner");
  fails({"Solver/Preconditioner=Jacobi", "Solver/Direct Solver Max Dofs=100"}, "Solver/Preconditioner");
  // (Contact/Penalty within formulation.md's range: the test scene's 0.05 has a warning of its own.)
  const Scene direct = steadyScene({"Solver/Preconditioner=Jacobi", "Capstans/capstan/Contact/Penalty=1e-2"});
  // The other warning: this roller is free along x and y, so it can roll off its one capstan.
  ASSERT_EQ(direct.warnings.size(), 2u);
  EXPECT_NE(direct.warnings[0].find("rolls off the capstan"), std::string::npos) << direct.warnings[0];
  EXPECT_NE(direct.warnings[1].find("Jacobi is not used"), std::string::npos) << direct.warnings[1];
}

// A rolling step (steady or quasi-static, on an annulus) that stalled under
// Coulomb's exact stick is told what converges where stick and slip chatter;
// other failures and other laws are not.
TEST(SteadyScene, StickChatterHint) {
  const std::string stalled = "augmentation loop stalled: volume change at 6e+06 x its tolerance";
  const Scene coulomb = steadyScene({"Capstans/capstan/Friction/Law=Coulomb"});
  const std::string hint = stickChatterHint(coulomb, stalled);
  EXPECT_NE(hint.find("Friction/Law = Tanh with Regularization 0.0005 "), std::string::npos) << hint;  // 1e-3 x 0.5 x 1
  EXPECT_NE(hint.find("capstan 'capstan'"), std::string::npos) << hint;
  EXPECT_EQ(stickChatterHint(coulomb, "newton failed (line search) in 60 iterations"), "");
  EXPECT_EQ(stickChatterHint(steadyScene({}), stalled), "");  // Tanh
  const Scene quasiStatic = parseScene(test::kRollerScene, "roller.xml", {"Capstans/capstan/Friction/Law=Coulomb"}, "");
  EXPECT_EQ(stickChatterHint(quasiStatic, stalled), hint);
}

}  // namespace

