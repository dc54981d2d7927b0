// capstan_bench: kernel throughput on one core.
//
//   capstan_bench [cells-per-side]     (default 20: 8000 bricks)
//
// Prints brick residual+tangent and residual-only evaluations per second, and
// the assembly (scatter into Tpetra) time per Newton iteration for the same box.
#include <Kokkos_Timer.hpp>
#include <Tpetra_Core.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "assembly.hpp"

using namespace capstan;

int main(int argc, char** argv) {
  Tpetra::ScopeGuard scope(&argc, &argv);
  const int n = argc > 1 ? std::atoi(argv[1]) : 20;
  auto comm = Tpetra::getDefaultComm();
  Scene scene;
  scene.mesh = {"Box", {0, 0, 0}, {1, 1, 1}, {n, n, n}};
  scene.solver = validParameters().sublist("Solver");
  scene.supports = {{"base", "ymin", "Fixed", {true, true, true}, 0, {0, 0, 0}}};
  BoxGenerator gen(scene.mesh.min, scene.mesh.max, scene.mesh.cells);
  Mesh mesh = distributeMesh(gen, comm);
  Assembly assembly(mesh, scene);
  // A smooth non-trivial deformation.
  Vector u(mesh.ownedDofMap);
  {
    auto d = u.getDataNonConst();
    for (size_t k = 0; k < mesh.numOwnedNodes; ++k) {
      const double* X = &mesh.X[3 * k];
      d[3 * k] = 0.1 * X[1] * X[1];
      d[3 * k + 1] = -0.05 * X[1] + 0.02 * std::sin(3 * X[0]);
      d[3 * k + 2] = 0.03 * X[0] * X[2];
    }
  }
  assembly.evaluate(u, nullptr, nullptr);  // fills positions
  auto& bricks = assembly.bricks();
  const auto& x = assembly.positions();
  const auto& ux = assembly.displacements();
  const long ne = long(mesh.numElements());
  auto run = [&](bool tangent) {
    int reps = 0;
    Kokkos::Timer t;
    do {
      bricks.evaluate(x, ux, tangent);
      ++reps;
    } while (t.seconds() < 2.0);
    return double(reps) * double(ne) / t.seconds();
  };
  const double withTangent = run(true), residualOnly = run(false);
  auto W = assembly.createMatrix();
  Vector f(mesh.ownedDofMap);
  const double before = assembly.assemblySeconds();
  int reps = 0;
  Kokkos::Timer t;
  do {
    assembly.evaluate(u, &f, W.get());
    ++reps;
  } while (t.seconds() < 2.0);
  const double perAssembly = (assembly.assemblySeconds() - before) / reps;
  if (comm->getRank() == 0) {
    std::printf("bricks: %ld on this rank (%d^3 box)\n", ne, n);
    std::printf("brick residual+tangent: %.3e evaluations/s\n", withTangent);
    std::printf("brick residual only:    %.3e evaluations/s\n", residualOnly);
    std::printf("full assembly (kernels + scatter + export, residual and tangent): %.4f s\n", perAssembly);
    std::printf("  of which brick kernel: %.4f s\n", double(ne) / withTangent);
  }
  return 0;
}
