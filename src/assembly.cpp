#include "assembly.hpp"

#include <Kokkos_Timer.hpp>
#include <Teuchos_CommHelpers.hpp>

#include <algorithm>
#include <limits>
#include <set>

namespace capstan {

namespace {
// An effect's active flags on the host (empty: every entity is active).
Kokkos::View<int*>::HostMirror activeOnHost(const LocalSystem& L) {
  return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.active);
}
}  // namespace

Assembly::Assembly(const Mesh& mesh, const Scene& scene) : mesh_(mesh), effects_(buildEffects(mesh, scene)) {
  nodeDofs_ = int(3 * mesh.numOverlapNodes());
  // Rigid cores first: their face nodes follow the core whatever other
  // support also names them.
  coreOfNode_.assign(mesh.numOverlapNodes(), -1);
  for (const auto& s : scene.supports) {
    if (s.type != "Rigid Core") continue;
    RigidCore core;
    core.name = s.name;
    core.axisPoint = s.axisPoint, core.axisDirection = s.axisDirection, core.force = s.force;
    core.torque = s.torque, core.rampTime = s.rampTime;
    core.free = {s.freeTranslation[0], s.freeTranslation[1], s.freeTranslation[2], s.rotation == "Free"};
    core.firstDof = nodeDofs_ + 6 * int(cores_.size());
    for (int n : mesh.faceNodes(s.face))
      if (coreOfNode_[n] < 0) coreOfNode_[n] = int(cores_.size());
    cores_.push_back(core);
  }
  const size_t ndof = size_t(nodeDofs_) + 6 * cores_.size();
  constraints_.supportOf.assign(ndof, -1);
  constraints_.velocity.assign(ndof, 0.0);
  for (const auto& s : scene.supports) {
    if (s.type == "Foundation") continue;  // an effect (src/effects/factory.hpp), no held dofs
    const int id = int(constraints_.supportNames.size());
    constraints_.supportNames.push_back(s.name);
    if (s.type == "Rigid Core") {
      auto& core = *std::find_if(cores_.begin(), cores_.end(), [&](const RigidCore& c) { return c.name == s.name; });
      core.support = id;
      for (size_t n = 0; n < coreOfNode_.size(); ++n)
        if (coreOfNode_[n] == int(&core - cores_.data()))
          for (int i = 0; i < 3; ++i) constraints_.supportOf[3 * n + i] = id;
      for (int j = 0; j < 6; ++j) {
        if (j < 4 && core.free[j]) continue;  // an unknown of the Newton solve
        constraints_.supportOf[core.firstDof + j] = id;
        constraints_.velocity[core.firstDof + j] = j == 3 && s.rotation == "Prescribed" ? s.angularVelocity : 0.0;
      }
      continue;
    }
    // Fixed, Roller, Displacement: the first support in the scene that holds a
    // dof owns it (and its reaction).
    for (int n : mesh.faceNodes(s.face))
      for (int i = 0; i < 3; ++i) {
        if (!s.components[i] || constraints_.supportOf[3 * n + i] >= 0) continue;
        constraints_.supportOf[3 * n + i] = id;
        constraints_.velocity[3 * n + i] = s.type == "Displacement" ? s.velocity[i] : 0.0;
      }
  }

  // Graph from every effect's entities: built once, fixed sparsity. An entity
  // with a core's face node also couples to the core's free unknowns.
  buildDofMaps();
  importer_ = rcp(new Tpetra::Import<>(ownedDofMap_, overlapDofMap_));
  // Global column ids: the owner of a shared row also receives columns that only
  // other ranks' elements touch, so the column map is built by Tpetra after the
  // export, not taken from this rank's nodes.
  const auto& overlap = *overlapDofMap_;
  auto gid = [&](int dof) { return overlap.getGlobalElement(overlapLid(dof)); };
  if (cores_.empty()) {
    graph_ = rcp(new FEGraph(ownedDofMap_, overlapDofMap_, 81, importer_));
  } else {
    // A node's row has at most 81 entries (27 nodes), plus a core's 4 unknowns;
    // a core's rows have one entry per dof of the elements at its face.
    Kokkos::DualView<size_t*, FEGraph::device_type> perRow("entries per row", overlap.getNodeNumElements());
    auto h = perRow.view_host();
    Kokkos::deep_copy(h, size_t(81 + 4 * cores_.size()));
    std::vector<std::vector<char>> seen(cores_.size(), std::vector<char>(constraints_.supportOf.size(), 0));
    for (const auto& effect : effects_.all) {
      if (!effect->local().stiff) continue;
      auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effect->local().dofs);
      for (size_t e = 0; e < dofs.extent(0); ++e)
        for (size_t k = 0; k < dofs.extent(1); ++k) {
          const int c = coreOfNode_[dofs(e, k) / 3];
          if (c >= 0)
            for (size_t l = 0; l < dofs.extent(1); ++l) seen[c][dofs(e, l)] = 1;
        }
    }
    for (size_t c = 0; c < cores_.size(); ++c) {
      const size_t count = std::count(seen[c].begin(), seen[c].end(), char(1)) + 6 * cores_.size();
      for (int j = 0; j < 6; ++j) h(overlapLid(cores_[c].firstDof + j)) = count;
    }
    perRow.modify_host();
    perRow.sync_device();
    graph_ = rcp(new FEGraph(ownedDofMap_, overlapDofMap_, perRow, importer_));
  }
  graph_->beginAssembly();
  for (const auto& effect : effects_.all) {
    coupled_.emplace_back();
    if (!effect->local().stiff) continue;  // no stiffness, no graph entries
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effect->local().dofs);
    std::vector<GO> cols;
    for (size_t e = 0; e < dofs.extent(0); ++e) {
      cols.clear();
      std::set<int> cores;
      for (size_t k = 0; k < dofs.extent(1); ++k) {
        cols.push_back(gid(dofs(e, k)));
        if (coreOfNode_[dofs(e, k) / 3] >= 0) cores.insert(coreOfNode_[dofs(e, k) / 3]);
      }
      for (int c : cores)
        for (int j = 0; j < 4; ++j)
          if (cores_[c].free[j]) cols.push_back(gid(cores_[c].firstDof + j));
      if (!cores.empty()) coupled_.back().push_back(int(e));
      for (GO row : cols) graph_->insertGlobalIndices(row, Teuchos::ArrayView<const GO>(cols));
    }
  }
  if (coresOwned_)  // the cores' held dofs get their unit diagonal
    for (const auto& core : cores_)
      for (int j = 0; j < 6; ++j) {
        const GO g = gid(core.firstDof + j);
        graph_->insertGlobalIndices(g, Teuchos::ArrayView<const GO>(&g, 1));
      }
  graph_->endAssembly();
  // Each effect's dofs as local column ids of the assembled matrix.
  const auto& colMap = *graph_->getColMap();
  columnOf_.resize(constraints_.supportOf.size());
  for (size_t d = 0; d < columnOf_.size(); ++d) columnOf_[d] = colMap.getLocalElement(gid(int(d)));
  for (const auto& effect : effects_.all) {
    if (!effect->local().stiff) {
      columns_.emplace_back();
      continue;
    }
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effect->local().dofs);
    std::vector<LO> cols(dofs.size());
    for (size_t e = 0; e < dofs.extent(0); ++e)
      for (size_t k = 0; k < dofs.extent(1); ++k) cols[e * dofs.extent(1) + k] = columnOf_[dofs(e, k)];
    columns_.push_back(std::move(cols));
  }
  buildTangentSinks();
  uOverlap_ = rcp(new Vector(overlapDofMap_));
  residual_ = rcp(new Tpetra::FEMultiVector<>(ownedDofMap_, importer_, 1));
  x_ = NodalVectors("x", mesh.numOverlapNodes());
  u_ = NodalVectors("u", mesh.numOverlapNodes());
  readCores(uOverlap_->getData());  // the undeformed state until the first evaluation
}

