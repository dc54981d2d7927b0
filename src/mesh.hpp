// The body's mesh as one rank sees it, and the generators that build it.
//
// A generator answers questions about single elements by global id (its nodes,
// their coordinates, its boundary faces), so each rank builds only its own part:
// the whole mesh never lives on one rank. Rank 0 partitions the element dual
// graph with METIS (the graph only: about 7 integers per element).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "types.hpp"

namespace capstan {

// A boundary face of an element: 4 node ids, counter-clockwise seen from outside.
struct BoundaryFace {
  std::string name;
  std::array<GO, 4> nodes;
};

class MeshGenerator {
 public:
  virtual ~MeshGenerator() = default;
  virtual GO numElements() const = 0;
  virtual GO numNodes() const = 0;
  virtual std::vector<std::string> faceNames() const = 0;
  virtual std::array<GO, 8> elementNodes(GO element) const = 0;
  virtual std::array<double, 3> nodeCoordinates(GO node) const = 0;
  virtual std::vector<BoundaryFace> boundaryFaces(GO element) const = 0;
  // Elements sharing a face with `element` (the dual graph).
  virtual std::vector<GO> faceNeighbours(GO element) const = 0;
  // The node next to `node` on its ring about the mesh's axis, one cell on
  // (step +1) or back (-1), or -1 where the mesh has no rings (steady rolling's
  // streamlines, formulation.md §8).
  virtual GO ringNeighbour(GO /*node*/, int /*step*/) const { return -1; }
};

// How elements are split over the ranks: Metis (k-way on the dual graph, any mesh) or Slabs (equal
// runs of element ids: slabs across the slowest index, so each rank's nodes run as on one rank and
// MueLu aggregates nearly as there; docs/performance.md, "Partitions").
enum class Partition { Metis, Slabs };

// Mesh/Partition = Auto: Slabs on several ranks where each rank's slab is at
// least kAutoSlabLayers cells thick along the slowest index, METIS otherwise.
// Thick slabs keep MueLu's aggregates as on one rank; thin ones leave the
// ranks unequal (docs/performance.md, "Defaults and why" and "Partitions").
constexpr int kAutoSlabLayers = 16;
Partition autoPartition(int slowestCells, int ranks);
// Mesh/Partition's value: "METIS", "Slabs", or "Auto" (autoPartition), and back;
// any other name is a logic error (the scene reader rejects it with a message).
Partition partitionFor(const std::string& name, int slowestCells, int ranks);
const char* partitionName(Partition partition);

// Structured box: Cells = {nx, ny, nz} bricks over [Min, Max]; faces xmin..zmax.
class BoxGenerator : public MeshGenerator {
 public:
  BoxGenerator(std::array<double, 3> min, std::array<double, 3> max, std::array<int, 3> cells);
  GO numElements() const override;
  GO numNodes() const override;
  std::vector<std::string> faceNames() const override;
  std::array<GO, 8> elementNodes(GO element) const override;
  std::array<double, 3> nodeCoordinates(GO node) const override;
  std::vector<BoundaryFace> boundaryFaces(GO element) const override;
  std::vector<GO> faceNeighbours(GO element) const override;

