#include "assembly.hpp"

#include <Kokkos_Timer.hpp>
#include <Teuchos_CommHelpers.hpp>

#include <algorithm>
#include <set>

namespace capstan {

namespace {
// An effect's active flags on the host (empty: every entity is active).
Kokkos::View<int*>::HostMirror activeOnHost(const LocalSystem& L) {
  return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.active);
}
}  // namespace

Assembly::Assembly(const Mesh& mesh, const Scene& scene) : mesh_(mesh) {
  // Effects the scene calls for, and nothing else.
  const double epsSolve =
      std::max(scene.pressurePenalty, scene.solver.get<double>("Minimum Solve Penalty") / scene.c);
  auto bricks = std::make_unique<BrickEffect>(mesh, scene.c, epsSolve,
                                              scene.solver.get<double>("Volume Tolerance"));
  bricks_ = bricks.get();
  effects_.push_back(std::move(bricks));
  const size_t ndof = 3 * mesh.numOverlapNodes();
  constraints_.supportOf.assign(ndof, -1);
  constraints_.velocity.assign(ndof, 0.0);
  for (const auto& s : scene.supports) {
    if (s.type == "Foundation") {
      auto f = std::make_unique<FoundationEffect>("foundation:" + s.name, mesh, s.face, s.stiffness,
                                                  s.components);
      foundations_.push_back(f.get());
      effects_.push_back(std::move(f));
      continue;
    }
    // Fixed, Roller, Displacement: the first support in the scene that holds a
    // dof owns it (and its reaction).
    const int id = int(constraints_.supportNames.size());
    constraints_.supportNames.push_back(s.name);
    for (int n : mesh.faceNodes(s.face))
      for (int i = 0; i < 3; ++i) {
        if (!s.components[i] || constraints_.supportOf[3 * n + i] >= 0) continue;
        constraints_.supportOf[3 * n + i] = id;
        constraints_.velocity[3 * n + i] = s.type == "Displacement" ? s.velocity[i] : 0.0;
      }
  }

  if (scene.bodyForce != std::array<double, 3>{0, 0, 0})
    effects_.push_back(std::make_unique<BodyForceEffect>(mesh, scene.bodyForce, scene.steps * scene.stepSize));

  for (const auto& c : scene.capstans) {
    ContactEffect::Settings set;
    set.radius = c.radius;
    set.axisPoint = c.axisPoint;
    set.axisDirection = c.axisDirection;
    set.velocity = c.velocity;
    set.penalty = c.penalty;
    set.exact = c.method == "Augmented Lagrangian";
    set.minimumSolvePenalty = c.minimumSolvePenalty;
    set.c = scene.c;
    set.tolerance = c.penetrationTolerance;
    set.maxAugmentations = c.maxAugmentations;
    set.rule = c.quadrature;
    // Candidate faces, each once even if two named faces share one. Every
    // capstan's faces also get an index in the union of all candidate faces
    // (the contact-face grid of fields.h5).
    std::vector<int> quads;
    std::set<std::array<int, 4>> mine;
    contactFaceOf_.emplace_back();
    for (const auto& name : c.contactFaces) {
      const auto& q = mesh.faces.at(name);
      for (size_t f = 0; f < q.size(); f += 4) {
        std::array<int, 4> key{q[f], q[f + 1], q[f + 2], q[f + 3]};
        std::sort(key.begin(), key.end());
        if (!mine.insert(key).second) continue;
        auto [it, fresh] = contactFaceIndex_.insert({key, int(contactFaceIndex_.size())});
        if (fresh) contactFaceNodes_.insert(contactFaceNodes_.end(), q.begin() + f, q.begin() + f + 4);
        quads.insert(quads.end(), q.begin() + f, q.begin() + f + 4);
        contactFaceOf_.back().push_back(it->second);
      }
    }
    auto effect = std::make_unique<ContactEffect>("contact:" + c.name, mesh, quads, set);
    contacts_.push_back(effect.get());
    frictions_.push_back(nullptr);
    const ContactEffect& contact = *effect;
    effects_.push_back(std::move(effect));
    if (c.frictionLaw == "None") continue;  // no friction kernel at all
    FrictionEffect::Settings fs;
    fs.law = c.frictionLaw == "Tanh"     ? kernels::FrictionLaw::Tanh
             : c.frictionLaw == "Arctan" ? kernels::FrictionLaw::Arctan
                                         : kernels::FrictionLaw::Coulomb;
    fs.mu = c.frictionCoefficient;
    fs.regularization = c.regularization;
    fs.tangentPenalty = c.tangentialPenalty;
    fs.angularVelocity = c.angularVelocity;
    auto friction = std::make_unique<FrictionEffect>("friction:" + c.name, mesh, quads, contact, fs);
    frictions_.back() = friction.get();
    effects_.push_back(std::move(friction));
  }

  // Graph from every effect's entities: built once, fixed sparsity.
  importer_ = rcp(new Tpetra::Import<>(mesh.ownedDofMap, mesh.overlapDofMap));
  // Global column ids: the owner of a shared row also receives columns that only
  // other ranks' elements touch, so the column map is built by Tpetra after the
  // export, not taken from this rank's nodes.
  graph_ = rcp(new FEGraph(mesh.ownedDofMap, mesh.overlapDofMap, 81, importer_));
  graph_->beginAssembly();
  const auto& overlap = *mesh.overlapDofMap;
  for (const auto& effect : effects_) {
    if (effect->local().K.extent(0) == 0) continue;  // no stiffness, no graph entries
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effect->local().dofs);
    std::vector<GO> cols(dofs.extent(1));
    for (size_t e = 0; e < dofs.extent(0); ++e) {
      for (size_t k = 0; k < cols.size(); ++k) cols[k] = overlap.getGlobalElement(dofs(e, k));
      for (GO row : cols) graph_->insertGlobalIndices(row, Teuchos::ArrayView<const GO>(cols));
    }
  }
  graph_->endAssembly();
  // Each effect's dofs as local column ids of the assembled matrix.
  const auto& colMap = *graph_->getColMap();
  for (const auto& effect : effects_) {
    if (effect->local().K.extent(0) == 0) {
      columns_.emplace_back();
      continue;
    }
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effect->local().dofs);
    std::vector<LO> cols(dofs.size());
    for (size_t e = 0; e < dofs.extent(0); ++e)
      for (size_t k = 0; k < dofs.extent(1); ++k)
        cols[e * dofs.extent(1) + k] = colMap.getLocalElement(overlap.getGlobalElement(dofs(e, k)));
    columns_.push_back(std::move(cols));
  }
  findEntryOffsets();
  uOverlap_ = rcp(new Vector(mesh.overlapDofMap));
  residual_ = rcp(new Tpetra::FEMultiVector<>(mesh.ownedDofMap, importer_, 1));
  x_ = NodalVectors("x", mesh.numOverlapNodes());
  u_ = NodalVectors("u", mesh.numOverlapNodes());
}