void Assembly::assembleCoreCoupling(FEMatrix& W) {
  if (cores_.empty()) return;
  // The chain rule for u_s = T + (R(theta) - I)(X_s - A) at each face node s,
  // with B_s = du_s/dq = [I | b_s]: element entries K(k, s) go to K(k, q) B_s,
  // K(s, l) to B_s^T K(s, l), K(s, s') to B_s^T K B_s'; and
  // d(sum_s R_s . b_s)/dtheta adds sum_s R_s . w_s to (theta, theta).
  // Accumulated per element in dense arrays, then added row by row.
  const auto& supportOf = constraints_.supportOf;
  const size_t nc = cores_.size(), nq = 4 * nc;
  // Scratch kept between assemblies (no allocation per evaluation).
  auto& toCore = coupling_.toCore;
  auto& fromCore = coupling_.fromCore;
  auto& coreCore = coupling_.coreCore;
  auto& touched = coupling_.touched;
  toCore.assign(nq * nodeDofs_, 0.0), fromCore.assign(nq * nodeDofs_, 0.0), coreCore.assign(nq * nq, 0.0);
  touched.assign(nodeDofs_, 0);
  for (size_t i = 0; i < effects_.all.size(); ++i) {
    const auto& L = effects_.all[i]->local();
    if (!L.stiff || coupled_[i].empty()) continue;
    const auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.dofs);
    const auto K = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), sinks_[i].kept);
    const auto active = activeOnHost(L);
    const int n = int(dofs.extent(1));
    std::vector<std::array<double, 4>> B(n);
    std::vector<int> coreOf(n);
    for (size_t slot = 0; slot < coupled_[i].size(); ++slot) {
      const int e = coupled_[i][slot];
      if (active.size() && !active(e)) continue;
      for (int k = 0; k < n; ++k) {
        const int d = dofs(e, k), c = coreOfNode_[d / 3];
        coreOf[k] = c;
        if (c >= 0) B[k] = coreChain(d);
      }
      for (int k = 0; k < n; ++k)
        for (int l = 0; l < n; ++l) {
          const int ck = coreOf[k], cl = coreOf[l], dk = dofs(e, k), dl = dofs(e, l);
          const double Kkl = K(slot, k, l);
          if ((ck < 0 && cl < 0) || Kkl == 0) continue;
          if (ck < 0) {
            if (supportOf[dk] >= 0) continue;
            touched[dk] = 1;
            for (int j = 0; j < 4; ++j) toCore[(4 * cl + j) * nodeDofs_ + dk] += Kkl * B[l][j];
          } else if (cl < 0) {
            if (supportOf[dl] >= 0) continue;
            touched[dl] = 1;
            for (int j = 0; j < 4; ++j) fromCore[(4 * ck + j) * nodeDofs_ + dl] += B[k][j] * Kkl;
          } else {
            for (int a = 0; a < 4; ++a)
              for (int b = 0; b < 4; ++b) coreCore[(4 * ck + a) * nq + 4 * cl + b] += B[k][a] * Kkl * B[l][b];
          }
        }
    }
  }
  std::vector<LO> cols;
  std::vector<double> vals;
  auto add = [&](LO row) {
    const LO added = W.sumIntoLocalValues(row, Teuchos::ArrayView<const LO>(cols), Teuchos::ArrayView<const double>(vals));
    if (added != LO(cols.size())) throw std::logic_error("assembly: a rigid-core entry is missing from the matrix graph");
  };
  auto freeCoreDof = [&](size_t q) { return cores_[q / 4].free[q % 4]; };
  auto coreDof = [&](size_t q) { return cores_[q / 4].firstDof + int(q % 4); };
  for (int d = 0; d < nodeDofs_; ++d) {
    if (!touched[d]) continue;
    cols.clear(), vals.clear();
    for (size_t q = 0; q < nq; ++q)
      if (freeCoreDof(q) && toCore[q * nodeDofs_ + d] != 0)
        cols.push_back(columnOf_[coreDof(q)]), vals.push_back(toCore[q * nodeDofs_ + d]);
    if (!cols.empty()) add(overlapLid(d));
  }
  for (size_t q = 0; q < nq; ++q) {
    if (!freeCoreDof(q)) continue;
    cols.clear(), vals.clear();
    for (int d = 0; d < nodeDofs_; ++d)
      if (touched[d] && fromCore[q * nodeDofs_ + d] != 0)
        cols.push_back(columnOf_[d]), vals.push_back(fromCore[q * nodeDofs_ + d]);
    for (size_t p = 0; p < nq; ++p) {
      double v = coreCore[q * nq + p];
      // The reactions are global sums: rank 0 adds the geometric term once.
      if (p == q && q % 4 == 3 && coresOwned_) v += cores_[q / 4].geometric;
      if (freeCoreDof(p) && v != 0) cols.push_back(columnOf_[coreDof(p)]), vals.push_back(v);
    }
    if (!cols.empty()) add(overlapLid(coreDof(q)));
  }
}

