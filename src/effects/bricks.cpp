#include "bricks.hpp"

#include <Teuchos_CommHelpers.hpp>

#include "../../kernels/brick.hpp"
#include "../mesh.hpp"
#include "entities.hpp"

namespace capstan {

using detail::dofsOf;
using detail::loadEntities;

namespace {

// One brick's reference (X) and current (x) node positions, from the effect's
// per-brick reference coordinates and the overlapped nodes' positions.
template <class Nodes, class Reference>
KOKKOS_INLINE_FUNCTION void gatherBrick(int e, const Nodes& nodes, const Reference& X, const NodalVectors& x,
                                        double Xe[8][3], double xe[8][3]) {
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) {
      Xe[a][i] = X(e, a, i);
      xe[a][i] = x(nodes(e, a), i);
    }
}

}  // namespace

BrickEffect::BrickEffect(const Mesh& mesh, double c, double penalty, double volumeTolerance)
    : Effect("brick"), c_(c), penalty_(penalty), volumeTolerance_(volumeTolerance) {
  const size_t ne = mesh.numElements();
  loadEntities(mesh, mesh.connectivity, "brick", nodes_, X_);
  pressureAnchor = Kokkos::View<double*>("pbar", ne);
  pressure = Kokkos::View<double*>("p", ne);
  volume = Kokkos::View<double*>("v", ne);
  referenceVolume = Kokkos::View<double*>("V", ne);
  minJacobian = Kokkos::View<double*>("minJ", ne);
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("brick R", ne, 24);
  local_.stiff = true;
  auto X = X_;
  auto V = referenceVolume;
  Kokkos::parallel_for(
      "brick reference volume", Kokkos::RangePolicy<ExecSpace>(0, ne), KOKKOS_LAMBDA(int e) {
        double Xe[8][3];
        for (int a = 0; a < 8; ++a)
          for (int i = 0; i < 3; ++i) Xe[a][i] = X(e, a, i);
        double minJ;
        V(e) = kernels::brickVolume(Xe, Xe, minJ);
      });
}

void BrickEffect::launch(const NodalVectors& x, const NodalVectors&, bool tangent, const TangentSink& sink) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
  auto V = referenceVolume, pbar = pressureAnchor, p = pressure, v = volume, minJ = minJacobian;
  const double c = c_, eps = penalty_;
  Kokkos::parallel_for(
      "brick residual+tangent", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)),
      KOKKOS_LAMBDA(int e) {
        double Xe[8][3], xe[8][3];
        gatherBrick(e, nodes, X, x, Xe, xe);
        kernels::BrickState st;
        double K[24 * 24];
        kernels::brickResidualTangent(Xe, xe, V(e), pbar(e), c, eps, &R(e, 0), tangent ? K : nullptr, st);
        if (tangent) sink.take<24>(e, K);
        p(e) = st.pressure;
        v(e) = st.volume;
        minJ(e) = st.minJ;
      });
}

BrickEffect::Compression BrickEffect::mostCompressed(const Teuchos::Comm<int>& comm) const {
  using MinLoc = Kokkos::MinLoc<double, int>;
  typename MinLoc::value_type local;
  auto minJ = minJacobian;
  Kokkos::parallel_reduce(
      "brick most compressed", Kokkos::RangePolicy<ExecSpace>(0, minJ.extent(0)),
      KOKKOS_LAMBDA(int e, typename MinLoc::value_type& m) {
        if (minJ(e) < m.val) m.val = minJ(e), m.loc = e;
      },
      MinLoc(local));
  Compression c;
  const bool any = minJ.extent(0) > 0;
  const double mine = any ? local.val : 1e300;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, mine, Teuchos::outArg(c.detF));
  // The centroid from the rank that holds the smallest (the lowest such rank).
  const int holder = any && mine == c.detF ? comm.getRank() : comm.getSize();
  int first = holder;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, holder, Teuchos::outArg(first));
  std::array<double, 3> at{};
  if (first == comm.getRank()) {
    auto X = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), Kokkos::subview(X_, local.loc, Kokkos::ALL, Kokkos::ALL));
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) at[i] += X(a, i) / 8;
  }
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, 3, at.data(), c.centroid.data());
  return c;
}

void BrickEffect::volumeGradients(const NodalVectors& x, Matrix& g) const {
  auto nodes = nodes_;
  auto X = X_;
  if (g.extent(0) != nodes.extent(0)) g = Matrix("brick dv/dx", nodes.extent(0), 24);
  auto out = g;
  Kokkos::parallel_for(
      "brick volume gradient", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)), KOKKOS_LAMBDA(int e) {
        double Xe[8][3], xe[8][3];
        gatherBrick(e, nodes, X, x, Xe, xe);
        kernels::brickVolumeGradient(Xe, xe, &out(e, 0));
      });
}

void BrickEffect::constraintRows(const NodalVectors& x, ConstraintRows& rows) const {
  volumeGradients(x, rows.gradient);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), volume);
  auto V = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), referenceVolume);
  rows.clear();
  for (size_t e = 0; e < V.extent(0); ++e) {
    rows.entity.push_back(int(e)), rows.multiplier.push_back(int(e));
    rows.force.push_back(-1.0), rows.diagonal.push_back(0.0), rows.value.push_back(v(e) - V(e));
    rows.schur.push_back(penalty_ * V(e)), rows.scale.push_back(V(e));
  }
}

void BrickEffect::multiplierMap(const Kokkos::View<double*>& next) const {
  Kokkos::deep_copy(next, pressure);
}

double BrickEffect::constraintViolation() const {
  double change = 0;
  auto v = volume, V = referenceVolume;
  Kokkos::parallel_reduce(
      "volume change", Kokkos::RangePolicy<ExecSpace>(0, v.extent(0)),
      KOKKOS_LAMBDA(int e, double& m) {
        const double d = kernels::fabs(v(e) / V(e) - 1);
        m = d > m ? d : m;
      },
      Kokkos::Max<double>(change));
  return change;
}

void BrickEffect::centroidStress(const NodalVectors& x, Matrix& stress,
                                 Kokkos::View<double*>& mises) const {
  auto nodes = nodes_;
  auto X = X_;
  auto p = pressure;
  const double c = c_;
  stress = Matrix("stress", nodes.extent(0), 6);
  mises = Kokkos::View<double*>("von Mises", nodes.extent(0));
  auto s = stress;
  auto m = mises;
  Kokkos::parallel_for(
      "brick centroid stress", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)),
      KOKKOS_LAMBDA(int e) {
        double Xe[8][3], xe[8][3], sig[6];
        gatherBrick(e, nodes, X, x, Xe, xe);
        kernels::brickCentroidStress(Xe, xe, p(e), c, sig);
        for (int k = 0; k < 6; ++k) s(e, k) = sig[k];
        m(e) = kernels::vonMises(sig);
      });
}

int BrickEffect::multiplierSites(std::vector<int>& nodes) const {
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), nodes_);
  nodes.assign(h.data(), h.data() + h.size());
  return 8;
}

}  // namespace capstan
