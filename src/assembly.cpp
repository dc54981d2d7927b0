#include "assembly.hpp"

#include <Kokkos_Timer.hpp>
#include <Teuchos_CommHelpers.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace capstan {

Assembly::Assembly(const Mesh& mesh, const Scene& scene)
    : mesh_(mesh), effects_(buildEffects(mesh, scene)), cores_(mesh, scene), constraints_(mesh, scene, cores_),
      layout_(cores_.layout()) {
  for (const auto& effect : effects_.all) effect->bindCores(cores_);
  // Steady friction couples a contact node to the nodes one ring cell upstream
  // and to omega, outside the bricks' 27-node stencil.
  extraColumns_ = scene.analysis.steady() ? 24 : 0;
  buildDofMaps();
  importer_ = rcp(new Tpetra::Import<>(ownedDofMap_, overlapDofMap_));
  buildGraph();
  buildTangentSinks();
  uOverlap_ = rcp(new Vector(overlapDofMap_));
  residual_ = rcp(new Tpetra::FEMultiVector<>(ownedDofMap_, importer_, 1));
  x_ = NodalVectors("x", mesh.numOverlapNodes());
  u_ = NodalVectors("u", mesh.numOverlapNodes());
  cores_.read(uOverlap_->getData());  // the undeformed state until the first evaluation
}