void Assembly::buildTangentSinks() {
  // The owned-plus-shared matrix is active between beginAssembly and endAssembly;
  // its local rows are the overlapped dof ids the effects use.
  auto W = createMatrix();
  W->beginAssembly();
  const auto local = W->getLocalMatrixHost();
  const auto rowStart = local.graph.row_map;
  const auto entries = local.graph.entries;
  if (entries.extent(0) > size_t(std::numeric_limits<int>::max()))
    throw std::runtime_error("assembly: a rank's matrix has more than 2^31 entries; run on more ranks");
  auto find = [&](LO row, LO col) -> int {
    for (auto j = rowStart(row); j < rowStart(row + 1); ++j)
      if (entries(j) == col) return int(j);
    throw std::logic_error("assembly: an element entry is missing from the matrix graph");
  };
  const auto& supportOf = constraints_.supportOf;
  for (size_t i = 0; i < effects_.all.size(); ++i) {
    const auto& L = effects_.all[i]->local();
    sinks_.emplace_back();
    if (!L.stiff) continue;
    TangentSink& sink = sinks_.back();
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.dofs);
    const size_t ne = dofs.extent(0), n = dofs.extent(1), nb = n / 3;
    if (n > 30) throw std::logic_error("assembly: an entity has more than 30 dofs (the held-column mask is an int)");
    sink.rowBlock = decltype(sink.rowBlock)("tangent row blocks", ne, n * nb);
    sink.heldColumns = Kokkos::View<int*>("tangent held columns", ne);
    auto hb = Kokkos::create_mirror_view(sink.rowBlock);
    auto hh = Kokkos::create_mirror_view(sink.heldColumns);
    for (size_t e = 0; e < ne; ++e) {
      int held = 0;
      for (size_t l = 0; l < n; ++l)
        if (supportOf[dofs(e, l)] >= 0) held |= 1 << l;
      hh(e) = held;
      for (size_t k = 0; k < n; ++k)
        for (size_t b = 0; b < nb; ++b) {
          int& o = hb(e, k * nb + b);
          o = -1;
          if (supportOf[dofs(e, k)] >= 0) continue;  // a held row: the identity
          // A node's 3 columns sit side by side in every row (its dofs have
          // consecutive column ids, and each row's entries are sorted).
          for (size_t j = 0; j < 3; ++j) {
            if (held & (1 << (3 * b + j))) continue;
            const int at = find(overlapLid(dofs(e, k)), columns_[i][e * n + 3 * b + j]) - int(j);
            if (o >= 0 && at != o)
              throw std::logic_error("assembly: a node's 3 columns are not side by side in a matrix row");
            o = at;
          }
          if (o < 0) o = 0;  // all 3 columns held: the bits skip them
        }
    }
    Kokkos::deep_copy(sink.rowBlock, hb);
    Kokkos::deep_copy(sink.heldColumns, hh);
    if (!coupled_[i].empty()) {
      sink.keepSlot = Kokkos::View<int*>("tangent keep slot", ne);
      sink.kept = decltype(sink.kept)("kept tangents", coupled_[i].size(), n, n);
      auto hk = Kokkos::create_mirror_view(sink.keepSlot);
      Kokkos::deep_copy(hk, -1);
      for (size_t slot = 0; slot < coupled_[i].size(); ++slot) hk(coupled_[i][slot]) = int(slot);
      Kokkos::deep_copy(sink.keepSlot, hk);
    }
  }
  std::vector<int> diagonal;
  for (LO d = 0; d < LO(ownedDofMap_->getNodeNumElements()); ++d)
    if (supportOf[assemblyDof(d)] >= 0) diagonal.push_back(find(d, columnOf_[assemblyDof(d)]));
  constrainedDiagonal_ = Kokkos::View<int*>("constrained diagonal", diagonal.size());
  auto hd = Kokkos::create_mirror_view(constrainedDiagonal_);
  for (size_t j = 0; j < diagonal.size(); ++j) hd(j) = diagonal[j];
  Kokkos::deep_copy(constrainedDiagonal_, hd);
  W->endAssembly();
}

