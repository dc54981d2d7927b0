#include "pressure_step.hpp"

#include <Kokkos_Timer.hpp>
#include <TpetraExt_MatrixMatrix.hpp>

#include <algorithm>
#include <cmath>

namespace capstan {

namespace {
// S^-1 ~ (eps M)^-1 + kLaplacianWeight L^-1, L^-1 by kLaplacianIterations of
// CG: the fastest weight and count measured on G1 4x; a larger weight leaves a
// larger nonlinear remainder per pass (docs/performance.md, "Defaults and why"
// and "The Laplacian's inverse").
constexpr double kLaplacianWeight = 0.15;
constexpr int kLaplacianIterations = 30;
}  // namespace

PressureStep::PressureStep(Assembly& assembly, Schur schur, Preconditioner preconditioner)
    : assembly_(assembly), effectRows_(assembly.effects().size()), schur_(schur), preconditioner_(preconditioner) {
  scratch_ = rcp(new Vector(assembly_.dofMap()));
  residualU_ = rcp(new Vector(assembly_.dofMap()));
  predictU_ = rcp(new Vector(assembly_.dofMap()));
}

PressureStep::Block PressureStep::newBlock() const {
  return {rcp(new Vector(assembly_.dofMap())), rcp(new Vector(rowMap_))};
}

void PressureStep::fillRows() {
  const auto& effects = assembly_.effects();
  size_t local = 0;
  for (size_t i = 0; i < effects.size(); ++i) {
    effects[i]->constraintRows(assembly_.positions(), effectRows_[i]);
    local += effectRows_[i].size();
  }
  // A new map (and Krylov basis) only when some rank's row count changed.
  auto comm = assembly_.dofMap()->getComm();
  int changed = rowMap_.is_null() || rowMap_->getNodeNumElements() != local, anyChanged = 0;
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, changed, Teuchos::outArg(anyChanged));
  if (anyChanged) {
    rowMap_ = rcp(new Map(Tpetra::global_size_t(Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid()), local,
                          GO(0), comm));
    for (auto* v : {&weight_, &force_, &diagonal_, &schurInverse_, &volumeScale_, &scratchC_, &residualC_, &predictC_})
      *v = rcp(new Vector(rowMap_));
    if (schur_ == Schur::Laplacian)
      for (auto* v : {&volumeRows_, &volumeRowsOverW_, &laplacianJacobi_, &cgR_, &cgP_, &cgQ_, &cgZ_, &laplacianIn_,
                      &laplacianOut_})
        *v = rcp(new Vector(rowMap_));
    basis_.clear();
    preconditioned_.clear();
    lastRowStart_.clear();
  }
  rows_ = long(rowMap_->getGlobalNumElements());
  // B^T's rows and the row vectors, effect after effect.
  rowStart_.assign(1, 0), cols_.clear(), vals_.clear();
  auto w = weight_->getDataNonConst();
  auto F = force_->getDataNonConst();
  auto D = diagonal_->getDataNonConst();
  auto sInv = schurInverse_->getDataNonConst();
  auto vs = volumeScale_->getDataNonConst();
  std::vector<size_t> start, columnStart;
  std::vector<GO> cols, columnCols;
  std::vector<double> vals, columnVals;
  // Separate columns (ConstraintRows::column): every row's dR/dmu_j, chained.
  // (On every rank alike: the matrix is built and applied collectively.)
  int anyColumn = std::any_of(effectRows_.begin(), effectRows_.end(),
                              [](const ConstraintRows& r) { return r.size() > 0 && r.column.extent(0) > 0; }),
      anyColumnGlobal = 0;
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, anyColumn, Teuchos::outArg(anyColumnGlobal));
  // A free core's torque row takes a residual's entries otherwise than its rotation's column
  // takes a gradient's (over the radius; steady: omega moves no face node): columns apart.
  const bool ownColumns = anyColumnGlobal > 0 ||
                          std::any_of(assembly_.rigidCores().begin(), assembly_.rigidCores().end(),
                                      [](const RigidCore& c) { return c.free[3]; });
  std::vector<size_t> allColumnStart(1, 0);
  std::vector<GO> allColumnCols;
  std::vector<double> allColumnVals;
  size_t j = 0;
  for (size_t i = 0; i < effects.size(); ++i) {
    const ConstraintRows& r = effectRows_[i];
    if (r.size() == 0) continue;
    assembly_.chainRows(*effects[i], r.gradient, start, cols, vals, &r.entity);
    const bool column = r.column.extent(0) > 0;
    if (ownColumns)  // dR/dmu_j: the row's own column, or force_j gradient_j, chained as residuals
      assembly_.chainRows(*effects[i], column ? r.column : r.gradient, columnStart, columnCols, columnVals,
                          &r.entity, true);
    auto grad = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), column ? r.column : r.gradient);
    for (size_t k = 0; k < r.size(); ++k, ++j) {
      double norm2 = 0;
      for (size_t l = 0; l < grad.extent(1); ++l) norm2 += grad(k, l) * grad(k, l);
      // A row with no free dof (all its nodes held) is no constraint: weight 0
      // keeps its equation and its dmu at 0.
      const bool empty = start[k + 1] == start[k];
      // w_j = |dR/dmu_j| / |S_j|.
      w[j] = empty ? 0.0 : (column ? 1.0 : std::fabs(r.force[k])) * std::sqrt(norm2) / std::fabs(r.schur[k]);
      if (ownColumns) {
        const double scale = column ? 1.0 : r.force[k];
        allColumnCols.insert(allColumnCols.end(), columnCols.begin() + long(columnStart[k]),
                             columnCols.begin() + long(columnStart[k + 1]));
        for (size_t l = columnStart[k]; l < columnStart[k + 1]; ++l) allColumnVals.push_back(scale * columnVals[l]);
        allColumnStart.push_back(allColumnCols.size());
      }
      sInv[j] = empty ? 0.0 : 1 / (w[j] * r.schur[k]);
      F[j] = r.force[k], D[j] = r.diagonal[k];
      vs[j] = empty ? 0.0 : w[j] * r.scale[k];
      cols_.insert(cols_.end(), cols.begin() + long(start[k]), cols.begin() + long(start[k + 1]));
      vals_.insert(vals_.end(), vals.begin() + long(start[k]), vals.begin() + long(start[k + 1]));
      rowStart_.push_back(cols_.size());
    }
  }
  // Refilled in place while the pattern holds (no contact point came or went)
  // on every rank: fillComplete on a new graph is collective (its column map)
  // and on a refilled one is not, so a rank alone in a new pattern waited
  // forever for the others (the 126k-dof steady drive on 2 ranks).
  int sameHere = !lastRowStart_.empty() && rowStart_ == lastRowStart_ && cols_ == lastCols_, sameEverywhere = 0;
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_MIN, sameHere, Teuchos::outArg(sameEverywhere));
  const bool same = sameEverywhere > 0;
  if (same) {
    gradient_->resumeFill();
  } else {
    size_t longest = 1;
    for (size_t k = 0; k + 1 < rowStart_.size(); ++k) longest = std::max(longest, rowStart_[k + 1] - rowStart_[k]);
    gradient_ = rcp(new CrsMatrix(rowMap_, longest));
    lastRowStart_ = rowStart_, lastCols_ = cols_;
  }
  for (size_t k = 0; k + 1 < rowStart_.size(); ++k) {
    if (rowStart_[k + 1] == rowStart_[k]) continue;
    const GO gid = rowMap_->getGlobalElement(LO(k));
    if (same)
      gradient_->replaceGlobalValues(gid, row(cols_, k), row(vals_, k));
    else
      gradient_->insertGlobalValues(gid, row(cols_, k), row(vals_, k));
  }
  gradient_->fillComplete(assembly_.dofMap(), rowMap_);
  columns_ = Teuchos::null;
  if (!ownColumns) return;
  size_t longest = 1;
  for (size_t k = 0; k + 1 < allColumnStart.size(); ++k)
    longest = std::max(longest, allColumnStart[k + 1] - allColumnStart[k]);
  columns_ = rcp(new CrsMatrix(rowMap_, longest));
  for (size_t k = 0; k + 1 < allColumnStart.size(); ++k) {
    const size_t n = allColumnStart[k + 1] - allColumnStart[k];
    if (n == 0) continue;
    columns_->insertGlobalValues(rowMap_->getGlobalElement(LO(k)),
                                 Teuchos::ArrayView<const GO>(allColumnCols.data() + allColumnStart[k], n),
                                 Teuchos::ArrayView<const double>(allColumnVals.data() + allColumnStart[k], n));
  }
  columns_->fillComplete(assembly_.dofMap(), rowMap_);
}