// Graph from every effect's entities: built once, fixed sparsity. An entity
// with a core's face node also couples to the core's free unknowns.
void Assembly::buildGraph() {
  // Global column ids: the owner of a shared row also receives columns that only
  // other ranks' elements touch, so the column map is built by Tpetra after the
  // export, not taken from this rank's nodes.
  const auto& overlap = *overlapDofMap_;
  auto gid = [&](int dof) { return overlap.getGlobalElement(layout_.overlapLid(dof)); };
  cores_.findCoupling(effects_.all);
  if (cores_.empty()) {
    graph_ = rcp(new FEGraph(ownedDofMap_, overlapDofMap_, 81 + extraColumns_, importer_));
  } else {
    // A node's row has at most 81 entries (27 nodes), plus a core's 4 unknowns;
    // a core's rows have one entry per dof of the elements at its face.
    Kokkos::DualView<size_t*, FEGraph::device_type> perRow("entries per row", overlap.getNodeNumElements());
    auto h = perRow.view_host();
    Kokkos::deep_copy(h, size_t(81 + extraColumns_ + 4 * cores_.size()));
    for (size_t c = 0; c < cores_.size(); ++c)
      for (int j = 0; j < kCoreUnknowns; ++j) h(layout_.overlapLid(cores_.records()[c].firstDof + j)) = cores_.rowEntries(c);
    perRow.modify_host();
    perRow.sync_device();
    graph_ = rcp(new FEGraph(ownedDofMap_, overlapDofMap_, perRow, importer_));
  }
  graph_->beginAssembly();
  // Each row's columns are gathered over the entities that touch it and
  // inserted once: inserting entity by entity searches the row each time
  // (G1 2x: 43 ms against 8 ms). A core's rows span every element at its face:
  // gathered apart (the 126k-dof drive's graph took 9.0 s element by element).
  using HostDofs = decltype(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), IntMatrix()));
  struct Stiff {
    HostDofs dofs;
    size_t rows;
    std::vector<size_t> coreFirst;  // entity e moves the cores' free unknowns coreDofs[coreFirst[e] .. [e + 1])
    std::vector<int> coreDofs;
  };
  std::vector<Stiff> stiff;
  for (const auto& effect : effects_.all) {
    if (!effect->local().stiff) continue;  // no stiffness, no graph entries
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effect->local().dofs);
    stiff.push_back({dofs, effect->local().rowDofs > 0 ? size_t(effect->local().rowDofs) : dofs.extent(1), {}, {}});
  }
  // The entities at each row dof (CSR: touching[first[d] .. first[d + 1]) as (effect, entity)).
  const size_t nDofs = size_t(layout_.size());
  std::vector<size_t> first(nDofs + 1, 0);
  for (const auto& st : stiff)
    for (size_t e = 0; e < st.dofs.extent(0); ++e)
      for (size_t k = 0; k < st.rows; ++k) ++first[st.dofs(e, k) + 1];
  for (size_t d = 0; d < nDofs; ++d) first[d + 1] += first[d];
  std::vector<std::pair<int, int>> touching(first[nDofs]);
  {
    std::vector<size_t> next(first.begin(), first.end() - 1);
    for (size_t i = 0; i < stiff.size(); ++i)
      for (size_t e = 0; e < stiff[i].dofs.extent(0); ++e)
        for (size_t k = 0; k < stiff[i].rows; ++k) touching[next[stiff[i].dofs(e, k)]++] = {int(i), int(e)};
  }
  // The cores' free unknowns each entity moves with (entities at a core's face only).
  const auto asDof = [](int dof) { return GO(dof); };
  std::vector<GO> cols;
  for (auto& st : stiff) {
    st.coreFirst.assign(st.dofs.extent(0) + 1, 0);
    for (size_t e = 0; e < st.dofs.extent(0) && !cores_.empty(); ++e) {
      cols.clear();
      cores_.appendFreeUnknowns(&st.dofs(e, 0), st.dofs.extent(1), asDof, cols);
      st.coreDofs.insert(st.coreDofs.end(), cols.begin(), cols.end());
      st.coreFirst[e + 1] = st.coreDofs.size();
    }
  }
  std::vector<int> seenBy(nDofs, -1);  // the row whose columns already hold this dof
  for (size_t d = 0; d < nDofs; ++d) {
    if (first[d] == first[d + 1]) continue;
    cols.clear();
    const auto add = [&](int c) {
      if (seenBy[c] != int(d)) seenBy[c] = int(d), cols.push_back(gid(c));
    };
    for (size_t t = first[d]; t < first[d + 1]; ++t) {
      const auto& [i, e] = touching[t];
      const Stiff& st = stiff[i];
      for (size_t k = 0; k < st.dofs.extent(1); ++k) add(st.dofs(e, k));
      for (size_t c = st.coreFirst[e]; c < st.coreFirst[e + 1]; ++c) add(st.coreDofs[c]);
    }
    graph_->insertGlobalIndices(gid(int(d)), Teuchos::ArrayView<const GO>(cols));
  }
  // A core's unknowns' rows (the chain rule's): every column of the entities at its face.
  std::map<GO, std::vector<GO>> coreRows;
  for (const auto& st : stiff)
    for (size_t e = 0; e < st.dofs.extent(0); ++e) {
      if (st.coreFirst[e] == st.coreFirst[e + 1]) continue;
      cols.clear();
      for (size_t k = 0; k < st.dofs.extent(1); ++k) cols.push_back(gid(st.dofs(e, k)));
      for (size_t c = st.coreFirst[e]; c < st.coreFirst[e + 1]; ++c) cols.push_back(gid(st.coreDofs[c]));
      for (size_t c = st.coreFirst[e]; c < st.coreFirst[e + 1]; ++c) {
        auto& row = coreRows[gid(st.coreDofs[c])];
        row.insert(row.end(), cols.begin(), cols.end());
      }
    }
  for (auto& [row, rowCols] : coreRows) {
    std::sort(rowCols.begin(), rowCols.end());
    rowCols.erase(std::unique(rowCols.begin(), rowCols.end()), rowCols.end());
    graph_->insertGlobalIndices(row, Teuchos::ArrayView<const GO>(rowCols));
  }
  if (layout_.coresOwned)  // the cores' held dofs get their unit diagonal
    for (const auto& core : cores_.records())
      for (int j = 0; j < kCoreUnknowns; ++j) {
        const GO g = gid(core.firstDof + j);
        graph_->insertGlobalIndices(g, Teuchos::ArrayView<const GO>(&g, 1));
      }
  graph_->endAssembly();
  // Each effect's dofs as local column ids of the assembled matrix.
  const auto& colMap = *graph_->getColMap();
  columnOf_.resize(layout_.size());
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
  // Rows are sorted: a binary search (G1 2x's 1.5 M look-ups took 20-30 ms
  // one by one), the whole row where it misses.
  auto find = [&](LO row, LO col) -> int {
    const auto* first = entries.data() + rowStart(row);
    const auto* last = entries.data() + rowStart(row + 1);
    const auto* at = std::lower_bound(first, last, col);
    if (at != last && *at == col) return int(at - entries.data());
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
    const size_t rows = L.rowDofs > 0 ? size_t(L.rowDofs) : n;
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
          if (supportOf[dofs(e, k)] >= 0 || k >= rows) continue;  // a held row (the identity), or no row
          // A node's 3 columns sit side by side in every row (its dofs have
          // consecutive column ids, and each row's entries are sorted).
          for (size_t j = 0; j < 3; ++j) {
            if (held & (1 << (3 * b + j))) continue;
            const int at = find(layout_.overlapLid(dofs(e, k)), columns_[i][e * n + 3 * b + j]) - int(j);
            if (o >= 0 && at != o)
              throw std::logic_error("assembly: a node's 3 columns are not side by side in a matrix row");
            o = at;
          }
          if (o < 0) o = 0;  // all 3 columns held: the bits skip them
        }
    }
    Kokkos::deep_copy(sink.rowBlock, hb);
    Kokkos::deep_copy(sink.heldColumns, hh);
    const auto& coupled = cores_.coupled(i);
    if (!coupled.empty()) {
      sink.keepSlot = Kokkos::View<int*>("tangent keep slot", ne);
      sink.kept = decltype(sink.kept)("kept tangents", coupled.size(), n, n);
      auto hk = Kokkos::create_mirror_view(sink.keepSlot);
      Kokkos::deep_copy(hk, -1);
      for (size_t slot = 0; slot < coupled.size(); ++slot) hk(coupled[slot]) = int(slot);
      Kokkos::deep_copy(sink.keepSlot, hk);
    }
  }
  constraints_.locateDiagonal(LO(ownedDofMap_->getNodeNumElements()), columnOf_, find);
  W->endAssembly();
}