RCP<FEMatrix> Assembly::createMatrix() const { return rcp(new FEMatrix(graph_)); }

void Assembly::chainRows(const Effect& e, const Matrix& values, std::vector<size_t>& rowStart,
                         std::vector<GO>& cols, std::vector<double>& vals, const std::vector<int>* entities) const {
  auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e.local().dofs);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), values);
  const auto& supportOf = constraints_.supportOf;
  auto gid = [&](int dof) { return overlapDofMap_->getGlobalElement(overlapLid(dof)); };
  rowStart.assign(1, 0), cols.clear(), vals.clear();
  for (size_t k = 0; k < v.extent(0); ++k) {
    const size_t entity = entities ? size_t((*entities)[k]) : k;
    const size_t first = cols.size();
    auto add = [&](GO col, double x) {
      for (size_t i = first; i < cols.size(); ++i)
        if (cols[i] == col) return void(vals[i] += x);
      cols.push_back(col), vals.push_back(x);
    };
    for (size_t j = 0; j < dofs.extent(1); ++j) {
      const int d = dofs(entity, j), c = coreOfNode_[d / 3];
      if (c < 0) {
        if (supportOf[d] < 0) add(gid(d), v(k, j));
        continue;
      }
      // The core's free unknowns this dof moves with: its own translation
      // component and the rotation (kept even where du/dtheta is 0, so that
      // every evaluation has the same columns).
      const RigidCore& core = cores_[c];
      const auto B = coreChain(d);
      for (int q = 0; q < 4; ++q)
        if (core.free[q] && (q == 3 || q == d % 3)) add(gid(core.firstDof + q), v(k, j) * B[q]);
    }
    rowStart.push_back(cols.size());
  }
}