void Assembly::findEntryOffsets() {
  // The owned-plus-shared matrix is active between beginAssembly and endAssembly;
  // its local rows are the overlapped dof ids the effects use.
  auto W = createMatrix();
  W->beginAssembly();
  const auto local = W->getLocalMatrixHost();
  const auto rowStart = local.graph.row_map;
  const auto entries = local.graph.entries;
  auto find = [&](LO row, LO col) -> long {
    for (auto j = rowStart(row); j < rowStart(row + 1); ++j)
      if (entries(j) == col) return long(j);
    throw std::logic_error("assembly: an element entry is missing from the matrix graph");
  };
  const auto& supportOf = constraints_.supportOf;
  for (size_t i = 0; i < effects_.size(); ++i) {
    const auto& L = effects_[i]->local();
    if (L.K.extent(0) == 0) {
      entryOffsets_.emplace_back();
      continue;
    }
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.dofs);
    const size_t n = dofs.extent(1);
    Kokkos::View<long***, Kokkos::LayoutRight> offsets("entry offsets", dofs.extent(0), n, n);
    auto h = Kokkos::create_mirror_view(offsets);
    for (size_t e = 0; e < dofs.extent(0); ++e)
      for (size_t k = 0; k < n; ++k)
        for (size_t l = 0; l < n; ++l)
          h(e, k, l) = supportOf[dofs(e, k)] >= 0 || supportOf[dofs(e, l)] >= 0
                           ? -1
                           : find(dofs(e, k), columns_[i][e * n + l]);
    Kokkos::deep_copy(offsets, h);
    entryOffsets_.push_back(offsets);
  }
  const auto& colMap = *W->getColMap();
  const auto& overlap = *mesh_.overlapDofMap;
  std::vector<long> diagonal;
  for (LO d = 0; d < LO(3 * mesh_.numOwnedNodes); ++d)
    if (supportOf[d] >= 0) diagonal.push_back(find(d, colMap.getLocalElement(overlap.getGlobalElement(d))));
  constrainedDiagonal_ = Kokkos::View<long*>("constrained diagonal", diagonal.size());
  auto hd = Kokkos::create_mirror_view(constrainedDiagonal_);
  for (size_t j = 0; j < diagonal.size(); ++j) hd(j) = diagonal[j];
  Kokkos::deep_copy(constrainedDiagonal_, hd);
  W->endAssembly();
}