RCP<FEMatrix> Assembly::createMatrix() const { return rcp(new FEMatrix(graph_)); }

void Assembly::chainRows(const Effect& e, const Matrix& values, std::vector<size_t>& rowStart,
                         std::vector<GO>& cols, std::vector<double>& vals, const std::vector<int>* entities,
                         bool residual) const {
  auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e.local().dofs);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), values);
  auto gid = [&](int dof) { return overlapDofMap_->getGlobalElement(layout_.overlapLid(dof)); };
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
      const int d = dofs(entity, j);
      if (!cores_.follows(d)) {
        if (!constraints_.held(d)) add(gid(d), v(k, j));
        continue;
      }
      const auto f = [&](int coreDof, double B) { add(gid(coreDof), v(k, j) * B); };
      if (residual) cores_.forEachFreeRow(d, f);
      else cores_.forEachFreeUnknown(d, f);
    }
    rowStart.push_back(cols.size());
  }
}

void Assembly::buildDofMaps() {
  if (cores_.empty()) {
    ownedDofMap_ = mesh_.ownedDofMap, overlapDofMap_ = mesh_.overlapDofMap;
    return;
  }
  const int nodeDofs = layout_.nodeDofs;
  const GO firstCoreGid = GO(3 * mesh_.numGlobalNodes);
  auto gid = [&](int d) { return d < nodeDofs ? 3 * mesh_.nodeGids[d / 3] + d % 3 : firstCoreGid + (d - nodeDofs); };
  const int ndof = layout_.size();
  std::vector<GO> owned, overlap(ndof);
  for (int d = 0; d < int(3 * mesh_.numOwnedNodes); ++d) owned.push_back(gid(d));
  if (layout_.coresOwned)
    for (int d = nodeDofs; d < ndof; ++d) owned.push_back(gid(d));
  for (int d = 0; d < ndof; ++d) overlap[layout_.overlapLid(d)] = gid(d);
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  ownedDofMap_ = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(owned), 0, mesh_.comm));
  overlapDofMap_ = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(overlap), 0, mesh_.comm));
}

