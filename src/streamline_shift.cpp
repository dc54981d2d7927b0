#include "streamline_shift.hpp"

#include <Tpetra_Import.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "../kernels/rigid_core.hpp"
#include "collective.hpp"
#include "effects/effect.hpp"
#include "rigid_cores.hpp"

namespace capstan {

namespace {

// Linear interpolation along a ring of (angle, index) sorted by angle, at
// angle t (periodic): the two neighbours and the weight of the second.
struct RingPoint {
  size_t a, b;
  double f;
};
template <class Ring>
RingPoint interpolate(const Ring& ring, double t) {
  const double twoPi = 2 * M_PI;
  t -= twoPi * std::floor((t - ring.front().first) / twoPi);
  const auto above = std::upper_bound(ring.begin(), ring.end(), t,
                                      [](double x, const auto& y) { return x < y.first; });
  const size_t ia = size_t(above - ring.begin()) - 1, ib = (ia + 1) % ring.size();
  const double pa = ring[ia].first, pb = ib == 0 ? ring.front().first + twoPi : ring[ib].first;
  return {ia, ib, pb > pa ? (t - pa) / (pb - pa) : 0.0};
}

// Every rank's records (doubles), concatenated in rank order on every rank.
std::vector<double> gatherAll(const std::vector<double>& mine, MPI_Comm comm) {
  int size = 0;
  MPI_Comm_size(comm, &size);
  int count = int(mine.size());
  std::vector<int> counts(size), offsets(size, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  std::partial_sum(counts.begin(), counts.end() - 1, offsets.begin() + 1);
  std::vector<double> all(size_t(offsets.back() + counts.back()));
  MPI_Allgatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, comm);
  return all;
}

// A ring of sites (angle, values) sorted by angle, coincident sites (a
// node's points on its faces) averaged into one.
using SiteRing = std::vector<std::pair<double, std::vector<double>>>;
SiteRing mergeCoincident(SiteRing ring) {
  std::sort(ring.begin(), ring.end());
  SiteRing merged;
  std::vector<int> n;
  for (auto& site : ring) {
    if (!merged.empty() && std::fabs(site.first - merged.back().first) < 1e-12) {
      for (size_t c = 0; c < site.second.size(); ++c) merged.back().second[c] += site.second[c];
      ++n.back();
      continue;
    }
    merged.push_back(std::move(site));
    n.push_back(1);
  }
  for (size_t i = 0; i < merged.size(); ++i)
    for (double& v : merged[i].second) v /= n[i];
  return merged;
}

}  // namespace

StreamlineShift::StreamlineShift(const Mesh& mesh, const RCP<const Map>& ownedDofs) : mesh_(mesh) {
  const GO n = GO(mesh.numGlobalNodes);
  std::vector<GO> gids(3 * n);
  for (GO g = 0; g < 3 * n; ++g) gids[g] = g;
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  all_ = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(gids), 0, mesh.comm));
  import_ = rcp(new Tpetra::Import<>(ownedDofs, all_));
  Vector X(ownedDofs), Xall(all_);
  {
    auto x = X.getDataNonConst();
    for (size_t k = 0; k < mesh.numOwnedNodes; ++k)
      for (int i = 0; i < 3; ++i) x[3 * k + i] = mesh.X[3 * k + i];
  }
  Xall.doImport(X, *import_, Tpetra::INSERT);
  auto xa = Xall.getData();
  X_.assign(xa.begin(), xa.end());
}

// Nodes grouped by their radius and axial position about the core's axis
// (reference geometry, to 1e-9 of the largest coordinate), each ring by angle.
const StreamlineShift::Rings& StreamlineShift::ringsOf(const RigidCore& core, size_t coreIndex) {
  auto it = rings_.find(coreIndex);
  if (it != rings_.end()) return it->second;
  Rings& r = rings_[coreIndex];
  const double* b = core.axisDirection.data();
  double e1[3] = {1, 0, 0};
  if (std::fabs(b[0]) > 0.9) e1[0] = 0, e1[1] = 1;
  const double d = e1[0] * b[0] + e1[1] * b[1] + e1[2] * b[2];
  for (int i = 0; i < 3; ++i) e1[i] -= d * b[i];
  const double l = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (int i = 0; i < 3; ++i) e1[i] /= l;
  const double e2[3] = {b[1] * e1[2] - b[2] * e1[1], b[2] * e1[0] - b[0] * e1[2], b[0] * e1[1] - b[1] * e1[0]};
  const size_t n = X_.size() / 3;
  double scale = 0;
  for (double x : X_) scale = std::max(scale, std::fabs(x));
  const double tol = 1e-9 * std::max(scale, 1e-300);
  std::map<std::pair<long long, long long>, int> ids;
  r.angle.resize(n);
  r.ring.resize(n);
  for (size_t g = 0; g < n; ++g) {
    double R[3];
    for (int i = 0; i < 3; ++i) R[i] = X_[3 * g + i] - core.axisPoint[i];
    const double a = R[0] * b[0] + R[1] * b[1] + R[2] * b[2];
    const double x1 = R[0] * e1[0] + R[1] * e1[1] + R[2] * e1[2], x2 = R[0] * e2[0] + R[1] * e2[1] + R[2] * e2[2];
    r.angle[g] = std::atan2(x2, x1);
    const auto key = std::make_pair(std::llround(std::sqrt(x1 * x1 + x2 * x2) / tol), std::llround(a / tol));
    auto [pos, added] = ids.emplace(key, int(r.rings.size()));
    if (added) r.rings.emplace_back();
    r.ring[g] = pos->second;
    r.rings[pos->second].push_back({r.angle[g], GO(g)});
  }
  for (auto& ring : r.rings) std::sort(ring.begin(), ring.end());
  return r;
}