void PressureStep::buildVolumeLaplacian(const CrsMatrix& K) {
  // The volume rows, their 1 / w_j and 1 / S_j (vectors on the row map: fillRows).
  Vector schurInverse(rowMap_);
  {
    auto m = volumeRows_->getDataNonConst();
    auto mw = volumeRowsOverW_->getDataNonConst();
    auto si = schurInverse.getDataNonConst();
    auto vs = volumeScale_->getData();
    auto w = weight_->getData();
    auto wsInv = schurInverse_->getData();
    for (size_t j = 0; j < size_t(m.size()); ++j) {
      const bool volume = vs[j] > 0;
      m[j] = volume ? 1.0 : 0.0;
      mw[j] = volume ? 1 / w[j] : 0.0;
      si[j] = volume ? wsInv[j] * w[j] : 0.0;
    }
  }
  // diag(K0) = diag(K) - diag(G (eps M)^-1 G^T): K without the volume penalty.
  Vector diagK(K.getRowMap()), penalty(assembly_.dofMap()), diagK0Inverse(assembly_.dofMap());
  K.getLocalDiagCopy(diagK);
  auto G = rcp(new CrsMatrix(*gradient_, Teuchos::Copy));
  G->leftScale(*volumeRows_);  // the volume rows only
  {
    auto squared = rcp(new CrsMatrix(*G, Teuchos::Copy));
    auto v = squared->getLocalMatrixDevice().values;
    Kokkos::parallel_for(
        "squared gradient", Kokkos::RangePolicy<ExecSpace>(0, v.extent(0)), KOKKOS_LAMBDA(int k) { v(k) *= v(k); });
    Kokkos::fence();
    squared->apply(schurInverse, penalty, Teuchos::TRANS);
  }
  {
    auto d = diagK.getData();
    auto pen = penalty.getData();
    auto out = diagK0Inverse.getDataNonConst();
    for (size_t i = 0; i < size_t(out.size()); ++i) {
      // K0 is positive definite; guard against round-off where the penalty dominates.
      const double k0 = std::max(d[i] - pen[i], 1e-3 * d[i]);
      out[i] = d[i] > 0 ? 1 / k0 : 0.0;
    }
  }
  auto GD = rcp(new CrsMatrix(*G, Teuchos::Copy));
  GD->rightScale(diagK0Inverse);
  laplacian_ = rcp(new CrsMatrix(rowMap_, 0));
  Tpetra::MatrixMatrix::Multiply(*GD, false, *G, true, *laplacian_);
  laplacian_->getLocalDiagCopy(*laplacianJacobi_);
  {
    auto d = laplacianJacobi_->getDataNonConst();
    for (size_t j = 0; j < size_t(d.size()); ++j) d[j] = d[j] > 0 ? 1 / d[j] : 0.0;
  }
}