LO Assembly::overlapLid(int dof) const {
  const int ownedNodeDofs = int(3 * mesh_.numOwnedNodes);
  if (dof >= nodeDofs_) return LO(coresOwned_ ? ownedNodeDofs + (dof - nodeDofs_) : dof);
  return LO(coresOwned_ && dof >= ownedNodeDofs ? dof + int(6 * cores_.size()) : dof);
}

void Assembly::buildDofMaps() {
  coresOwned_ = !cores_.empty() && mesh_.comm->getRank() == 0;
  if (cores_.empty()) {
    ownedDofMap_ = mesh_.ownedDofMap, overlapDofMap_ = mesh_.overlapDofMap;
    return;
  }
  const GO firstCoreGid = GO(3 * mesh_.numGlobalNodes);
  auto gid = [&](int d) { return d < nodeDofs_ ? 3 * mesh_.nodeGids[d / 3] + d % 3 : firstCoreGid + (d - nodeDofs_); };
  const int ndof = int(constraints_.supportOf.size());
  std::vector<GO> owned, overlap(ndof);
  for (int d = 0; d < int(3 * mesh_.numOwnedNodes); ++d) owned.push_back(gid(d));
  if (coresOwned_)
    for (int d = nodeDofs_; d < ndof; ++d) owned.push_back(gid(d));
  for (int d = 0; d < ndof; ++d) overlap[overlapLid(d)] = gid(d);
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  ownedDofMap_ = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(owned), 0, mesh_.comm));
  overlapDofMap_ = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(overlap), 0, mesh_.comm));
}

void Assembly::readCores(const Teuchos::ArrayRCP<const double>& ud) {
  for (auto& core : cores_) {
    for (int i = 0; i < 3; ++i) core.translation[i] = ud[overlapLid(core.firstDof + i)];
    core.rotation = ud[overlapLid(core.firstDof + 3)];
  }
  followers_.resize(mesh_.numOverlapNodes());
  for (size_t n = 0; n < coreOfNode_.size(); ++n) {
    if (coreOfNode_[n] < 0) continue;
    const auto& core = cores_[coreOfNode_[n]];
    followers_[n] = kernels::coreFollower(core.axisPoint.data(), core.axisDirection.data(), core.translation.data(),
                                          core.rotation, &mesh_.X[3 * n]);
  }
}