void Assembly::rollWithCores(Vector& u, const std::vector<double>& dTheta) {
  uOverlap_->doImport(u, *importer_, Tpetra::INSERT);
  cores_.read(uOverlap_->getData());
  cores_.roll(u.getDataNonConst(), dTheta);
}

void Assembly::applyConstraints(Vector& u, double t) {
  constraints_.apply(u, t, cores_);
  if (cores_.empty()) return;
  // The face nodes follow the cores' values, which rank 0 owns.
  uOverlap_->doImport(u, *importer_, Tpetra::INSERT);
  cores_.read(uOverlap_->getData());
  cores_.placeFaceNodes(u.getDataNonConst());
}

bool Assembly::evaluate(const Vector& u, Vector* f, FEMatrix* W, const Vector* z, Vector* Kz) {
  if (bool(z) != bool(Kz) || (z && !W)) throw std::logic_error("assembly: K z needs z, Kz and the tangent W");
  Kokkos::Timer timer;
  auto phase = [&](double& seconds, double& since) {
    const double now = timer.seconds();
    seconds += now - since;
    since = now;
  };
  // Each phase writes its own rows of f and K z (node rows, held rows, the
  // cores' rows); W is exported last, after every phase has added to it.
  double since = 0;
  importState(u, z);
  phase(phases_.import, since);
  std::vector<Matrix> KzLocal;  // per effect: K z per entity (the sinks hold z per entity)
  const bool valid = launchEffects(W, z, KzLocal);
  phase(phases_.launch, since);
  scatterResiduals(f, W, Kz, KzLocal);
  phase(phases_.scatter, since);
  constrainRows(f, W);
  phase(phases_.constraints, since);
  coupleCores(f, W, Kz);
  phase(phases_.coreCoupling, since);
  if (W) W->endAssembly();
  phase(phases_.matrixExport, since);
  if (f && !valid) {
    // An inverted element: a residual Newton cannot mistake for converged.
    auto out = f->getDataNonConst();
    for (LO d = 0; d < LO(out.size()); ++d) out[d] = 1e150;
  }
  assemblySeconds_ += timer.seconds();
  return valid;
}

// u (and z) on the overlapped dofs; the cores' q; the nodes' x and u.
void Assembly::importState(const Vector& u, const Vector* z) {
  uOverlap_->doImport(u, *importer_, Tpetra::INSERT);
  auto ud = uOverlap_->getData();
  cores_.read(ud);
  auto hx = Kokkos::create_mirror_view(x_);
  auto hu = Kokkos::create_mirror_view(u_);
  for (size_t n = 0; n < mesh_.numOverlapNodes(); ++n)
    for (int i = 0; i < 3; ++i) {
      // A core's face node sits where the core puts it, whatever u holds there.
      hu(n, i) = cores_.coreOf(n) >= 0 ? cores_.follower(n).u[i] : ud[layout_.overlapLid(int(3 * n + i))];
      hx(n, i) = mesh_.X[3 * n + i] + hu(n, i);
    }
  Kokkos::deep_copy(x_, hx);
  Kokkos::deep_copy(u_, hu);
  if (z) {
    if (zOverlap_.is_null()) zOverlap_ = rcp(new Vector(overlapDofMap_));
    zOverlap_->doImport(*z, *importer_, Tpetra::INSERT);
  }
}