void PressureStep::applyVolumeLaplacianInverse(const Vector& b, Vector& x) const {
  // Jacobi-preconditioned CG from 0; rows outside the volumes stay 0.
  x.putScalar(0.0);
  cgR_->update(1.0, b, 0.0);
  cgZ_->elementWiseMultiply(1.0, *laplacianJacobi_, *cgR_, 0.0);
  cgP_->update(1.0, *cgZ_, 0.0);
  double rz = cgR_->dot(*cgZ_);
  for (int it = 0; it < kLaplacianIterations && rz > 0; ++it) {
    laplacian_->apply(*cgP_, *cgQ_);
    const double pq = cgP_->dot(*cgQ_);
    if (!(pq > 0)) break;
    const double alpha = rz / pq;
    x.update(alpha, *cgP_, 1.0);
    cgR_->update(-alpha, *cgQ_, 1.0);
    cgZ_->elementWiseMultiply(1.0, *laplacianJacobi_, *cgR_, 0.0);
    const double rzNext = cgR_->dot(*cgZ_);
    cgP_->update(1.0, *cgZ_, rzNext / rz);
    rz = rzNext;
  }
}

void PressureStep::applySystem(const CrsMatrix& K, const Block& x, Block& y) const {
  // y_u = K x_u + B F x_c
  K.apply(*x.u, *y.u);
  if (columns_.is_null()) {
    scratchC_->elementWiseMultiply(1.0, *force_, *x.c, 0.0);
    gradient_->apply(*scratchC_, *y.u, Teuchos::TRANS, 1.0, 1.0);
  } else {
    columns_->apply(*x.c, *y.u, Teuchos::TRANS, 1.0, 1.0);
  }
  // y_c = w .* (B^T x_u + D x_c)
  gradient_->apply(*x.u, *y.c);
  y.c->elementWiseMultiply(1.0, *diagonal_, *x.c, 1.0);
  y.c->elementWiseMultiply(1.0, *weight_, *y.c, 0.0);
}