std::vector<std::array<double, 5>> Assembly::coreSums(const Teuchos::ArrayRCP<const double>& v) const {
  const size_t nc = cores_.size();
  std::vector<double> local(5 * nc, 0.0), global(5 * nc, 0.0);
  for (size_t n = 0; n < mesh_.numOwnedNodes; ++n) {
    const int c = coreOfNode_[n];
    if (c < 0) continue;
    for (int i = 0; i < 3; ++i) {
      const double r = v[3 * n + i];
      local[5 * c + i] += r;
      local[5 * c + 3] += r * followers_[n].b[i];
      local[5 * c + 4] += r * followers_[n].w[i];
    }
  }
  if (nc) Teuchos::reduceAll(*mesh_.comm, Teuchos::REDUCE_SUM, int(5 * nc), local.data(), global.data());
  std::vector<std::array<double, 5>> out(nc);
  for (size_t c = 0; c < nc; ++c)
    for (int k = 0; k < 5; ++k) out[c][k] = global[5 * c + k];
  return out;
}

void Assembly::rollWithCores(Vector& u, const std::vector<double>& dTheta) {
  uOverlap_->doImport(u, *importer_, Tpetra::INSERT);
  readCores(uOverlap_->getData());
  auto data = u.getDataNonConst();
  for (size_t c = 0; c < cores_.size(); ++c) {
    const auto& core = cores_[c];
    if (!core.free[3] || dTheta[c] == 0) continue;
    for (size_t n = 0; n < mesh_.numOwnedNodes; ++n) {
      double r[3], turned[3];
      for (int i = 0; i < 3; ++i)
        r[i] = mesh_.X[3 * n + i] + data[3 * n + i] - core.axisPoint[i] - core.translation[i];
      kernels::rotateAboutAxis(core.axisDirection.data(), dTheta[c], r, turned);
      for (int i = 0; i < 3; ++i) data[3 * n + i] += turned[i] - r[i];
    }
    if (coresOwned_) data[3 * mesh_.numOwnedNodes + 6 * c + 3] += dTheta[c];
  }
}

void Assembly::applyConstraints(Vector& u, double t) {
  const auto& supportOf = constraints_.supportOf;
  {
    auto data = u.getDataNonConst();
    for (LO d = 0; d < LO(data.size()); ++d) {
      const int a = assemblyDof(d);
      const bool follows = a < nodeDofs_ && coreOfNode_[a / 3] >= 0;
      if (supportOf[a] >= 0 && !follows) data[d] = constraints_.velocity[a] * t;
    }
  }
  if (cores_.empty()) return;
  // The face nodes follow the cores' values, which rank 0 owns.
  uOverlap_->doImport(u, *importer_, Tpetra::INSERT);
  readCores(uOverlap_->getData());
  auto data = u.getDataNonConst();
  for (size_t n = 0; n < mesh_.numOwnedNodes; ++n)
    if (coreOfNode_[n] >= 0)
      for (int i = 0; i < 3; ++i) data[3 * n + i] = followers_[n].u[i];
}