RCP<FEMatrix> Assembly::createMatrix() const { return rcp(new FEMatrix(graph_)); }

void Assembly::applyConstraints(Vector& u, double t) const {
  auto data = u.getDataNonConst();
  for (LO d = 0; d < LO(data.size()); ++d)
    if (constraints_.supportOf[d] >= 0) data[d] = constraints_.velocity[d] * t;
}

bool Assembly::evaluate(const Vector& u, Vector* f, FEMatrix* W) {
  Kokkos::Timer timer;
  uOverlap_->doImport(u, *importer_, Tpetra::INSERT);
  {
    auto ud = uOverlap_->getData();
    auto hx = Kokkos::create_mirror_view(x_);
    auto hu = Kokkos::create_mirror_view(u_);
    for (size_t n = 0; n < mesh_.numOverlapNodes(); ++n)
      for (int i = 0; i < 3; ++i) {
        hu(n, i) = ud[3 * n + i];
        hx(n, i) = mesh_.X[3 * n + i] + ud[3 * n + i];
      }
    Kokkos::deep_copy(x_, hx);
    Kokkos::deep_copy(u_, hu);
  }
  const bool tangent = W != nullptr;
  for (auto& effect : effects_) effect->evaluate(x_, u_, tangent);

  double minJ = 1e300;
  auto elementMinJ = bricks_->minJacobian;
  Kokkos::parallel_reduce(
      "min J", Kokkos::RangePolicy<ExecSpace>(0, elementMinJ.extent(0)),
      KOKKOS_LAMBDA(int e, double& m) { m = elementMinJ(e) < m ? elementMinJ(e) : m; },
      Kokkos::Min<double>(minJ));
  double globalMinJ = minJ;
  Teuchos::reduceAll(*mesh_.comm, Teuchos::REDUCE_MIN, minJ, Teuchos::outArg(globalMinJ));
  const bool valid = globalMinJ > 0 && std::isfinite(globalMinJ);
  const auto& supportOf = constraints_.supportOf;

  if (f) {
    std::vector<Matrix> R;
    for (const auto& effect : effects_) R.push_back(effect->local().R);
    sumEntityVectors(R);
    auto ro = residual_->getData(0);
    rawOwnedResidual_.assign(ro.begin(), ro.end());
    auto out = f->getDataNonConst();
    for (LO d = 0; d < LO(out.size()); ++d)
      out[d] = !valid ? 1e150 : supportOf[d] >= 0 ? 0.0 : ro[d];
  }

  if (W) {
    // Element matrices are added straight into the local CRS values at their
    // precomputed offsets, in a parallel loop (atomic: entities share entries).
    W->beginAssembly();
    W->setAllToScalar(0.0);
    const auto values = W->getLocalMatrixDevice().values;
    for (size_t i = 0; i < effects_.size(); ++i) {
      const auto& L = effects_[i]->local();
      if (L.K.extent(0) == 0) continue;
      const auto K = L.K;
      const auto active = L.active;
      const auto offsets = entryOffsets_[i];
      const int n = int(K.extent(1));
      Kokkos::parallel_for(
          "scatter", Kokkos::RangePolicy<ExecSpace>(0, K.extent(0)), KOKKOS_LAMBDA(int e) {
            if (active.extent(0) && !active(e)) return;
            for (int k = 0; k < n; ++k)
              for (int l = 0; l < n; ++l) {
                const long o = offsets(e, k, l);
                if (o >= 0) Kokkos::atomic_add(&values(o), K(e, k, l));
              }
          });
    }
    const auto diagonal = constrainedDiagonal_;
    Kokkos::parallel_for(
        "constrained diagonal", Kokkos::RangePolicy<ExecSpace>(0, diagonal.extent(0)),
        KOKKOS_LAMBDA(int j) { values(diagonal(j)) = 1.0; });
    Kokkos::fence();
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
    for (size_t i = 0; i < effects_.size(); ++i) {
      auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effects_[i]->local().dofs);
      auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), values[i]);
      auto active = activeOnHost(effects_[i]->local());
      for (size_t e = 0; e < dofs.extent(0); ++e)
        if (!active.size() || active(e))
          for (size_t k = 0; k < dofs.extent(1); ++k) r[dofs(e, k)] += v(e, k);
    }
  }
  residual_->endAssembly();  // one export: shared rows added into their owners
}

