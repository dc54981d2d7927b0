#include "pressure_step.hpp"

#include <Kokkos_Timer.hpp>

#include <cmath>

namespace capstan {

PressureStep::PressureStep(Assembly& assembly) : assembly_(assembly) {
  const BrickEffect& bricks = assembly_.bricks();
  const size_t ne = bricks.pressureAnchor.extent(0);
  auto comm = assembly_.dofMap()->getComm();
  elementMap_ = rcp(new Map(Tpetra::global_size_t(Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid()), ne,
                            GO(0), comm));
  weight_ = rcp(new Vector(elementMap_));
  schurInverse_ = rcp(new Vector(elementMap_));
  scratch_ = rcp(new Vector(assembly_.dofMap()));
  residualP_ = rcp(new Vector(elementMap_));
  // G^T's structure: each element's free dofs (a rigid core's unknowns for
  // its face nodes). Values come with each solve.
  Matrix ones("ones", ne, 24);
  Kokkos::deep_copy(ones, 1.0);
  assembly_.chainRows(bricks, ones, rowStart_, cols_, vals_);
  size_t longest = 1;
  for (size_t e = 0; e < ne; ++e) longest = std::max(longest, rowStart_[e + 1] - rowStart_[e]);
  gradient_ = rcp(new CrsMatrix(elementMap_, longest));
  for (size_t e = 0; e < ne; ++e)
    if (rowStart_[e + 1] > rowStart_[e])
      gradient_->insertGlobalValues(elementMap_->getGlobalElement(LO(e)), row(cols_, e), row(vals_, e));
  gradient_->fillComplete(assembly_.dofMap(), elementMap_);
}

PressureStep::Block PressureStep::newBlock() const {
  return {rcp(new Vector(assembly_.dofMap())), rcp(new Vector(elementMap_))};
}

void PressureStep::fillVolumeGradient() {
  const BrickEffect& bricks = assembly_.bricks();
  bricks.volumeGradients(assembly_.positions(), g_);
  assembly_.chainRows(bricks, g_, rowStart_, cols_, vals_);
  auto g = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g_);
  auto V = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.referenceVolume);
  const double eps = bricks.solvePenalty();
  auto w = weight_->getDataNonConst();
  auto sInv = schurInverse_->getDataNonConst();
  gradient_->resumeFill();
  for (size_t e = 0; e < g.extent(0); ++e) {
    double norm2 = 0;
    for (int k = 0; k < 24; ++k) norm2 += g(e, k) * g(e, k);
    // An element with no free dof (all its nodes held) has no constraint row:
    // weight 0 keeps its equation and its dp at 0.
    const bool empty = rowStart_[e + 1] == rowStart_[e];
    w[e] = empty ? 0.0 : std::sqrt(norm2) / (eps * V(e));
    sInv[e] = empty ? 0.0 : 1 / (w[e] * eps * V(e));
    if (!empty) gradient_->replaceGlobalValues(elementMap_->getGlobalElement(LO(e)), row(cols_, e), row(vals_, e));
  }
  gradient_->fillComplete(assembly_.dofMap(), elementMap_);
}

void PressureStep::applySystem(const CrsMatrix& K, const Block& x, Block& y) const {
  // y_u = K x_u - G x_p
  K.apply(*x.u, *y.u);
  gradient_->apply(*x.p, *y.u, Teuchos::TRANS, -1.0, 1.0);
  // y_p = w .* (G^T x_u)
  gradient_->apply(*x.u, *y.p);
  y.p->elementWiseMultiply(1.0, *weight_, *y.p, 0.0);
}

void PressureStep::applyPreconditioner(const Inverse& Kinv, const Block& r, Block& z) {
  // z_p = (w eps M)^-1 r_p, then z_u = K~^-1 (r_u + G z_p)
  z.p->elementWiseMultiply(1.0, *schurInverse_, *r.p, 0.0);
  scratch_->update(1.0, *r.u, 0.0);
  gradient_->apply(*z.p, *scratch_, Teuchos::TRANS, 1.0, 1.0);
  Kinv(*scratch_, *z.u);
}

double PressureStep::volumeError(const Vector& rp) const {
  const BrickEffect& bricks = assembly_.bricks();
  auto V = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.referenceVolume);
  auto r = rp.getData();
  auto w = weight_->getData();
  double local = 0, global = 0;
  for (size_t e = 0; e < V.extent(0); ++e)
    if (w[e] > 0) local = std::max(local, std::fabs(r[e]) / (w[e] * V(e)));
  Teuchos::reduceAll(*elementMap_->getComm(), Teuchos::REDUCE_MAX, local, Teuchos::outArg(global));
  return global;
}

