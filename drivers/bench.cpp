// capstan_bench: kernel and assembly throughput on one core, against the core's
// measured floating-point peak (all figures from this one run, so their ratios
// hold whatever the machine's load).
//
//   capstan_bench [cells-per-side]     (default 20: 8000 bricks)
//
// Prints a markdown table:
//   - FMA peak: a loop of independent fused multiply-adds the compiler
//     vectorises (2 flops each), GFLOP/s;
//   - brick residual+tangent (each tangent handed to a sink that drops it: the
//     arithmetic, as the kernel runs inside the assembly but for the scatter)
//     and residual only, contact face and friction face
//     (Coulomb, sliding) kernels: evaluations/s, counted flops per evaluation,
//     GFLOP/s and fraction of the FMA peak;
//   - assembly: a plain global-index sumIntoGlobalValues loop (the element
//     matrices already computed) against capstan's assembly (kernels, each
//     tangent added at precomputed local offsets as it is formed, export),
//     elements/s;
//   - memory bandwidth (STREAM triad), rank 0 alone and all ranks at once:
//     under `mpiexec -n 2` the ratio bounds how much a second rank can speed
//     up the memory-bound sparse solves (docs/performance.md).
#include <Kokkos_Timer.hpp>
#include <Tpetra_Core.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <vector>

#include "assembly.hpp"
#include "heap_tunables.hpp"
#include "kernels/brick.hpp"
#include "kernels/contact.hpp"
#include "kernels/friction.hpp"

using namespace capstan;

namespace {

// Repeats f (which does `work` units per call) for at least `seconds`; units/s.
double rate(const std::function<void()>& f, double work, double seconds = 1.0) {
  f();  // warm up
  long reps = 0;
  Kokkos::Timer t;
  do {
    f();
    ++reps;
  } while (t.seconds() < seconds);
  return double(reps) * work / t.seconds();
}

// Peak: 12 independent accumulators of 8 doubles (one AVX-512 register each;
// enough to cover the FMA latency on both pipes), each updated by a fused
// multiply-add per iteration: flops/s = 2 x 96 x iterations / time.
typedef double Vec8 __attribute__((vector_size(64)));
__attribute__((noinline)) double fmaLoop(long iters, double m, double a) {
  Vec8 acc[12];
  for (int k = 0; k < 12; ++k)
    for (int j = 0; j < 8; ++j) acc[k][j] = 1.0 + k + 0.1 * j;
  const Vec8 vm = m - (Vec8){}, va = a - (Vec8){};
  for (long it = 0; it < iters; ++it)
#pragma GCC unroll 12
    for (int k = 0; k < 12; ++k) acc[k] = acc[k] * vm + va;
  double s = 0;
  for (int k = 0; k < 12; ++k)
    for (int j = 0; j < 8; ++j) s += acc[k][j];
  return s;
}

double fmaPeak() {
  const long iters = 10000000;
  double sink = 0;
  const double r = rate([&] { sink += fmaLoop(iters, 0.999999999, 1e-9); }, 2.0 * 96 * iters, 1.5);
  if (sink == 42.0) std::printf("(unlikely)\n");  // keeps the loop alive
  return r;
}

// Flops of brickResidualTangent counted from its loops (kernels/brick.hpp; a fused multiply-add is
// 2, checked with an operation-counting type): per Gauss point, per element and the tangent's
// products, term by term in docs/performance.md, "Kernels and assembly".
constexpr double kBrickFlopsResidual = 8 * (418 + 507) + 6;  // 7406
constexpr double kBrickFlopsTangent =
    kBrickFlopsResidual + 8 * 48 + 3072 + 18432 + 2 + 24 + 576 + 192;  // 30088
// Contact face, 2x2 Gauss, every point in contact (kernels/contact.hpp), per point:
//   area elements 2 x 60, shape 30, position 24, gap 30, traction 10,
//   residual 12 x 4, C 3x3 30, tangent 16 node pairs x 9 x 4  -> ~870
constexpr double kContactFlops = 4 * 870;

// STREAM triad a = b + s c over arrays far larger than the caches: bytes/s
// moved (3 x 8 bytes per entry), for `seconds` from a common start.
double triadBandwidth(long n, double seconds) {
  Kokkos::View<double*> a("a", n), b("b", n), c("c", n);
  Kokkos::deep_copy(b, 1.0), Kokkos::deep_copy(c, 2.0);
  return rate(
      [&] {
        Kokkos::parallel_for(
            "triad", Kokkos::RangePolicy<>(0, n), KOKKOS_LAMBDA(long i) { a(i) = b(i) + 1.5 * c(i); });
        Kokkos::fence();
      },
      24.0 * n, seconds);
}

}  // namespace

