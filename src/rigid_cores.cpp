#include "rigid_cores.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <stdexcept>

#include "constraints.hpp"
#include "scene.hpp"
#include "vec3.hpp"

namespace capstan {

RigidCores::RigidCores(const Mesh& mesh, const Scene& scene) : mesh_(mesh), steady_(scene.analysis.steady()) {
  const int nodeDofs = int(3 * mesh.numOverlapNodes());
  // Rigid cores first: their face nodes follow the core whatever other
  // support also names them.
  coreOfNode_.assign(mesh.numOverlapNodes(), -1);
  for (const auto& s : scene.supports) {
    if (!s.isCore()) continue;
    RigidCore core;
    core.name = s.name;
    core.axisPoint = s.axisPoint, core.axisDirection = s.axisDirection, core.force = s.force;
    core.torque = s.torque, core.rampTime = s.rampTime, core.torqueRampTime = s.torqueRampTime;
    core.free = {s.freeTranslation[0], s.freeTranslation[1], s.freeTranslation[2], s.rotation == SupportSpec::Rotation::Free};
    core.firstDof = nodeDofs + kCoreUnknowns * int(cores_.size());
    double radius = 0;  // the largest over the ranks: the same on any number of ranks
    for (int n : mesh.faceNodes(s.face)) {
      if (coreOfNode_[n] < 0) coreOfNode_[n] = int(cores_.size());
      radius = std::max(radius, distanceFromAxis(core, &mesh.X[3 * n]));
    }
    Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_MAX, radius, Teuchos::outArg(core.radius));
    if (!(core.radius > 0)) core.radius = 1;  // a face on its axis carries no torque
    cores_.push_back(core);
  }
  layout_ = DofLayout(mesh, cores_.size());
}

double RigidCores::distanceFromAxis(const RigidCore& core, const double* X) {
  const Vec3 r = sub({X[0], X[1], X[2]}, core.axisPoint);
  return norm(sub(r, scale(core.axisDirection, dot(r, core.axisDirection))));
}

int RigidCores::find(const std::string& name) const {
  for (size_t c = 0; c < cores_.size(); ++c)
    if (cores_[c].name == name) return int(c);
  return -1;
}

void RigidCores::read(const Teuchos::ArrayRCP<const double>& ud) {
  for (auto& core : cores_) {
    for (int i = 0; i < 3; ++i) core.translation[i] = ud[layout_.overlapLid(core.firstDof + i)];
    const double q3 = ud[layout_.overlapLid(core.firstDof + 3)];
    core.rotation = steady_ ? 0.0 : q3;
    core.angularVelocity = steady_ ? q3 : core.angularVelocity;
  }
  followers_.resize(mesh_.numOverlapNodes());
  for (size_t n = 0; n < coreOfNode_.size(); ++n) {
    if (coreOfNode_[n] < 0) continue;
    const auto& core = cores_[coreOfNode_[n]];
    followers_[n] = kernels::coreFollower(core.axisPoint.data(), core.axisDirection.data(), core.translation.data(),
                                          core.rotation, &mesh_.X[3 * n]);
  }
}

void RigidCores::placeFaceNodes(const Teuchos::ArrayRCP<double>& data) const {
  for (size_t n = 0; n < mesh_.numOwnedNodes; ++n)
    if (coreOfNode_[n] >= 0)
      for (int i = 0; i < 3; ++i) data[3 * n + i] = followers_[n].u[i];
}

void RigidCores::roll(const Teuchos::ArrayRCP<double>& data, const std::vector<double>& dTheta) const {
  for (size_t c = 0; c < cores_.size(); ++c) {
    const auto& core = cores_[c];
    if (dTheta[c] == 0) continue;
    for (size_t n = 0; n < mesh_.numOwnedNodes; ++n) {
      double r[3], turned[3];
      for (int i = 0; i < 3; ++i)
        r[i] = mesh_.X[3 * n + i] + data[3 * n + i] - core.axisPoint[i] - core.translation[i];
      kernels::rotateAboutAxis(core.axisDirection.data(), dTheta[c], r, turned);
      for (int i = 0; i < 3; ++i) data[3 * n + i] += turned[i] - r[i];
    }
    if (layout_.coresOwned) data[3 * mesh_.numOwnedNodes + kCoreUnknowns * c + 3] += dTheta[c];
  }
}

