#include "saddle_point_lu.hpp"

#include <Tpetra_RowMatrixTransposer.hpp>

#include <vector>

namespace capstan {

namespace {
// Each row's diagonal gets this fraction of its Schur approximation w_j S_j: a node's stick and
// contact rows come once from each face at it, so they repeat and the block matrix is singular;
// GMRES removes the difference (docs/numerics.md, "The pressure loop").
constexpr double kRegularisation = 1e-6;
constexpr int kWorkspaceIncreasePercent = 100;
}  // namespace

SaddlePointLU::SaddlePointLU() {
  // Zero diagonals (the exact constraints) delay pivots beyond the analysis'
  // estimate: the pressed box with stick rows needed more than MUMPS' default
  // working space (INFOG(1) = -9) even after its retry.
  MumpsOptions options;
  options.workspaceIncreasePercent = kWorkspaceIncreasePercent;
  mumps_ = std::make_unique<MumpsSolver>(options);
}
SaddlePointLU::~SaddlePointLU() = default;

void SaddlePointLU::factor(const CrsMatrix& K, const CrsMatrix& G, const CrsMatrix& T, const Vector& w,
                           const Vector& D, const Vector& schurInverse) {
  // The combined rows: this rank's positions, then its constraint rows with
  // their GIDs past every position's.
  const auto uMap = K.getRowMap(), cMap = G.getRowMap();
  const GO offset = uMap->getMaxAllGlobalIndex() + 1;
  if (map_.is_null() || uMap_ != uMap || cMap_ != cMap) {
    std::vector<GO> gids;
    gids.reserve(uMap->getNodeNumElements() + cMap->getNodeNumElements());
    for (size_t i = 0; i < uMap->getNodeNumElements(); ++i) gids.push_back(uMap->getGlobalElement(LO(i)));
    for (size_t j = 0; j < cMap->getNodeNumElements(); ++j) gids.push_back(cMap->getGlobalElement(LO(j)) + offset);
    const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
    map_ = rcp(new Map(invalid, Teuchos::ArrayView<const GO>(gids), 0, uMap->getComm()));
    uMap_ = uMap, cMap_ = cMap;
    b_ = rcp(new Tpetra::MultiVector<>(map_, 1));
    x_ = rcp(new Tpetra::MultiVector<>(map_, 1));
  }
  // T^T: each position's row of the constraint columns (other ranks' rows come over).
  auto Tt = Tpetra::RowMatrixTransposer<double, LO, GO>(Teuchos::rcpFromRef(T)).createTranspose();
  const size_t nu = uMap->getNodeNumElements(), nc = cMap->getNodeNumElements();
  std::vector<size_t> lengths(nu + nc);
  const size_t none = Teuchos::OrdinalTraits<size_t>::invalid();
  for (size_t i = 0; i < nu; ++i) {
    const size_t coupled = Tt->getNumEntriesInGlobalRow(uMap->getGlobalElement(LO(i)));
    lengths[i] = K.getNumEntriesInLocalRow(LO(i)) + (coupled == none ? 0 : coupled);
  }
  for (size_t j = 0; j < nc; ++j) lengths[nu + j] = G.getNumEntriesInLocalRow(LO(j)) + 1;
  auto A = rcp(new CrsMatrix(map_, Teuchos::ArrayView<const size_t>(lengths)));
  std::vector<GO> cols;
  std::vector<double> vals;
  auto insertRow = [&](const CrsMatrix& M, GO from, GO to, GO shift, double scale) {
    const size_t n = M.getNumEntriesInGlobalRow(from);
    if (n == 0 || n == none) return;
    typename CrsMatrix::nonconst_global_inds_host_view_type c("cols", n);
    typename CrsMatrix::nonconst_values_host_view_type v("vals", n);
    size_t got = 0;
    M.getGlobalRowCopy(from, c, v, got);
    cols.clear(), vals.clear();
    for (size_t k = 0; k < got; ++k) cols.push_back(c(k) + shift), vals.push_back(scale * v(k));
    A->insertGlobalValues(to, Teuchos::ArrayView<const GO>(cols), Teuchos::ArrayView<const double>(vals));
  };
  for (size_t i = 0; i < nu; ++i) {
    const GO row = uMap->getGlobalElement(LO(i));
    insertRow(K, row, row, 0, 1.0);
    insertRow(*Tt, row, row, offset, 1.0);
  }
  auto wv = w.getData();
  auto dv = D.getData();
  auto sv = schurInverse.getData();
  for (size_t j = 0; j < nc; ++j) {
    const GO row = cMap->getGlobalElement(LO(j)), to = row + offset;
    const double diagonal = wv[j] == 0 ? 1.0 : wv[j] * dv[j] + (sv[j] != 0 ? kRegularisation / sv[j] : 0.0);
    if (wv[j] != 0) insertRow(G, row, to, 0, wv[j]);
    A->insertGlobalValues(to, Teuchos::tuple<GO>(to), Teuchos::tuple<double>(diagonal));
  }
  A->fillComplete(map_, map_);
  mumps_->factor(*A);
}

void SaddlePointLU::solve(const Vector& ru, const Vector& rc, Vector& zu, Vector& zc) {
  const size_t nu = ru.getLocalLength(), nc = rc.getLocalLength();
  {
    auto b = b_->getDataNonConst(0);
    auto u = ru.getData();
    auto c = rc.getData();
    for (size_t i = 0; i < nu; ++i) b[i] = u[i];
    for (size_t j = 0; j < nc; ++j) b[nu + j] = c[j];
  }
  mumps_->solve(*b_, *x_);
  auto x = x_->getData(0);
  auto u = zu.getDataNonConst();
  auto c = zc.getDataNonConst();
  for (size_t i = 0; i < nu; ++i) u[i] = x[i];
  for (size_t j = 0; j < nc; ++j) c[j] = x[nu + j];
}

}  // namespace capstan