int main(int argc, char** argv) {
  capstan::reexecWithHeapTunables(argv);  // as capstan itself runs (src/heap_tunables.hpp)
  Tpetra::ScopeGuard scope(&argc, &argv);
  if (capstan::launchedByMpiexec()) capstan::setTcpNoDelay();  // finalize without 40 ms stalls (src/mpi_startup.hpp)
  const int n = argc > 1 ? std::atoi(argv[1]) : 20;
  auto comm = Tpetra::getDefaultComm();
  const double peak = fmaPeak();

  // ---- brick kernel on a deformed box
  Scene scene;
  scene.mesh.type = MeshSpec::Type::Box;
  scene.mesh.min = {0, 0, 0};
  scene.mesh.max = {1, 1, 1};
  scene.mesh.cells = {n, n, n};
  scene.solver = SolverSettings::defaults();
  scene.supports = {{"base", "ymin", SupportSpec::Type::Fixed, {true, true, true}, 0, {0, 0, 0}}};
  BoxGenerator gen(scene.mesh.min, scene.mesh.max, scene.mesh.cells);
  Mesh mesh = distributeMesh(gen, comm);
  Assembly assembly(mesh, scene);
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
  const double ne = double(mesh.numElements());
  // The kernel's arithmetic: each tangent goes to a sink that does nothing
  // with it (the assembly's sink adds it to the matrix: the assembly rows).
  const TangentSink drop;
  const double brickTangent = rate([&] { bricks.evaluate(x, ux, &drop); }, ne);
  const double brickResidual = rate([&] { bricks.evaluate(x, ux, nullptr); }, ne);

  // ---- face kernels on one face pressed into a capstan, every point in contact
  const double Xf[4][3] = {{0, 1, 0}, {0.5, 1, 0}, {0.5, 1, 0.5}, {0, 1, 0.5}};
  double xf[4][3], xn[4][3];
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) xf[a][i] = xn[a][i] = Xf[a][i] + (i == 1 ? -0.01 * a : 0.0);
  for (int a = 0; a < 4; ++a) xn[a][0] -= 0.02;  // the face moved 0.02 along x in the step
  kernels::Cylinder cyl{{0.25, 2.95, 0}, {0, 0, 1}, 2.0};
  const double lambda[kernels::kMaxFacePoints] = {};
  double R[12], K[144];
  kernels::ContactPoint cp[kernels::kMaxFacePoints];
  const int faces = 10000;
  double sink = 0;
  const double contact = rate(
      [&] {
        for (int f = 0; f < faces; ++f) {
          cyl.a[1] = 2.95 + 1e-9 * (f & 7);  // keeps the call from being hoisted
          kernels::contactFaceResidualTangent(Xf, xf, cyl, 1e-3, 1e-3, lambda, kernels::FaceRule::Gauss2, R, K, cp);
          sink += K[13];
        }
      },
      faces);
  kernels::FrictionParameters fp;
  fp.law = kernels::FrictionLaw::Coulomb;
  fp.mu = 0.5;
  fp.tangentPenalty = 1e-3;
  fp.spin = 0.1;
  const double history[3 * kernels::kMaxFacePoints] = {};
  kernels::FrictionPoint fpts[kernels::kMaxFacePoints];
  const double friction = rate(
      [&] {
        for (int f = 0; f < faces; ++f) {
          cyl.a[1] = 2.95 + 1e-9 * (f & 7);
          kernels::frictionFaceResidualTangent(Xf, xf, xn, cyl, 1e-3, 1e-3, lambda, kernels::FaceRule::Gauss2, fp,
                                               history, R, K, fpts);
          sink += K[13];
        }
      },
      faces);

  // ---- assembly: plain global-index insertion vs capstan's
  auto W = assembly.createMatrix();
  Vector f(mesh.ownedDofMap);
  assembly.evaluate(u, &f, W.get());
  const auto& L = bricks.local();
  auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.dofs);
  // The plain loop's element matrices: every brick's tangent kept.
  TangentSink keepAll;
  keepAll.keepSlot = Kokkos::View<int*>("every brick", mesh.numElements());
  keepAll.kept = decltype(keepAll.kept)("brick tangents", mesh.numElements(), 24, 24);
  {
    auto slot = keepAll.keepSlot;
    Kokkos::parallel_for(
        "slots", Kokkos::RangePolicy<>(0, slot.extent(0)), KOKKOS_LAMBDA(int e) { slot(e) = e; });
  }
  bricks.evaluate(x, ux, &keepAll);
  auto Kh = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), keepAll.kept);
  const auto& overlap = *mesh.overlapDofMap;
  std::vector<GO> gids(24);
  const double plainGlobal = rate(
      [&] {
        W->beginAssembly();
        W->setAllToScalar(0.0);
        for (size_t e = 0; e < dofs.extent(0); ++e) {
          for (int k = 0; k < 24; ++k) gids[k] = overlap.getGlobalElement(dofs(e, k));
          for (int k = 0; k < 24; ++k)
            W->sumIntoGlobalValues(gids[k], Teuchos::ArrayView<const GO>(gids),
                                   Teuchos::ArrayView<const double>(&Kh(e, k, 0), 24));
        }
        W->endAssembly();
      },
      ne);
  const double ours = rate([&] { assembly.evaluate(u, &f, W.get()); }, ne);
  const double oursResidual = rate([&] { assembly.evaluate(u, &f, nullptr); }, ne);
  const double oursTangent = rate([&] { assembly.evaluate(u, nullptr, W.get()); }, ne);

  // ---- memory bandwidth: rank 0 alone (the others wait), then all at once
  const long streamLength = 20000000;  // 3 x 160 MB per rank
  double alone = 0, together = 0;
  comm->barrier();
  if (comm->getRank() == 0) alone = triadBandwidth(streamLength, 1.0);
  comm->barrier();
  const double mine = triadBandwidth(streamLength, 1.0);
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_SUM, mine, Teuchos::outArg(together));

  if (comm->getRank() == 0) {
    auto row = [&](const char* what, double evals, double flops) {
      std::printf("| %s | %.3e | %.0f | %.2f | %.1f%% |\n", what, evals, flops, evals * flops * 1e-9,
                  100 * evals * flops / peak);
    };
    std::printf("bricks: %.0f on this rank (%d^3 box); FMA peak of this core: %.1f GFLOP/s; huge pages: %s\n\n", ne, n,
                peak * 1e-9, capstan::hugePagesRequested() ? "on" : "off");
    std::printf("| kernel | evaluations/s | flops/evaluation | GFLOP/s | of peak |\n|---|---|---|---|---|\n");
    row("brick residual + tangent", brickTangent, kBrickFlopsTangent);
    row("brick residual only", brickResidual, kBrickFlopsResidual);
    row("contact face, 2x2 Gauss, in contact", contact, kContactFlops);
    std::printf("| friction face, Coulomb sliding, 2x2 Gauss | %.3e | | | |\n\n", friction);
    std::printf("| assembly of residual + tangent | elements/s | ratio |\n|---|---|---|\n");
    std::printf("| plain sumIntoGlobalValues loop (insertion only) | %.3e | 1 |\n", plainGlobal);
    std::printf("| capstan (kernels + local scatter + export) | %.3e | %.1f |\n", ours, ours / plainGlobal);
    std::printf("| capstan, residual only | %.3e | %.1f |\n", oursResidual, oursResidual / plainGlobal);
    std::printf("| capstan, tangent only | %.3e | %.1f |\n\n", oursTangent, oursTangent / plainGlobal);
    std::printf("| memory bandwidth (triad) | GB/s | ratio |\n|---|---|---|\n");
    std::printf("| rank 0 alone | %.1f | 1 |\n", alone * 1e-9);
    std::printf("| all %d ranks at once (sum) | %.1f | %.2f |\n", comm->getSize(), together * 1e-9, together / alone);
    if (sink == 42.0) std::printf("(unlikely)\n");
  }
  return 0;
}