void RigidCores::translate(const Teuchos::ArrayRCP<double>& data, size_t c, const std::array<double, 3>& delta) const {
  for (size_t n = 0; n < mesh_.numOwnedNodes; ++n)
    for (int i = 0; i < 3; ++i) data[3 * n + i] += delta[i];
  if (layout_.coresOwned)
    for (int i = 0; i < 3; ++i) data[3 * mesh_.numOwnedNodes + kCoreUnknowns * c + i] += delta[i];
}

std::vector<std::array<double, 5>> RigidCores::sums(const double* v) const {
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

std::vector<std::array<double, 4>> RigidCores::rowSums(const double* v) const {
  const auto s = sums(v);
  std::vector<std::array<double, 4>> out(s.size());
  for (size_t c = 0; c < s.size(); ++c) out[c] = {s[c][0], s[c][1], s[c][2], cores_[c].torqueRow(s[c][3])};
  return out;
}

void RigidCores::setReactions(const double* ownedResidual) {
  const auto s = sums(ownedResidual);
  for (size_t c = 0; c < cores_.size(); ++c) {
    for (int i = 0; i < 3; ++i) cores_[c].forceOnBody[i] = s[c][i];
    cores_[c].torqueOnBody = s[c][3];
    cores_[c].geometric = steady_ ? 0.0 : s[c][4];  // steady: b does not change with omega
  }
}

void RigidCores::findCoupling(const std::vector<std::unique_ptr<Effect>>& effects) {
  coupled_.assign(effects.size(), {});
  rowEntries_.assign(cores_.size(), 0);
  if (cores_.empty()) return;
  std::vector<std::vector<char>> seen(cores_.size(), std::vector<char>(layout_.size(), 0));
  for (size_t i = 0; i < effects.size(); ++i) {
    if (!effects[i]->local().stiff) continue;  // no stiffness, no graph entries
    auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), effects[i]->local().dofs);
    for (size_t e = 0; e < dofs.extent(0); ++e) {
      bool touches = false;
      for (size_t k = 0; k < dofs.extent(1); ++k) {
        const int c = dofs(e, k) < layout_.nodeDofs ? coreOfNode_[dofs(e, k) / 3] : -1;
        if (c < 0) continue;
        touches = true;
        for (size_t l = 0; l < dofs.extent(1); ++l) seen[c][dofs(e, l)] = 1;
      }
      if (touches) coupled_[i].push_back(int(e));
    }
  }
  for (size_t c = 0; c < cores_.size(); ++c)
    rowEntries_[c] = std::count(seen[c].begin(), seen[c].end(), char(1)) + kCoreUnknowns * cores_.size();
}