bool Assembly::evaluate(const Vector& u, Vector* f, FEMatrix* W, const Vector* z, Vector* Kz) {
  Kokkos::Timer timer;
  uOverlap_->doImport(u, *importer_, Tpetra::INSERT);
  {
    auto ud = uOverlap_->getData();
    readCores(ud);
    auto hx = Kokkos::create_mirror_view(x_);
    auto hu = Kokkos::create_mirror_view(u_);
    for (size_t n = 0; n < mesh_.numOverlapNodes(); ++n)
      for (int i = 0; i < 3; ++i) {
        // A core's face node sits where the core puts it, whatever u holds there.
        hu(n, i) = coreOfNode_[n] >= 0 ? followers_[n].u[i] : ud[overlapLid(int(3 * n + i))];
        hx(n, i) = mesh_.X[3 * n + i] + hu(n, i);
      }
    Kokkos::deep_copy(x_, hx);
    Kokkos::deep_copy(u_, hu);
  }
  // The tangent goes straight from each kernel into W's local CRS values
  // (and into K z for the predictor), entity by entity.
  if (bool(z) != bool(Kz) || (z && !W)) throw std::logic_error("assembly: K z needs z, Kz and the tangent W");
  const bool action = z != nullptr;
  std::vector<Matrix> KzLocal;  // per effect: K z per entity (the sinks hold z per entity)
  if (W) {
    W->beginAssembly();
    W->setAllToScalar(0.0);
    const auto values = W->getLocalMatrixDevice().values;
    for (size_t i = 0; i < effects_.all.size(); ++i)
      if (effects_.all[i]->local().stiff) sinks_[i].values = values;  // the others evaluate without a sink
  }
  if (action) {
    if (zOverlap_.is_null()) zOverlap_ = rcp(new Vector(overlapDofMap_));
    zOverlap_->doImport(*z, *importer_, Tpetra::INSERT);
    auto zd = zOverlap_->getData();
    for (size_t i = 0; i < effects_.all.size(); ++i) {
      const auto& L = effects_.all[i]->local();
      KzLocal.emplace_back("K z", L.dofs.extent(0), L.dofs.extent(1));  // zero for entities without a tangent
      if (!L.stiff) continue;
      auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.dofs);
      Matrix zLocal("z", dofs.extent(0), dofs.extent(1));
      auto hz = Kokkos::create_mirror_view(zLocal);
      for (size_t e = 0; e < dofs.extent(0); ++e)
        for (size_t k = 0; k < dofs.extent(1); ++k) hz(e, k) = zd[overlapLid(dofs(e, k))];
      Kokkos::deep_copy(zLocal, hz);
      sinks_[i].z = zLocal, sinks_[i].Kz = KzLocal.back();
    }
  }
  for (size_t i = 0; i < effects_.all.size(); ++i)
    effects_.all[i]->evaluate(x_, u_, W && effects_.all[i]->local().stiff ? &sinks_[i] : nullptr);
  for (auto& sink : sinks_) sink.values = {}, sink.z = {}, sink.Kz = {};  // no stale views kept

  double minJ = 1e300;
  auto elementMinJ = effects_.bricks->minJacobian;
  Kokkos::parallel_reduce(
      "min J", Kokkos::RangePolicy<ExecSpace>(0, elementMinJ.extent(0)),
      KOKKOS_LAMBDA(int e, double& m) { m = elementMinJ(e) < m ? elementMinJ(e) : m; },
      Kokkos::Min<double>(minJ));
  double globalMinJ = minJ;
  Teuchos::reduceAll(*mesh_.comm, Teuchos::REDUCE_MIN, minJ, Teuchos::outArg(globalMinJ));
  const bool valid = globalMinJ > 0 && std::isfinite(globalMinJ);
  const auto& supportOf = constraints_.supportOf;

  // The residual; with rigid cores also for the tangent alone, whose
  // theta-theta entry needs the reactions at the face nodes.
  if (f || (W && !cores_.empty())) {
    std::vector<Matrix> R;
    for (const auto& effect : effects_.all) R.push_back(effect->local().R);
    sumEntityVectors(R);
    auto ro = residual_->getData(0);
    rawOwnedResidual_.assign(ro.begin(), ro.end());
    const auto sums = coreSums(ro);
    for (size_t c = 0; c < cores_.size(); ++c) {
      for (int i = 0; i < 3; ++i) cores_[c].forceOnBody[i] = sums[c][i];
      cores_[c].torqueOnBody = sums[c][3];
      cores_[c].geometric = sums[c][4];
    }
    if (f) {
      auto out = f->getDataNonConst();
      for (LO d = 0; d < LO(out.size()); ++d) {
        const int a = assemblyDof(d);
        if (!valid) out[d] = 1e150;
        else if (supportOf[a] >= 0) out[d] = 0.0;
        else if (a < nodeDofs_) out[d] = ro[d];
        else {
          // A core's free unknown: the reactions it exerts on the body balance
          // the external load on it.
          const auto& core = cores_[(a - nodeDofs_) / 6];
          const int j = (a - nodeDofs_) % 6;
          const double load = core.loadFactor(time_);
          out[d] = j < 3 ? core.forceOnBody[j] - load * core.force[j] : core.torqueOnBody - load * core.torque;
        }
      }
    }
  }

  if (action) {
    // K z: summed like a residual, then carried to the cores' unknowns.
    sumEntityVectors(KzLocal);
    auto ro = residual_->getData(0);
    const auto sums = coreSums(ro);
    auto yd = Kz->getDataNonConst();
    for (LO d = 0; d < LO(yd.size()); ++d) {
      const int a = assemblyDof(d);
      yd[d] = a < nodeDofs_ ? ro[d] : (a - nodeDofs_) % 6 < 4 ? sums[(a - nodeDofs_) / 6][(a - nodeDofs_) % 6] : 0.0;
    }
  }

  if (W) {
    const auto values = W->getLocalMatrixDevice().values;
    const auto diagonal = constrainedDiagonal_;
    Kokkos::parallel_for(
        "constrained diagonal", Kokkos::RangePolicy<ExecSpace>(0, diagonal.extent(0)),
        KOKKOS_LAMBDA(int j) { values(diagonal(j)) = 1.0; });
    Kokkos::fence();
    assembleCoreCoupling(*W);
    W->endAssembly();
  }
  assemblySeconds_ += timer.seconds();
  return valid;
}

