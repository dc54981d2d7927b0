// Mesh generators: the annulus (pinch-roller coating) is a closed ring of
// bricks with positive Jacobians, the right volume, outward-facing boundary
// faces and a symmetric dual graph; it distributes like the box. Both
// partitions (METIS, slabs) put their cuts where they should and count them.
#include <gtest/gtest.h>

#include <Teuchos_CommHelpers.hpp>
#include <Tpetra_Core.hpp>

#include <algorithm>
#include <cmath>
#include <set>

#include "kernels/hex_shape.hpp"
#include "mesh.hpp"

using namespace capstan;

namespace {

std::array<double, 3> sub(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
std::array<double, 3> cross(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// Sum of all bricks' volumes (2x2x2 Gauss); fails the test if any Gauss point
// has det J <= 0.
double checkedVolume(const MeshGenerator& gen) {
  double volume = 0;
  for (GO e = 0; e < gen.numElements(); ++e) {
    double X[8][3];
    const auto nodes = gen.elementNodes(e);
    for (int a = 0; a < 8; ++a) {
      const auto x = gen.nodeCoordinates(nodes[a]);
      for (int i = 0; i < 3; ++i) X[a][i] = x[i];
    }
    for (int q = 0; q < 8; ++q) {
      double D[8][3];
      const double det = kernels::hexReferenceGradients(X, kernels::gauss2(q & 1), kernels::gauss2((q >> 1) & 1),
                                                        kernels::gauss2(q >> 2), D);
      EXPECT_GT(det, 0) << "element " << e;
      volume += det;
    }
  }
  return volume;
}

}  // namespace

TEST(Annulus, BricksVolumeFacesAndNeighbours) {
  const std::array<double, 3> c{1.0, -2.0, 0.5};
  const double ri = 4.25, ro = 6.25, length = 3.0;
  const std::array<int, 3> cells{3, 24, 2};
  AnnulusGenerator gen(c, ri, ro, length, cells);
  ASSERT_EQ(gen.numElements(), 3 * 24 * 2);
  ASSERT_EQ(gen.numNodes(), 4 * 24 * 3);

  // Every Gauss point has det J > 0, and the volumes add up to the polygonal
  // annulus (the bricks' straight edges): n/2 sin(2 pi/n) (ro^2 - ri^2) L.
  const double volume = checkedVolume(gen);
  const double n = cells[1];
  EXPECT_NEAR(volume, 0.5 * n * std::sin(2 * M_PI / n) * (ro * ro - ri * ri) * length, 1e-10 * volume);

  // Boundary faces: counts, and normals pointing out of the ring.
  std::map<std::string, int> count;
  for (GO e = 0; e < gen.numElements(); ++e)
    for (const auto& f : gen.boundaryFaces(e)) {
      ++count[f.name];
      std::array<std::array<double, 3>, 4> p;
      for (int a = 0; a < 4; ++a) p[a] = gen.nodeCoordinates(f.nodes[a]);
      const auto normal = cross(sub(p[1], p[0]), sub(p[3], p[0]));
      std::array<double, 3> mid{0, 0, 0};
      for (int a = 0; a < 4; ++a)
        for (int i = 0; i < 3; ++i) mid[i] += 0.25 * p[a][i];
      const double rx = mid[0] - c[0], ry = mid[1] - c[1];
      const double radial = (normal[0] * rx + normal[1] * ry) / std::hypot(rx, ry);
      if (f.name == "inner") {
        EXPECT_LT(radial, 0);
        EXPECT_NEAR(std::hypot(p[0][0] - c[0], p[0][1] - c[1]), ri, 1e-12);
      } else if (f.name == "outer") {
        EXPECT_GT(radial, 0);
        EXPECT_NEAR(std::hypot(p[0][0] - c[0], p[0][1] - c[1]), ro, 1e-12);
      } else if (f.name == "zmin") {
        EXPECT_LT(normal[2], 0);
        EXPECT_NEAR(mid[2], c[2], 1e-12);
      } else {
        ASSERT_EQ(f.name, "zmax");
        EXPECT_GT(normal[2], 0);
        EXPECT_NEAR(mid[2], c[2] + length, 1e-12);
      }
    }
  EXPECT_EQ(count["inner"], 24 * 2);
  EXPECT_EQ(count["outer"], 24 * 2);
  EXPECT_EQ(count["zmin"], 3 * 24);
  EXPECT_EQ(count["zmax"], 3 * 24);

  // The dual graph is symmetric, closed around the circumference, and two
  // neighbours share exactly 4 nodes (a face).
  for (GO e = 0; e < gen.numElements(); ++e) {
    const auto nb = gen.faceNeighbours(e);
    const auto ne = gen.elementNodes(e);
    for (GO m : nb) {
      const auto back = gen.faceNeighbours(m);
      EXPECT_NE(std::find(back.begin(), back.end(), e), back.end()) << e << " -> " << m;
      const auto nm = gen.elementNodes(m);
      int shared = 0;
      for (GO a : ne) shared += std::count(nm.begin(), nm.end(), a);
      EXPECT_EQ(shared, 4) << e << " and " << m;
    }
  }
  // Element (0, 23, 0) and (0, 0, 0) are neighbours across the angle 0.
  const auto last = gen.faceNeighbours(23 * 3);
  EXPECT_NE(std::find(last.begin(), last.end(), 0), last.end());
}

// Graded: radial thicknesses in geometric progression to the outer-cell ratio,
// and the fine sector holding its share of the circumferential cells; still a
// valid ring (positive Jacobians, the polygonal volume).
TEST(Annulus, Grading) {
  const double ri = 1.0, ro = 3.0, length = 0.5;
  AnnulusGenerator gen({0, 0, 0}, ri, ro, length, {5, 40, 1}, 0.2, {-90, 30, 0.5});
  std::vector<double> r(6);
  for (int i = 0; i <= 5; ++i) r[i] = gen.nodeCoordinates(i)[0];  // j = 0, k = 0: along the start angle
  const double c0 = std::cos(std::atan2(gen.nodeCoordinates(0)[1], gen.nodeCoordinates(0)[0]));
  for (double& x : r) x /= c0;
  EXPECT_NEAR(r[0], ri, 1e-12);
  EXPECT_NEAR(r[5], ro, 1e-12);
  EXPECT_NEAR((r[5] - r[4]) / (r[1] - r[0]), 0.2, 1e-12);
  for (int i = 1; i < 4; ++i) EXPECT_NEAR((r[i + 1] - r[i]) / (r[i] - r[i - 1]), std::pow(0.2, 0.25), 1e-12);
  // 20 of the 40 cells lie within -90 +- 15 degrees.
  int inSector = 0;
  double area = 0;
  for (GO j = 0; j < 40; ++j) {
    const auto a = gen.nodeCoordinates(6 * j), b = gen.nodeCoordinates(6 * ((j + 1) % 40));
    const double ta = std::atan2(a[1], a[0]), tb = std::atan2(b[1], b[0]);
    double mid = std::atan2(std::sin(ta) + std::sin(tb), std::cos(ta) + std::cos(tb)) * 180 / M_PI;
    if (std::fabs(mid + 90) < 15) ++inSector;
    double dt = tb - ta;
    if (dt < 0) dt += 2 * M_PI;
    area += 0.5 * std::sin(dt) * (ro * ro - ri * ri);
  }
  EXPECT_EQ(inSector, 20);
  const double volume = checkedVolume(gen);
  EXPECT_NEAR(volume, area * length, 1e-10 * volume);
}

TEST(Annulus, DistributesWithFaces) {
  AnnulusGenerator gen({0, 0, 0}, 1.0, 2.0, 1.0, {2, 12, 2});
  const Mesh mesh = distributeMesh(gen, Tpetra::getDefaultComm());
  EXPECT_EQ(mesh.numGlobalElements, 2 * 12 * 2);
  EXPECT_EQ(mesh.numGlobalNodes, 3 * 12 * 3);
  EXPECT_EQ(mesh.faces.count("inner"), 1u);
  EXPECT_EQ(mesh.faces.at("inner").size() % 4, 0u);
  // Inner-face nodes all lie on the inner radius.
  for (int n : mesh.faceNodes("inner"))
    EXPECT_NEAR(std::hypot(mesh.X[3 * n], mesh.X[3 * n + 1]), 1.0, 1e-12);
}

// ---------------------------------------------------------------- partitions
namespace {

// Faces between this rank's elements and other ranks', summed over ranks and
// halved: an independent count of the faces the partition cuts.
GO countCutFaces(const MeshGenerator& gen, const Mesh& mesh) {
  const std::set<GO> mine(mesh.elementGids.begin(), mesh.elementGids.end());
  long long local = 0, global = 0;
  for (GO e : mesh.elementGids)
    for (GO nb : gen.faceNeighbours(e))
      if (!mine.count(nb)) ++local;
  Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_SUM, local, Teuchos::outArg(global));
  return GO(global / 2);
}

}  // namespace

TEST(Partition, MetisCutsFewFacesAndCountsThem) {
  BoxGenerator gen({0, 0, 0}, {6, 2, 4}, {12, 4, 8});
  const Mesh mesh = distributeMesh(gen, Tpetra::getDefaultComm(), Partition::Metis);
  const int ranks = mesh.comm->getSize();
  EXPECT_EQ(mesh.numCutFaces, countCutFaces(gen, mesh));
  if (ranks == 1) {
    EXPECT_EQ(mesh.numCutFaces, 0);
  }
  // Two ranks: no worse than the best plane (across x: 4 x 8 faces) by much.
  if (ranks == 2) {
    EXPECT_LE(mesh.numCutFaces, 2 * 4 * 8);
  }
}

// Auto picks slabs only where each rank's slab is kAutoSlabLayers (16) cells
// thick or more, and only on several ranks; the mesh records what it used.
TEST(Partition, AutoPicksThickSlabsOnly) {
  EXPECT_EQ(autoPartition(48, 2), Partition::Slabs);  // G1 8x: 24 layers a rank
  EXPECT_EQ(autoPartition(32, 2), Partition::Slabs);
  EXPECT_EQ(autoPartition(31, 2), Partition::Metis);
  EXPECT_EQ(autoPartition(24, 2), Partition::Metis);  // G1 4x: 12
  EXPECT_EQ(autoPartition(8, 2), Partition::Metis);   // H1 8x: 4
  EXPECT_EQ(autoPartition(48, 1), Partition::Metis);  // one rank: nothing to split
  EXPECT_EQ(autoPartition(64, 4), Partition::Slabs);
  EXPECT_EQ(autoPartition(60, 4), Partition::Metis);
  EXPECT_EQ(partitionFor("Auto", 48, 2), Partition::Slabs);
  EXPECT_EQ(partitionFor("Auto", 24, 2), Partition::Metis);
  EXPECT_EQ(partitionFor("METIS", 48, 2), Partition::Metis);
  EXPECT_EQ(partitionFor("Slabs", 8, 2), Partition::Slabs);
  EXPECT_THROW(partitionFor("slabs", 48, 2), std::logic_error);
  EXPECT_STREQ(partitionName(Partition::Slabs), "Slabs");
  EXPECT_STREQ(partitionName(Partition::Metis), "METIS");
  BoxGenerator gen({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  EXPECT_EQ(distributeMesh(gen, Tpetra::getDefaultComm(), Partition::Slabs).partition, Partition::Slabs);
  EXPECT_EQ(distributeMesh(gen, Tpetra::getDefaultComm(), Partition::Metis).partition, Partition::Metis);
}

TEST(Partition, BoxSlabsAreRunsAcrossZ) {
  const int nx = 6, ny = 4, nz = 8;
  BoxGenerator gen({0, 0, 0}, {3, 2, 4}, {nx, ny, nz});
  const Mesh mesh = distributeMesh(gen, Tpetra::getDefaultComm(), Partition::Slabs);
  const int ranks = mesh.comm->getSize(), rank = mesh.comm->getRank();
  const GO ne = GO(nx) * ny * nz;
  // This rank holds the run [rank ne / ranks, (rank + 1) ne / ranks).
  ASSERT_EQ(GO(mesh.elementGids.size()), (rank + 1) * ne / ranks - rank * ne / ranks);
  for (size_t i = 0; i < mesh.elementGids.size(); ++i) EXPECT_EQ(mesh.elementGids[i], rank * ne / ranks + GO(i));
  // 8 layers over 1 or 2 ranks: every slab is whole layers, z in [z0, z0 + 4 / ranks].
  const double z0 = 4.0 * rank / ranks, z1 = 4.0 * (rank + 1) / ranks;
  for (size_t n = 0; n < mesh.numOverlapNodes(); ++n) {
    EXPECT_GE(mesh.X[3 * n + 2], z0 - 1e-12);
    EXPECT_LE(mesh.X[3 * n + 2], z1 + 1e-12);
  }
  // Each plane between slabs cuts nx x ny faces.
  EXPECT_EQ(mesh.numCutFaces, GO(ranks - 1) * nx * ny);
  EXPECT_EQ(mesh.numCutFaces, countCutFaces(gen, mesh));
  // Every node is owned once.
  long long owned = long(mesh.numOwnedNodes), total = 0;
  Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_SUM, owned, Teuchos::outArg(total));
  EXPECT_EQ(total, (nx + 1) * (ny + 1) * (nz + 1));
}

TEST(Partition, AnnulusSlabsAreRunsAlongTheAxis) {
  const double length = 2.0;
  AnnulusGenerator gen({0, 0, 0}, 1.0, 2.0, length, {2, 12, 4});
  const Mesh mesh = distributeMesh(gen, Tpetra::getDefaultComm(), Partition::Slabs);
  const int ranks = mesh.comm->getSize(), rank = mesh.comm->getRank();
  const double z0 = length * rank / ranks, z1 = length * (rank + 1) / ranks;
  for (size_t n = 0; n < mesh.numOverlapNodes(); ++n) {
    EXPECT_GE(mesh.X[3 * n + 2], z0 - 1e-12);
    EXPECT_LE(mesh.X[3 * n + 2], z1 + 1e-12);
  }
  // The cut is one ring of 2 x 12 faces per plane between slabs.
  EXPECT_EQ(mesh.numCutFaces, GO(ranks - 1) * 2 * 12);
  EXPECT_EQ(mesh.numCutFaces, countCutFaces(gen, mesh));
}