 private:
  std::array<double, 3> min_, max_;
  std::array<GO, 3> n_;
  std::array<GO, 3> ijk(GO element) const;
};

// Hollow cylinder (a pinch roller's coating) along +z from Center, its zmin axis point: cells
// {radial, circumferential, axial}, right-handed, closed around; faces inner, outer, zmin, zmax.
// Graded for the nip: outerCellRatio (< 1: thin outside); sector {centre, width (deg), fraction}.
class AnnulusGenerator : public MeshGenerator {
 public:
  AnnulusGenerator(std::array<double, 3> center, double innerRadius, double outerRadius, double length,
                   std::array<int, 3> cells, double outerCellRatio = 1,
                   std::array<double, 3> sector = {0, 0, 0});
  GO numElements() const override;
  GO numNodes() const override;
  std::vector<std::string> faceNames() const override;
  std::array<GO, 8> elementNodes(GO element) const override;
  std::array<double, 3> nodeCoordinates(GO node) const override;
  std::vector<BoundaryFace> boundaryFaces(GO element) const override;
  std::vector<GO> faceNeighbours(GO element) const override;
  GO ringNeighbour(GO node, int step) const override;
  // The nt ring angles (radians, increasing from the first): uniform, or
  // sectorCells() cells over the sector {centre, width (degrees), fraction}
  // and the rest over the remainder.
  static std::vector<double> ringAngles(int nt, std::array<double, 3> sector);
  static int sectorCells(int nt, const std::array<double, 3>& sector) {
    return sector[1] > 0 ? std::clamp(int(std::lround(sector[2] * nt)), 1, nt - 1) : 0;
  }
  // The widest and the narrowest ring cell, in degrees (the scene's checks; no allocation).
  static double widestRingCellDegrees(int nt, const std::array<double, 3>& sector) {
    const int m = sectorCells(nt, sector);
    return m == 0 ? 360.0 / nt : std::max(sector[1] / m, (360 - sector[1]) / (nt - m));
  }
  static double narrowestRingCellDegrees(int nt, const std::array<double, 3>& sector) {
    const int m = sectorCells(nt, sector);
    return m == 0 ? 360.0 / nt : std::min(sector[1] / m, (360 - sector[1]) / (nt - m));
  }

 private:
  std::array<double, 3> center_;
  double length_;
  std::array<GO, 3> n_;  // radial, circumferential, axial cells
  std::vector<double> radius_, angle_;  // node radii (n_[0] + 1) and angles (n_[1])
  std::array<GO, 3> ijk(GO element) const;
  GO node(GO i, GO j, GO k) const;  // j taken modulo the circumferential count
};

// This rank's part of the body. Node numbering is "overlapped": the nodes this
// rank owns come first (in owned-map order), then the ghost nodes it shares.
struct Mesh {
  RCP<const Comm> comm;
  GO numGlobalNodes = 0, numGlobalElements = 0;
  std::vector<std::string> faceNames;

  std::vector<GO> nodeGids;          // overlapped order
  size_t numOwnedNodes = 0;
  std::vector<double> X;             // 3 per overlapped node: reference coordinates
  std::vector<GO> elementGids;       // every element lives on exactly one rank
  GO numCutFaces = 0;                // element faces between two ranks (all ranks)
  Partition partition = Partition::Metis;  // how the elements were split
  std::vector<int> connectivity;     // 8 overlapped node ids per element
  std::map<std::string, std::vector<int>> faces;  // 4 overlapped node ids per quad
  // Per overlapped node on a streamline face (distributeMesh): its ring
  // neighbours two and one cells back, one and two cells on (overlapped ids;
  // kRingSteps), else -1. Those neighbours are ghosts of this rank even where
  // none of its elements holds them.
  static constexpr int kRingSteps[4] = {-2, -1, 1, 2};
  std::vector<std::array<int, 4>> ringNeighbours;

  RCP<const Map> ownedNodeMap, overlapNodeMap, ownedDofMap, overlapDofMap;

  size_t numElements() const { return elementGids.size(); }
  size_t numOverlapNodes() const { return nodeGids.size(); }
  // Overlapped node ids (sorted, unique) on a named face of this rank's elements.
  std::vector<int> faceNodes(const std::string& face) const;
};

// Partitions the generator's elements over comm and builds this rank's part.
// streamlineFaces: faces whose nodes need their ring neighbours (steady rolling).
Mesh distributeMesh(const MeshGenerator& generator, const RCP<const Comm>& comm,
                    Partition partition = Partition::Metis, const std::vector<std::string>& streamlineFaces = {});

}  // namespace capstan