void RigidCores::assembleCoupling(FEMatrix& W, const std::vector<std::unique_ptr<Effect>>& effects,
                                  const std::vector<TangentSink>& sinks, const std::vector<LO>& columnOf,
                                  const Constraints& constraints) {
  if (cores_.empty()) return;
  // Chain rule for u_s = T + (R(theta) - I)(X_s - A), B_s = du_s/dq = [I | b_s]: K(k, s) -> K(k, q)
  // B_s, K(s, l) -> B_s^T K(s, l), K(s, s') -> B_s^T K B_s', and sum_s R_s . w_s to (theta, theta),
  // from d(sum_s R_s . b_s)/dtheta; per element in dense arrays, then row by row.
  const auto& supportOf = constraints.supportOf;
  const size_t nc = cores_.size(), nq = 4 * nc;
  const int nodeDofs = layout_.nodeDofs;
  // Scratch kept between assemblies (no allocation per evaluation).
  auto& toCore = coupling_.toCore;
  auto& fromCore = coupling_.fromCore;
  auto& coreCore = coupling_.coreCore;
  auto& touched = coupling_.touched;
  toCore.assign(nq * nodeDofs, 0.0), fromCore.assign(nq * nodeDofs, 0.0), coreCore.assign(nq * nq, 0.0);
  touched.assign(nodeDofs, 0);
  for (size_t i = 0; i < effects.size(); ++i) {
    const auto& L = effects[i]->local();
    if (!L.stiff || coupled_[i].empty()) continue;
    const auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.dofs);
    const auto K = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), sinks[i].kept);
    const auto active = activeOnHost(L);
    const int n = int(dofs.extent(1));
    std::vector<std::array<double, 4>> B(n), C(n);  // row and column chains
    std::vector<int> coreOf(n);
    for (size_t slot = 0; slot < coupled_[i].size(); ++slot) {
      const int e = coupled_[i][slot];
      if (active.size() && !active(e)) continue;
      for (int k = 0; k < n; ++k) {
        const int d = dofs(e, k), c = d < layout_.nodeDofs ? coreOfNode_[d / 3] : -1;
        coreOf[k] = c;
        if (c >= 0) B[k] = chain(d), C[k] = chainColumn(d);
      }
      for (int k = 0; k < n; ++k)
        for (int l = 0; l < n; ++l) {
          const int ck = coreOf[k], cl = coreOf[l], dk = dofs(e, k), dl = dofs(e, l);
          const double Kkl = K(slot, k, l);
          if ((ck < 0 && cl < 0) || Kkl == 0) continue;
          if (ck < 0) {
            if (supportOf[dk] >= 0) continue;
            touched[dk] = 1;
            for (int j = 0; j < 4; ++j) toCore[(4 * cl + j) * nodeDofs + dk] += Kkl * C[l][j];
          } else if (cl < 0) {
            if (supportOf[dl] >= 0) continue;
            touched[dl] = 1;
            for (int j = 0; j < 4; ++j) fromCore[(4 * ck + j) * nodeDofs + dl] += B[k][j] * Kkl;
          } else {
            for (int a = 0; a < 4; ++a)
              for (int b = 0; b < 4; ++b) coreCore[(4 * ck + a) * nq + 4 * cl + b] += B[k][a] * Kkl * C[l][b];
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
  for (int d = 0; d < nodeDofs; ++d) {
    if (!touched[d]) continue;
    cols.clear(), vals.clear();
    for (size_t q = 0; q < nq; ++q)
      if (freeCoreDof(q) && toCore[q * nodeDofs + d] != 0)
        cols.push_back(columnOf[coreDof(q)]), vals.push_back(toCore[q * nodeDofs + d]);
    if (!cols.empty()) add(layout_.overlapLid(d));
  }
  for (size_t q = 0; q < nq; ++q) {
    if (!freeCoreDof(q)) continue;
    cols.clear(), vals.clear();
    if (q % 4 == 3 && cores_[q / 4].holding()) {  // steady rolling's start: omega - held = 0
      if (layout_.coresOwned) cols.push_back(columnOf[coreDof(q)]), vals.push_back(1.0), add(layout_.overlapLid(coreDof(q)));
      continue;
    }
    for (int d = 0; d < nodeDofs; ++d)
      if (touched[d] && fromCore[q * nodeDofs + d] != 0)
        cols.push_back(columnOf[d]), vals.push_back(fromCore[q * nodeDofs + d]);
    for (size_t p = 0; p < nq; ++p) {
      double v = coreCore[q * nq + p];
      // The reactions are global sums: rank 0 adds the geometric term once.
      if (p == q && q % 4 == 3 && layout_.coresOwned) v += cores_[q / 4].geometric;
      if (freeCoreDof(p) && v != 0) cols.push_back(columnOf[coreDof(p)]), vals.push_back(v);
    }
    if (q % 4 == 3)  // the torque balance as the residual writes it: over the core's radius
      for (double& v : vals) v = cores_[q / 4].torqueRow(v);
    if (!cols.empty()) add(layout_.overlapLid(coreDof(q)));
  }
}

}  // namespace capstan
