// The distributed assembly equals a serial one: on every rank, the same box is
// also assembled alone (a one-rank communicator), and the residual and tangent
// action agree dof by dof. Run on 1 and 2 ranks.
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_XMLParameterListHelpers.hpp>
#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "assembly.hpp"
#include "errors.hpp"

using namespace capstan;

namespace {

Scene boxScene() {
  Scene s;
  s.mesh = {"Box", {0, 0, 0}, {2, 1, 1.5}, {4, 2, 3}};
  s.c = 1.3;
  s.pressurePenalty = 1e-2;
  s.solver = validParameters().sublist("Solver");
  SupportSpec fixed{"base", "ymin", "Fixed", {true, true, true}, 0, {0, 0, 0}};
  SupportSpec roll{"side", "xmin", "Roller", {true, false, false}, 0, {0, 0, 0}};
  SupportSpec spring{"spring", "zmax", "Foundation", {false, true, true}, 0.7, {0, 0, 0}};
  s.supports = {fixed, roll, spring};
  return s;
}

// A smooth displacement field (zero on ymin and x = 0 on xmin).
double field(const double* X, int i) {
  return 0.05 * X[1] * (i + 1) * std::sin(X[0] + 0.3 * i) * (1 + 0.2 * X[2]) +
         (i == 0 ? 0.0 : 0.0);
}

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

}  // namespace