void Assembly::tangentAction(const Vector& z, Vector& y) {
  uOverlap_->doImport(z, *importer_, Tpetra::INSERT);
  auto zd = uOverlap_->getData();
  std::vector<Matrix> Kz;
  for (const auto& effect : effects_) {
    const auto& L = effect->local();
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.dofs);
    auto K = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.K);
    Matrix out("K z", dofs.extent(0), dofs.extent(1));
    auto ho = Kokkos::create_mirror_view(out);
    auto active = activeOnHost(L);
    const bool stiff = L.K.extent(0) > 0;
    for (size_t e = 0; e < dofs.extent(0); ++e)
      for (size_t k = 0; k < dofs.extent(1); ++k) {
        double s = 0;
        if (!stiff || (active.size() && !active(e))) {
          ho(e, k) = 0;
          continue;
        }
        for (size_t l = 0; l < dofs.extent(1); ++l) s += K(e, k, l) * zd[dofs(e, l)];
        ho(e, k) = s;
      }
    Kokkos::deep_copy(out, ho);
    Kz.push_back(out);
  }
  sumEntityVectors(Kz);
  auto ro = residual_->getData(0);
  auto yd = y.getDataNonConst();
  for (LO d = 0; d < LO(yd.size()); ++d) yd[d] = ro[d];
}

void Assembly::constraintIncrement(Vector& z, double t0, double t1) const {
  auto data = z.getDataNonConst();
  for (LO d = 0; d < LO(data.size()); ++d)
    data[d] = constraints_.supportOf[d] >= 0 ? constraints_.velocity[d] * (t1 - t0) : 0.0;
}

std::vector<std::array<double, 3>> Assembly::constraintReactions() const {
  const size_t ns = constraints_.supportNames.size();
  std::vector<double> local(3 * ns, 0.0), global(3 * ns, 0.0);
  for (size_t d = 0; d < rawOwnedResidual_.size(); ++d)
    if (constraints_.supportOf[d] >= 0) local[3 * constraints_.supportOf[d] + d % 3] += rawOwnedResidual_[d];
  if (ns)
    Teuchos::reduceAll(*mesh_.comm, Teuchos::REDUCE_SUM, int(3 * ns), local.data(), global.data());
  std::vector<std::array<double, 3>> out(ns);
  for (size_t s = 0; s < ns; ++s) out[s] = {global[3 * s], global[3 * s + 1], global[3 * s + 2]};
  return out;
}

}  // namespace capstan
