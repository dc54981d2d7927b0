#include "mesh.hpp"

#include <metis.h>
#include <mpi.h>

#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Map.hpp>

#include <algorithm>
#include <set>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

namespace capstan {

// ---------------------------------------------------------------- box generator

BoxGenerator::BoxGenerator(std::array<double, 3> min, std::array<double, 3> max,
                           std::array<int, 3> cells)
    : min_(min), max_(max), n_{cells[0], cells[1], cells[2]} {}

GO BoxGenerator::numElements() const { return n_[0] * n_[1] * n_[2]; }
GO BoxGenerator::numNodes() const { return (n_[0] + 1) * (n_[1] + 1) * (n_[2] + 1); }

std::vector<std::string> BoxGenerator::faceNames() const {
  return {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
}

std::array<GO, 3> BoxGenerator::ijk(GO e) const {
  return {e % n_[0], (e / n_[0]) % n_[1], e / (n_[0] * n_[1])};
}

std::array<GO, 8> BoxGenerator::elementNodes(GO e) const {
  const auto [i, j, k] = ijk(e);
  const GO sx = n_[0] + 1, sy = n_[1] + 1;
  auto node = [&](GO a, GO b, GO c) { return a + sx * (b + sy * c); };
  return {node(i, j, k),         node(i + 1, j, k),         node(i + 1, j + 1, k),
          node(i, j + 1, k),     node(i, j, k + 1),         node(i + 1, j, k + 1),
          node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)};
}

std::array<double, 3> BoxGenerator::nodeCoordinates(GO node) const {
  const GO sx = n_[0] + 1, sy = n_[1] + 1;
  const GO idx[3] = {node % sx, (node / sx) % sy, node / (sx * sy)};
  std::array<double, 3> X;
  for (int d = 0; d < 3; ++d)
    X[d] = idx[d] == n_[d] ? max_[d] : min_[d] + (max_[d] - min_[d]) * double(idx[d]) / double(n_[d]);
  return X;
}

std::vector<BoundaryFace> BoxGenerator::boundaryFaces(GO e) const {
  const auto [i, j, k] = ijk(e);
  const auto n = elementNodes(e);
  std::vector<BoundaryFace> f;
  // Local node lists ordered so that the normal points out of the box.
  if (i == 0) f.push_back({"xmin", {n[0], n[4], n[7], n[3]}});
  if (i == n_[0] - 1) f.push_back({"xmax", {n[1], n[2], n[6], n[5]}});
  if (j == 0) f.push_back({"ymin", {n[0], n[1], n[5], n[4]}});
  if (j == n_[1] - 1) f.push_back({"ymax", {n[3], n[7], n[6], n[2]}});
  if (k == 0) f.push_back({"zmin", {n[0], n[3], n[2], n[1]}});
  if (k == n_[2] - 1) f.push_back({"zmax", {n[4], n[5], n[6], n[7]}});
  return f;
}

std::vector<GO> BoxGenerator::faceNeighbours(GO e) const {
  const auto c = ijk(e);
  std::vector<GO> nb;
  for (int d = 0; d < 3; ++d)
    for (int s : {-1, 1}) {
      auto m = c;
      m[d] += s;
      if (m[d] < 0 || m[d] >= n_[d]) continue;
      nb.push_back(m[0] + n_[0] * (m[1] + n_[1] * m[2]));
    }
  return nb;
}

// ---------------------------------------------------------------- annulus generator

AnnulusGenerator::AnnulusGenerator(std::array<double, 3> center, double innerRadius, double outerRadius,
                                   double length, std::array<int, 3> cells, double outerCellRatio,
                                   std::array<double, 3> sector)
    : center_(center), length_(length), n_{cells[0], cells[1], cells[2]} {
  // Radii: thicknesses t_k = t_0 q^k, q^(n-1) = outerCellRatio, summing to the wall.
  const int nr = cells[0];
  const double q = nr > 1 ? std::pow(outerCellRatio, 1.0 / (nr - 1)) : 1.0;
  double sum = 0;
  for (int k = 0; k < nr; ++k) sum += std::pow(q, k);
  radius_.assign(nr + 1, innerRadius);
  for (int k = 0; k < nr; ++k) radius_[k + 1] = radius_[k] + (outerRadius - innerRadius) * std::pow(q, k) / sum;
  radius_[nr] = outerRadius;
  angle_ = ringAngles(cells[1], sector);
}

std::vector<double> AnnulusGenerator::ringAngles(int nt, std::array<double, 3> sector) {
  const double width = sector[1] * M_PI / 180;
  const int m = sectorCells(nt, sector);
  std::vector<double> angle(nt);
  const double start = m ? sector[0] * M_PI / 180 - width / 2 : 0.0;
  for (int j = 0; j < nt; ++j)
    angle[j] = m == 0 ? 2 * M_PI * j / nt
               : j <= m ? start + width * j / m
                        : start + width + (2 * M_PI - width) * (j - m) / (nt - m);
  return angle;
}

GO AnnulusGenerator::numElements() const { return n_[0] * n_[1] * n_[2]; }
GO AnnulusGenerator::numNodes() const { return (n_[0] + 1) * n_[1] * (n_[2] + 1); }

std::vector<std::string> AnnulusGenerator::faceNames() const { return {"inner", "outer", "zmin", "zmax"}; }

std::array<GO, 3> AnnulusGenerator::ijk(GO e) const {
  return {e % n_[0], (e / n_[0]) % n_[1], e / (n_[0] * n_[1])};
}

GO AnnulusGenerator::node(GO i, GO j, GO k) const {
  return i + (n_[0] + 1) * ((j % n_[1]) + n_[1] * k);
}

std::array<GO, 8> AnnulusGenerator::elementNodes(GO e) const {
  const auto [i, j, k] = ijk(e);
  return {node(i, j, k),         node(i + 1, j, k),         node(i + 1, j + 1, k),
          node(i, j + 1, k),     node(i, j, k + 1),         node(i + 1, j, k + 1),
          node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)};
}