void PressureStep::applyPreconditioner(const Inverse& Kinv, const Block& r, Block& z) {
  if (useLU_) {
    lu_->solve(*r.u, *r.c, *z.u, *z.c);
    return;
  }
  // z_c = (w S)^-1 r_c, then z_u = K~^-1 (r_u - B F z_c)
  z.c->elementWiseMultiply(1.0, *schurInverse_, *r.c, 0.0);
  if (schur_ == Schur::Laplacian) {
    // + omega L^-1 w^-1 r_c on the volume rows
    laplacianIn_->elementWiseMultiply(1.0, *volumeRowsOverW_, *r.c, 0.0);
    applyVolumeLaplacianInverse(*laplacianIn_, *laplacianOut_);
    z.c->update(kLaplacianWeight, *laplacianOut_, 1.0);
  }
  scratch_->update(1.0, *r.u, 0.0);
  if (columns_.is_null()) {
    scratchC_->elementWiseMultiply(1.0, *force_, *z.c, 0.0);
    gradient_->apply(*scratchC_, *scratch_, Teuchos::TRANS, -1.0, 1.0);
  } else {
    columns_->apply(*z.c, *scratch_, Teuchos::TRANS, -1.0, 1.0);
  }
  Kinv(*scratch_, *z.u);
}

double PressureStep::volumeError(const Vector& rc) const {
  auto r = rc.getData();
  auto s = volumeScale_->getData();
  double local = 0, global = 0;
  for (size_t j = 0; j < size_t(r.size()); ++j)
    if (s[j] > 0) local = std::max(local, std::fabs(r[j]) / s[j]);
  Teuchos::reduceAll(*rowMap_->getComm(), Teuchos::REDUCE_MAX, local, Teuchos::outArg(global));
  return global;
}

double PressureStep::predictedVolumeError(const Inverse& Kinv, const Vector& ru, const Vector& rc) {
  // After the step, R ~ -ru and c ~ -rc / w; Newton (multipliers held) then
  // moves the positions by K^-1 ru and the constraints by B^T K^-1 ru.
  Kinv(ru, *predictU_);
  gradient_->apply(*predictU_, *predictC_);
  predictC_->elementWiseMultiply(1.0, *weight_, *predictC_, 0.0);
  predictC_->update(1.0, rc, -1.0);
  return volumeError(*predictC_);
}

void PressureStep::measuredAfterNewton(double volumeError) {
  if (lastPredicted_ > 0) missRatio_ = std::max(1.0, volumeError / lastPredicted_);
  lastPredicted_ = 0;
}