PressureStep::Result PressureStep::solve(const CrsMatrix& K, const Inverse& Kinv, const Vector& f, double tolerance,
                                         double volumeTarget, int maxIterations, Vector& dx,
                                         Kokkos::View<double*> dp) {
  Kokkos::Timer timer;
  fillVolumeGradient();
  const BrickEffect& bricks = assembly_.bricks();
  // Right-hand side: (-R, w .* (V - v)).
  Block rhs = newBlock();
  rhs.u->update(-1.0, f, 0.0);
  {
    auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.volume);
    auto V = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.referenceVolume);
    auto r = rhs.p->getDataNonConst();
    auto w = weight_->getData();
    for (size_t e = 0; e < v.extent(0); ++e) r[e] = w[e] * (V(e) - v(e));
  }
  Block x = newBlock(), work = newBlock(), z = newBlock();
  const double beta0 = std::sqrt(dot(rhs, rhs));
  Result result;
  // Done: the volume error left meets the target, or the residual is reduced
  // by `tolerance` and the volume error is far from the target anyway. Going
  // on past `tolerance` is worth at most as many iterations again (+10): a
  // target below what round-off allows must not run to maxIterations.
  int reachedAt = -1;  // iterations when the residual first met `tolerance`
  const auto done = [&](double res, double volumeLeft) {
    if (res > tolerance * beta0) return volumeTarget > 0 && volumeLeft <= volumeTarget;
    if (reachedAt < 0) reachedAt = result.iterations;
    return volumeTarget <= 0 || volumeLeft <= volumeTarget || volumeLeft > 10 * volumeTarget ||
           result.iterations >= 2 * reachedAt + 10;
  };
  double volumeLeft = volumeTarget > 0 ? volumeError(*rhs.p) : 0.0;
  const int m = std::max(1, std::min(maxIterations, 300));  // restart length
  if (basis_.empty()) basis_.push_back(newBlock());
  double beta = beta0;
  Block& r = work;
  update(1.0, rhs, 0.0, r);
  while (!done(beta, volumeLeft) && result.iterations < maxIterations) {
    // One GMRES(m) cycle from the residual r (Givens rotations on the
    // Hessenberg matrix H, modified Gram-Schmidt).
    std::vector<double> H((m + 1) * m, 0.0), cs(m), sn(m), s(m + 1, 0.0);
    auto h = [&](int i, int j) -> double& { return H[i * m + j]; };
    update(1 / beta, r, 0.0, basis_[0]);
    residualP_->update(1.0, *basis_[0].p, 0.0);
    s[0] = beta;
    int k = 0;  // columns built
    double res = beta;
    while (k < m && result.iterations < maxIterations) {
      if (basis_.size() < size_t(k + 2)) basis_.push_back(newBlock());  // allocated as the cycle needs
      applyPreconditioner(Kinv, basis_[k], z);
      Block& w = basis_[k + 1];
      applySystem(K, z, w);
      for (int i = 0; i <= k; ++i) {
        h(i, k) = dot(w, basis_[i]);
        update(-h(i, k), basis_[i], 1.0, w);
      }
      h(k + 1, k) = std::sqrt(dot(w, w));
      if (h(k + 1, k) > 0) update(0.0, w, 1 / h(k + 1, k), w);
      for (int i = 0; i < k; ++i) {
        const double a = h(i, k), b = h(i + 1, k);
        h(i, k) = cs[i] * a + sn[i] * b;
        h(i + 1, k) = -sn[i] * a + cs[i] * b;
      }
      const double a = h(k, k), b = h(k + 1, k), d = std::hypot(a, b);
      cs[k] = d > 0 ? a / d : 1.0, sn[k] = d > 0 ? b / d : 0.0;
      h(k, k) = d, h(k + 1, k) = 0;
      s[k + 1] = -sn[k] * s[k];
      s[k] = cs[k] * s[k];
      res = std::fabs(s[k + 1]);
      // The volume error in GMRES's residual b - A x_k = s_{k+1} u_k, where
      // u_k = V_{k+1} Q_k^T e_{k+1} (Q_k: the rotations so far) follows
      // u_k = -sn_k u_{k-1} + cs_k v_{k+1}, u_{-1} = v_0: one update of its
      // constraint block per iteration.
      if (volumeTarget > 0) {
        residualP_->update(cs[k], *basis_[k + 1].p, -sn[k]);
        volumeLeft = std::fabs(s[k + 1]) * volumeError(*residualP_);
      }
      ++k, ++result.iterations;
      if (done(res, volumeLeft) || b == 0) break;
    }
    // x += P^-1 (basis y), y = H^-1 s (upper triangular after the rotations)
    std::vector<double> y(k, 0.0);
    for (int i = k - 1; i >= 0; --i) {
      double t = s[i];
      for (int j = i + 1; j < k; ++j) t -= h(i, j) * y[j];
      y[i] = h(i, i) != 0 ? t / h(i, i) : 0.0;
    }
    r.u->putScalar(0.0), r.p->putScalar(0.0);
    for (int i = 0; i < k; ++i) update(y[i], basis_[i], 1.0, r);
    applyPreconditioner(Kinv, r, z);
    update(1.0, z, 1.0, x);
    // The true residual, for the next cycle and the figure reported.
    applySystem(K, x, r);
    update(1.0, rhs, -1.0, r);
    const double trueRes = std::sqrt(dot(r, r));
    const bool progress = trueRes < beta;
    beta = trueRes;
    if (volumeTarget > 0) volumeLeft = volumeError(*r.p);
    if (!progress) break;  // stagnated: keep what there is (the loop checks the outcome)
  }
  result.reduction = beta0 > 0 ? beta / beta0 : 0.0;
  result.volumeResidual = volumeError(*r.p);
  // Held dofs stay where they are (K's identity rows would keep them at ~0
  // anyway; the preconditioner need not).
  dx.update(1.0, *x.u, 0.0);
  {
    auto d = dx.getDataNonConst();
    for (LO i = 0; i < LO(dx.getLocalLength()); ++i)
      if (assembly_.ownedConstrained(i)) d[i] = 0;
  }
  auto hp = Kokkos::create_mirror_view(dp);
  auto xp = x.p->getData();
  for (size_t e = 0; e < hp.extent(0); ++e) hp(e) = xp[e];
  Kokkos::deep_copy(dp, hp);
  seconds_ += timer.seconds();
  return result;
}

}  // namespace capstan