std::array<double, 3> AnnulusGenerator::nodeCoordinates(GO n) const {
  const GO sr = n_[0] + 1;
  const GO i = n % sr, j = (n / sr) % n_[1], k = n / (sr * n_[1]);
  const double r = radius_[i], theta = angle_[j];
  const double z = k == n_[2] ? length_ : length_ * double(k) / double(n_[2]);
  return {center_[0] + r * std::cos(theta), center_[1] + r * std::sin(theta), center_[2] + z};
}

std::vector<BoundaryFace> AnnulusGenerator::boundaryFaces(GO e) const {
  const auto [i, j, k] = ijk(e);
  const auto n = elementNodes(e);
  std::vector<BoundaryFace> f;
  // As the box's xmin, xmax, zmin, zmax: (radial, circumferential, axial) plays (x, y, z).
  if (i == 0) f.push_back({"inner", {n[0], n[4], n[7], n[3]}});
  if (i == n_[0] - 1) f.push_back({"outer", {n[1], n[2], n[6], n[5]}});
  if (k == 0) f.push_back({"zmin", {n[0], n[3], n[2], n[1]}});
  if (k == n_[2] - 1) f.push_back({"zmax", {n[4], n[5], n[6], n[7]}});
  return f;
}

std::vector<GO> AnnulusGenerator::faceNeighbours(GO e) const {
  const auto [i, j, k] = ijk(e);
  auto id = [&](GO a, GO b, GO c) { return a + n_[0] * (((b + n_[1]) % n_[1]) + n_[1] * c); };
  std::vector<GO> nb;
  if (i > 0) nb.push_back(id(i - 1, j, k));
  if (i < n_[0] - 1) nb.push_back(id(i + 1, j, k));
  nb.push_back(id(i, j - 1, k));  // closed around the circumference
  if (n_[1] > 2) nb.push_back(id(i, j + 1, k));
  if (k > 0) nb.push_back(id(i, j, k - 1));
  if (k < n_[2] - 1) nb.push_back(id(i, j, k + 1));
  return nb;
}

GO AnnulusGenerator::ringNeighbour(GO n, int step) const {
  const GO sr = n_[0] + 1;
  const GO i = n % sr, j = (n / sr) % n_[1], k = n / (sr * n_[1]);
  return node(i, j + n_[1] + step, k);
}

// ---------------------------------------------------------------- distribution