PressureStep::Result PressureStep::solve(const CrsMatrix& K, const Inverse& Kinv, const Vector& f, double tolerance,
                                         double volumeTarget, int maxIterations, Vector& dx,
                                         std::vector<Kokkos::View<double*>>& dmu) {
  Kokkos::Timer timer;
  fillRows();
  useLU_ = preconditioner_ == Preconditioner::LU;
  std::string luRefused;
  if (useLU_) {
    if (!lu_) lu_ = std::make_unique<SaddlePointLU>();
    RCP<const CrsMatrix> T = columns_;
    if (T.is_null()) {  // the rows' forces on the positions: F G
      auto FG = rcp(new CrsMatrix(*gradient_, Teuchos::Copy));
      FG->leftScale(*force_);
      T = FG;
    }
    try {
      lu_->factor(K, *gradient_, *T, *weight_, *diagonal_, *schurInverse_);
    } catch (const std::runtime_error& e) {  // MUMPS refused it (every rank alike): Block from here on
      useLU_ = false;
      preconditioner_ = Preconditioner::Block;
      luRefused = e.what();
    }
  }
  if (!useLU_ && schur_ == Schur::Laplacian) buildVolumeLaplacian(K);
  Result result;
  // Right-hand side: (-R, -w .* c).
  Block rhs = newBlock();
  rhs.u->update(-1.0, f, 0.0);
  {
    auto r = rhs.c->getDataNonConst();
    auto w = weight_->getData();
    size_t j = 0;
    for (size_t i = 0; i < effectRows_.size(); ++i)
      for (size_t k = 0; k < effectRows_[i].size(); ++k, ++j) r[j] = -w[j] * effectRows_[i].value[k];
    // The rows the stop rule does not look at: contact points.
    long contact = 0, all = 0;
    for (const ConstraintRows& rows : effectRows_) contact += long(std::count(rows.scale.begin(), rows.scale.end(), 0.0));
    Teuchos::reduceAll(*rowMap_->getComm(), Teuchos::REDUCE_SUM, contact, Teuchos::outArg(all));
    result.contactRows = int(all);
  }
  Block x = newBlock(), work = newBlock();
  const double beta0 = std::sqrt(dot(rhs, rhs));
  // Done early once the volume error predicted after the next Newton solve meets the target (the
  // step's own error misses what that solve moves); else at `tolerance`, going on past it at most
  // as many iterations again (docs/numerics.md, "When a step stops").
  const double predictionTarget = volumeTarget / missRatio_;
  result.predictionTarget = predictionTarget;
  int reachedAt = -1;       // iterations when the residual first met `tolerance`
  double nextCheck = beta0;  // the prediction is checked again below this residual
  bool predictionMet = false;  // stays met through the cycle's end (its true residual is not checked again)
  // res: the residual's norm, s ru and s rc its blocks, volumeLeft = s volumeError(rc).
  const auto done = [&](double res, double volumeLeft, const Vector& ru, const Vector& rc, double s) {
    if (predictionMet) return true;
    if (volumeTarget > 0 && res > tolerance * beta0) {
      if (volumeLeft > predictionTarget || res > nextCheck) return false;
      nextCheck = 0.5 * res;
      ++result.predictions;
      const double predicted = s * predictedVolumeError(Kinv, ru, rc);
      if (predicted <= predictionTarget) result.volumePredicted = predicted;
      return predictionMet = predicted <= predictionTarget;
    }
    if (res > tolerance * beta0) return false;
    if (reachedAt < 0) reachedAt = result.iterations;
    return volumeTarget <= 0 || volumeLeft <= volumeTarget || volumeLeft > 10 * volumeTarget ||
           result.iterations >= 2 * reachedAt + 10;
  };
  double volumeLeft = volumeTarget > 0 ? volumeError(*rhs.c) : 0.0;
  const int m = std::max(1, std::min(maxIterations, 300));  // restart length
  if (basis_.empty()) basis_.push_back(newBlock());
  double beta = beta0;
  Block& r = work;
  update(1.0, rhs, 0.0, r);
  while (!done(beta, volumeLeft, *r.u, *r.c, 1.0) && result.iterations < maxIterations) {
    // One GMRES(m) cycle from the residual r (Givens rotations on the
    // Hessenberg matrix H, modified Gram-Schmidt).
    std::vector<double> H((m + 1) * m, 0.0), cs(m), sn(m), s(m + 1, 0.0);
    auto h = [&](int i, int j) -> double& { return H[i * m + j]; };
    update(1 / beta, r, 0.0, basis_[0]);
    residualC_->update(1.0, *basis_[0].c, 0.0);
    if (volumeTarget > 0) residualU_->update(1.0, *basis_[0].u, 0.0);
    s[0] = beta;
    int k = 0;  // columns built
    double res = beta;
    while (k < m && result.iterations < maxIterations) {
      if (basis_.size() < size_t(k + 2)) basis_.push_back(newBlock());  // allocated as the cycle needs
      if (preconditioned_.size() < size_t(k + 1)) preconditioned_.push_back(newBlock());
      applyPreconditioner(Kinv, basis_[k], preconditioned_[k]);
      Block& w = basis_[k + 1];
      applySystem(K, preconditioned_[k], w);
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
      // u_k = -sn_k u_{k-1} + cs_k v_{k+1}, u_{-1} = v_0: one update of each
      // block per iteration (the position block for the prediction).
      if (volumeTarget > 0) {
        residualC_->update(cs[k], *basis_[k + 1].c, -sn[k]);
        residualU_->update(cs[k], *basis_[k + 1].u, -sn[k]);
        volumeLeft = std::fabs(s[k + 1]) * volumeError(*residualC_);
      }
      ++k, ++result.iterations;
      if (done(res, volumeLeft, *residualU_, *residualC_, std::fabs(s[k])) || b == 0) break;
    }
    // x += (P^-1 basis) y, y = H^-1 s (upper triangular after the rotations)
    std::vector<double> y(k, 0.0);
    for (int i = k - 1; i >= 0; --i) {
      double t = s[i];
      for (int j = i + 1; j < k; ++j) t -= h(i, j) * y[j];
      y[i] = h(i, i) != 0 ? t / h(i, i) : 0.0;
    }
    for (int i = 0; i < k; ++i) update(y[i], preconditioned_[i], 1.0, x);
    // The true residual, for the next cycle and the figure reported.
    applySystem(K, x, r);
    update(1.0, rhs, -1.0, r);
    const double trueRes = std::sqrt(dot(r, r));
    const bool progress = trueRes < beta;
    beta = trueRes;
    if (volumeTarget > 0) volumeLeft = volumeError(*r.c);
    if (!progress) break;  // stagnated: keep what there is (the loop checks the outcome)
  }
  result.lu = useLU_;
  result.luRefused = luRefused;
  result.reduction = beta0 > 0 ? beta / beta0 : 0.0;
  result.initial = beta0;
  lastPredicted_ = result.reduction < 1 ? result.volumePredicted : 0.0;  // a step without progress is not taken
  result.volumeResidual = volumeError(*r.c);
  // Held dofs stay where they are (K's identity rows would keep them at ~0
  // anyway; the preconditioner need not).
  dx.update(1.0, *x.u, 0.0);
  {
    auto d = dx.getDataNonConst();
    for (LO i = 0; i < LO(dx.getLocalLength()); ++i)
      if (assembly_.ownedConstrained(i)) d[i] = 0;
  }
  // dmu into each effect's multiplier layout.
  auto xc = x.c->getData();
  dmu.resize(effectRows_.size());
  size_t j = 0;
  for (size_t i = 0; i < effectRows_.size(); ++i) {
    auto mu = assembly_.effects()[i]->multipliers();
    if (dmu[i].extent(0) != mu.extent(0)) dmu[i] = Kokkos::View<double*>("pressure step dmu", mu.extent(0));
    auto h = Kokkos::create_mirror_view(dmu[i]);
    Kokkos::deep_copy(h, 0.0);
    const ConstraintRows& r = effectRows_[i];
    for (size_t k = 0; k < r.size(); ++k, ++j) {
      if (r.direction.empty()) {
        h(r.multiplier[k]) = xc[j];
        continue;
      }
      for (int i = 0; i < 3; ++i) h(r.multiplier[k] + i) += xc[j] * r.direction[3 * k + i];
    }
    Kokkos::deep_copy(dmu[i], h);
  }
  seconds_ += timer.seconds();
  return result;
}

}  // namespace capstan