void Assembly::sumEntityVectors(const std::vector<Matrix>& values) {
  residual_->beginAssembly();
  residual_->putScalar(0.0);
  {
    auto r = residual_->getDataNonConst(0);
    for (size_t i = 0; i < effects_.all.size(); ++i) {
      auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effects_.all[i]->local().dofs);
      auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), values[i]);
      auto active = activeOnHost(effects_.all[i]->local());
      for (size_t e = 0; e < dofs.extent(0); ++e)
        if (!active.size() || active(e))
          for (size_t k = 0; k < dofs.extent(1); ++k) r[overlapLid(dofs(e, k))] += v(e, k);
    }
  }
  residual_->endAssembly();  // one export: shared rows added into their owners
}

void Assembly::constraintIncrement(Vector& z, double t0, double t1) const {
  auto data = z.getDataNonConst();
  const auto& supportOf = constraints_.supportOf;
  const auto& velocity = constraints_.velocity;
  for (LO d = 0; d < LO(data.size()); ++d) {
    const int a = assemblyDof(d);
    if (a < nodeDofs_ && coreOfNode_[a / 3] >= 0) {
      // Linearised at the cores' last state: dT + b dtheta, held parts only.
      const auto& core = cores_[coreOfNode_[a / 3]];
      const int i = a % 3;
      const double dT = supportOf[core.firstDof + i] >= 0 ? velocity[core.firstDof + i] * (t1 - t0) : 0.0;
      const double dTheta = supportOf[core.firstDof + 3] >= 0 ? velocity[core.firstDof + 3] * (t1 - t0) : 0.0;
      data[d] = dT + followers_[a / 3].b[i] * dTheta;
    } else {
      data[d] = supportOf[a] >= 0 ? velocity[a] * (t1 - t0) : 0.0;
    }
  }
}

std::vector<std::array<double, 3>> Assembly::constraintReactions() const {
  const size_t ns = constraints_.supportNames.size();
  std::vector<double> local(3 * ns, 0.0), global(3 * ns, 0.0);
  for (size_t d = 0; d < rawOwnedResidual_.size(); ++d) {
    const int a = assemblyDof(LO(d));
    if (constraints_.supportOf[a] >= 0) local[3 * constraints_.supportOf[a] + a % 3] += rawOwnedResidual_[d];
  }
  if (ns)
    Teuchos::reduceAll(*mesh_.comm, Teuchos::REDUCE_SUM, int(3 * ns), local.data(), global.data());
  std::vector<std::array<double, 3>> out(ns);
  for (size_t s = 0; s < ns; ++s) out[s] = {global[3 * s], global[3 * s + 1], global[3 * s + 2]};
  return out;
}

}  // namespace capstan