namespace {

MPI_Comm rawComm(const RCP<const Comm>& comm) {
  auto mpi = Teuchos::rcp_dynamic_cast<const Teuchos::MpiComm<int>>(comm);
  return mpi.is_null() ? MPI_COMM_SELF : (*mpi->getRawMpiComm())();
}

// Equal runs of consecutive element ids.
std::vector<idx_t> consecutiveRuns(GO ne, int nparts) {
  std::vector<idx_t> part(ne);
  for (GO e = 0; e < ne; ++e) part[e] = idx_t(e * nparts / ne);
  return part;
}

// Rank 0: part[e] for every element.
std::vector<idx_t> partitionElements(const MeshGenerator& gen, int nparts, Partition partition) {
  const GO ne = gen.numElements();
  if (nparts == 1) return std::vector<idx_t>(ne, 0);
  if (ne < nparts) throw std::runtime_error("mesh: fewer elements than MPI ranks");
  if (partition == Partition::Slabs) return consecutiveRuns(ne, nparts);
  std::vector<idx_t> part(ne, 0);
  std::vector<idx_t> xadj(ne + 1, 0), adjncy;
  for (GO e = 0; e < ne; ++e) {
    for (GO nb : gen.faceNeighbours(e)) adjncy.push_back(idx_t(nb));
    xadj[e + 1] = idx_t(adjncy.size());
  }
  idx_t n = idx_t(ne), ncon = 1, np = nparts, objval = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;  // reproducible partitions
  const int status = METIS_PartGraphKway(&n, &ncon, xadj.data(), adjncy.data(), nullptr, nullptr,
                                         nullptr, &np, nullptr, nullptr, options, &objval,
                                         part.data());
  if (status != METIS_OK) throw std::runtime_error("mesh: METIS partitioning failed");
  // METIS may leave a part empty on tiny meshes: then fall back to runs of
  // consecutive elements, so every rank has work.
  std::vector<GO> size(nparts, 0);
  for (idx_t p : part) ++size[p];
  if (*std::min_element(size.begin(), size.end()) == 0) return consecutiveRuns(ne, nparts);
  return part;
}

// Element faces whose two elements lie on different ranks.
GO cutFaces(const MeshGenerator& gen, const std::vector<idx_t>& part) {
  GO cut = 0;
  for (GO e = 0; e < GO(part.size()); ++e)
    for (GO nb : gen.faceNeighbours(e))
      if (nb > e && part[nb] != part[e]) ++cut;
  return cut;
}

// Each rank receives the global ids of its elements, in increasing order,
// and the number of faces cut.
std::vector<GO> scatterElements(const MeshGenerator& gen, const RCP<const Comm>& comm, Partition partition,
                                GO& cutFacesOut) {
  const int nranks = comm->getSize(), rank = comm->getRank();
  MPI_Comm mc = rawComm(comm);
  std::vector<long long> sendbuf;
  std::vector<int> counts(nranks, 0), displs(nranks, 0);
  long long cut = 0;
  if (rank == 0) {
    const auto part = partitionElements(gen, nranks, partition);
    cut = nranks > 1 ? cutFaces(gen, part) : 0;
    for (idx_t p : part) ++counts[p];
    std::partial_sum(counts.begin(), counts.end() - 1, displs.begin() + 1);
    sendbuf.resize(part.size());
    auto next = displs;
    for (size_t e = 0; e < part.size(); ++e) sendbuf[next[part[e]]++] = (long long)e;
  }
  int mine = 0;
  MPI_Scatter(counts.data(), 1, MPI_INT, &mine, 1, MPI_INT, 0, mc);
  std::vector<long long> recv(mine);
  MPI_Scatterv(sendbuf.data(), counts.data(), displs.data(), MPI_LONG_LONG, recv.data(), mine,
               MPI_LONG_LONG, 0, mc);
  MPI_Bcast(&cut, 1, MPI_LONG_LONG, 0, mc);
  cutFacesOut = GO(cut);
  return std::vector<GO>(recv.begin(), recv.end());
}

RCP<const Map> dofMap(const std::vector<GO>& nodes, const RCP<const Comm>& comm) {
  std::vector<GO> dofs(3 * nodes.size());
  for (size_t n = 0; n < nodes.size(); ++n)
    for (int c = 0; c < 3; ++c) dofs[3 * n + c] = 3 * nodes[n] + c;
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  return rcp(new Map(invalid, Teuchos::ArrayView<const GO>(dofs), 0, comm));
}

}  // namespace

Partition autoPartition(int slowestCells, int ranks) {
  return ranks > 1 && slowestCells / ranks >= kAutoSlabLayers ? Partition::Slabs : Partition::Metis;
}