void StreamlineShift::apply(Vector& u, const RigidCore& core, size_t coreIndex, double dTheta, LO rotationLid) {
  const Rings& r = ringsOf(core, coreIndex);
  Vector uAll(all_);
  uAll.doImport(u, *import_, Tpetra::INSERT);
  auto ua = uAll.getData();
  const double* b = core.axisDirection.data();
  const size_t n = X_.size() / 3;
  // w: each node's position about the axis, turned back by its angle.
  std::vector<double> w(3 * n);
  for (size_t g = 0; g < n; ++g) {
    double p[3];
    for (int i = 0; i < 3; ++i) p[i] = X_[3 * g + i] + ua[3 * g + i] - core.axisPoint[i] - core.translation[i];
    kernels::rotateAboutAxis(b, -r.angle[g], p, &w[3 * g]);
  }
  auto data = u.getDataNonConst();
  for (size_t k = 0; k < mesh_.numOwnedNodes; ++k) {
    const GO g = mesh_.nodeGids[k];
    const auto& ring = r.rings[r.ring[g]];
    const double t = r.angle[g] + dTheta;  // the point dTheta downstream
    const RingPoint q = interpolate(ring, t);
    const GO ga = ring[q.a].second, gb = ring[q.b].second;
    double wi[3], p[3];
    for (int i = 0; i < 3; ++i) wi[i] = (1 - q.f) * w[3 * ga + i] + q.f * w[3 * gb + i];
    kernels::rotateAboutAxis(b, t, wi, p);
    for (int i = 0; i < 3; ++i)
      data[3 * k + i] = core.axisPoint[i] + core.translation[i] + p[i] - mesh_.X[3 * k + i];
  }
  if (rotationLid >= 0) data[rotationLid] += dTheta;
}

void StreamlineShift::shiftMultipliers(Effect& effect, const RigidCore& core, size_t coreIndex, double dTheta) {
  std::vector<int> siteNodes;
  const int perSite = effect.multiplierSites(siteNodes);
  if (perSite == 0) return;  // the same on every rank: it depends on the settings only
  const Rings& r = ringsOf(core, coreIndex);
  auto view = effect.multipliers();
  auto values = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), view);
  const size_t sites = siteNodes.size() / size_t(perSite);
  int components = sites > 0 ? int(values.extent(0) / sites) : 0;
  MPI_Comm comm = rawComm(mesh_.comm);
  MPI_Allreduce(MPI_IN_PLACE, &components, 1, MPI_INT, MPI_MAX, comm);
  if (components == 0) return;
  // Per used site: its key (the rings of its nodes, sorted, padded with -1),
  // its angle (the circular mean of its nodes' angles) and its values.
  const size_t width = size_t(perSite) + 1 + size_t(components);
  std::vector<double> mine;
  std::vector<size_t> used;
  for (size_t s = 0; s < sites; ++s) {
    const int* nodes = &siteNodes[s * perSite];
    if (nodes[0] < 0) continue;
    std::vector<int> key(perSite, -1);
    double sx = 0, sy = 0;
    for (int a = 0; a < perSite; ++a) {
      const GO g = mesh_.nodeGids[nodes[a]];
      key[a] = r.ring[g];
      sx += std::cos(r.angle[g]), sy += std::sin(r.angle[g]);
    }
    std::sort(key.begin(), key.end());
    key.erase(std::unique(key.begin(), key.end()), key.end());
    key.resize(perSite, -1);
    for (int k : key) mine.push_back(k);
    mine.push_back(std::atan2(sy, sx));
    for (int c = 0; c < components; ++c) mine.push_back(values(s * components + c));
    used.push_back(s);
  }
  const std::vector<double> all = gatherAll(mine, comm);
  std::map<std::vector<int>, SiteRing> rings;
  for (size_t o = 0; o < all.size(); o += width) {
    std::vector<int> key(all.begin() + o, all.begin() + o + perSite);
    rings[key].push_back({all[o + perSite], std::vector<double>(all.begin() + o + perSite + 1, all.begin() + o + width)});
  }
  for (auto& entry : rings) entry.second = mergeCoincident(std::move(entry.second));
  for (size_t i = 0; i < used.size(); ++i) {
    const double* rec = &mine[i * width];
    const auto& ring = rings.at(std::vector<int>(rec, rec + perSite));
    const RingPoint p = interpolate(ring, rec[perSite] + dTheta);
    for (int c = 0; c < components; ++c)
      values(used[i] * components + c) = (1 - p.f) * ring[p.a].second[c] + p.f * ring[p.b].second[c];
  }
  Kokkos::deep_copy(view, values);
  effect.projectMultipliers();
}

}  // namespace capstan