// Every effect's kernel. The tangent goes straight from each kernel into W's
// local CRS values (and into K z for the predictor), entity by entity. Returns
// whether every element has det F > 0 (global).
bool Assembly::launchEffects(FEMatrix* W, const Vector* z, std::vector<Matrix>& KzLocal) {
  if (W) {
    W->beginAssembly();
    W->setAllToScalar(0.0);
    const auto values = W->getLocalMatrixDevice().values;
    for (size_t i = 0; i < effects_.all.size(); ++i)
      if (effects_.all[i]->local().stiff) sinks_[i].values = values;  // the others evaluate without a sink
  }
  if (z) {
    auto zd = zOverlap_->getData();
    for (size_t i = 0; i < effects_.all.size(); ++i) {
      const auto& L = effects_.all[i]->local();
      KzLocal.emplace_back("K z", L.dofs.extent(0), L.dofs.extent(1));  // zero for entities without a tangent
      if (!L.stiff) continue;
      auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.dofs);
      Matrix zLocal("z", dofs.extent(0), dofs.extent(1));
      auto hz = Kokkos::create_mirror_view(zLocal);
      for (size_t e = 0; e < dofs.extent(0); ++e)
        for (size_t k = 0; k < dofs.extent(1); ++k) hz(e, k) = zd[layout_.overlapLid(dofs(e, k))];
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
  return globalMinJ > 0 && std::isfinite(globalMinJ);
}

// The per-entity residuals summed into the owned rows, kept unconstrained for
// the reactions and the cores' sums, and copied to f's node rows; likewise K z.
// With rigid cores the residual is also needed for the tangent alone, whose
// theta-theta entry needs the reactions at the face nodes.
void Assembly::scatterResiduals(Vector* f, FEMatrix* W, Vector* Kz, const std::vector<Matrix>& KzLocal) {
  if (f || (W && !cores_.empty())) {
    std::vector<Matrix> R;
    for (const auto& effect : effects_.all) R.push_back(effect->local().R);
    sumEntityVectors(R);
    auto ro = residual_->getData(0);
    rawOwnedResidual_.assign(ro.begin(), ro.end());
    if (f) {
      auto out = f->getDataNonConst();
      for (LO d = 0; d < LO(out.size()); ++d)
        if (layout_.assemblyDof(d) < layout_.nodeDofs) out[d] = ro[d];
    }
  }
  if (Kz) {
    // K z: summed like a residual (its cores' rows: coupleCores).
    sumEntityVectors(KzLocal);
    auto ro = residual_->getData(0);
    auto yd = Kz->getDataNonConst();
    for (LO d = 0; d < LO(yd.size()); ++d)
      if (layout_.assemblyDof(d) < layout_.nodeDofs) yd[d] = ro[d];
  }
}

// Held rows: f = 0 there, and W has the identity in row and column (the
// kernels left the held rows and columns out).
void Assembly::constrainRows(Vector* f, FEMatrix* W) {
  if (f) {
    auto out = f->getDataNonConst();
    for (LO d = 0; d < LO(out.size()); ++d)
      if (constraints_.held(layout_.assemblyDof(d))) out[d] = 0.0;
  }
  if (W) constraints_.setDiagonal(*W);
}

// The cores' part: the reactions at their face nodes, f's rows of their free
// unknowns, K z carried to their unknowns, and the chain rule in W.
void Assembly::coupleCores(Vector* f, FEMatrix* W, Vector* Kz) {
  if (f || (W && !cores_.empty())) cores_.setReactions(rawOwnedResidual_.data());
  if (f) {
    auto out = f->getDataNonConst();
    for (LO d = 0; d < LO(out.size()); ++d) {
      const int a = layout_.assemblyDof(d);
      if (a >= layout_.nodeDofs && !constraints_.held(a)) out[d] = cores_.residual(a, time_);
    }
  }
  if (Kz) {
    auto yd = Kz->getDataNonConst();
    const auto sums = cores_.rowSums(yd.getRawPtr());  // over the node rows (K z's owned sums)
    for (LO d = 0; d < LO(yd.size()); ++d) {
      const int a = layout_.assemblyDof(d) - layout_.nodeDofs;
      if (a >= 0) yd[d] = a % 6 < 4 ? sums[a / 6][a % 6] : 0.0;
    }
  }
  if (W) cores_.assembleCoupling(*W, effects_.all, sinks_, columnOf_, constraints_);
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
          for (size_t k = 0; k < dofs.extent(1); ++k) r[layout_.overlapLid(dofs(e, k))] += v(e, k);
    }
  }
  residual_->endAssembly();  // one export: shared rows added into their owners
}

void Assembly::constraintIncrement(Vector& z, double t0, double t1, bool turned) const {
  constraints_.increment(z, t0, t1, cores_, turned);
}

std::vector<std::array<double, 3>> Assembly::constraintReactions() const {
  return constraints_.reactions(rawOwnedResidual_, *mesh_.comm);
}

}  // namespace capstan