Partition partitionFor(const std::string& name, int slowestCells, int ranks) {
  if (name == "Slabs") return Partition::Slabs;
  if (name == "METIS") return Partition::Metis;
  if (name == "Auto") return autoPartition(slowestCells, ranks);
  // The scene reader accepts these three only, so anything else is a bug here.
  throw std::logic_error("mesh: unknown Mesh/Partition '" + name + "'");
}

const char* partitionName(Partition partition) { return partition == Partition::Slabs ? "Slabs" : "METIS"; }

Mesh distributeMesh(const MeshGenerator& gen, const RCP<const Comm>& comm, Partition partition,
                    const std::vector<std::string>& streamlineFaces) {
  Mesh m;
  m.comm = comm;
  m.partition = partition;
  m.numGlobalNodes = gen.numNodes();
  m.numGlobalElements = gen.numElements();
  m.faceNames = gen.faceNames();
  m.elementGids = scatterElements(gen, comm, partition, m.numCutFaces);

  // Nodes this rank touches; ownership decided by Tpetra (one owner per node).
  std::vector<GO> touched;
  for (GO e : m.elementGids)
    for (GO n : gen.elementNodes(e)) touched.push_back(n);
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  RCP<const Map> touchedMap = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(touched), 0, comm));
  m.ownedNodeMap = Tpetra::createOneToOne(touchedMap);

  // Overlapped order: owned nodes first, then ghosts (sorted).
  const auto owned = m.ownedNodeMap->getNodeElementList();
  m.nodeGids.assign(owned.begin(), owned.end());
  m.numOwnedNodes = m.nodeGids.size();
  for (GO n : touched)
    if (!m.ownedNodeMap->isNodeGlobalElement(n)) m.nodeGids.push_back(n);
  // Ring neighbours of the streamline faces' nodes: ghosts too (owned by the
  // ranks whose elements hold them).
  std::vector<std::pair<GO, std::array<GO, 4>>> rings;
  if (!streamlineFaces.empty()) {
    std::set<GO> seen(touched.begin(), touched.end()), extra;
    for (GO e : m.elementGids)
      for (const auto& f : gen.boundaryFaces(e)) {
        if (std::find(streamlineFaces.begin(), streamlineFaces.end(), f.name) == streamlineFaces.end()) continue;
        for (GO n : f.nodes) {
          std::array<GO, 4> nb;
          for (int s = 0; s < 4; ++s) nb[s] = gen.ringNeighbour(n, Mesh::kRingSteps[s]);
          rings.push_back({n, nb});
          for (GO x : nb)
            if (x >= 0 && !seen.count(x)) extra.insert(x);
        }
      }
    m.nodeGids.insert(m.nodeGids.end(), extra.begin(), extra.end());
  }
  m.overlapNodeMap = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(m.nodeGids), 0, comm));
  m.ownedDofMap = dofMap(std::vector<GO>(owned.begin(), owned.end()), comm);
  m.overlapDofMap = dofMap(m.nodeGids, comm);

  std::unordered_map<GO, int> lid;
  for (size_t n = 0; n < m.nodeGids.size(); ++n) lid[m.nodeGids[n]] = int(n);
  m.X.resize(3 * m.nodeGids.size());
  for (size_t n = 0; n < m.nodeGids.size(); ++n) {
    const auto X = gen.nodeCoordinates(m.nodeGids[n]);
    for (int d = 0; d < 3; ++d) m.X[3 * n + d] = X[d];
  }
  m.ringNeighbours.assign(m.nodeGids.size(), {-1, -1, -1, -1});
  for (const auto& [n, nb] : rings)
    for (int s = 0; s < 4; ++s) m.ringNeighbours[lid.at(n)][s] = nb[s] >= 0 ? lid.at(nb[s]) : -1;
  for (const auto& name : m.faceNames) m.faces[name];
  for (GO e : m.elementGids) {
    for (GO n : gen.elementNodes(e)) m.connectivity.push_back(lid.at(n));
    for (const auto& f : gen.boundaryFaces(e))
      for (GO n : f.nodes) m.faces[f.name].push_back(lid.at(n));
  }
  return m;
}

std::vector<int> Mesh::faceNodes(const std::string& face) const {
  std::vector<int> nodes = faces.at(face);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

}  // namespace capstan
