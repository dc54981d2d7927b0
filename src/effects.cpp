#include "effects.hpp"

#include <Kokkos_Timer.hpp>

#include "../kernels/brick.hpp"
#include "../kernels/foundation.hpp"
#include "mesh.hpp"

namespace capstan {

void Effect::evaluate(const NodalVectors& x, const NodalVectors& u, bool tangent) {
  Kokkos::Timer timer;
  launch(x, u, tangent);
  Kokkos::fence();
  seconds_ += timer.seconds();
  ++launches_;
}

namespace {

// Dof ids of entities given by their node ids.
template <class NodeView>
IntMatrix dofsOf(const NodeView& nodes) {
  const int nn = int(nodes.extent(1));
  IntMatrix dofs("dofs", nodes.extent(0), 3 * nn);
  Kokkos::parallel_for(
      "dofs", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)), KOKKOS_LAMBDA(int e) {
        for (int a = 0; a < nn; ++a)
          for (int i = 0; i < 3; ++i) dofs(e, 3 * a + i) = 3 * nodes(e, a) + i;
      });
  return dofs;
}

// Node ids and reference coordinates of entities (bricks: 8 nodes, faces: 4)
// from a flat node list, into device views.
template <class NodeView, class CoordView>
void loadEntities(const Mesh& mesh, const std::vector<int>& nodeList, const std::string& label,
                  NodeView& nodes, CoordView& X) {
  const size_t nn = NodeView::static_extent(1), count = nodeList.size() / nn;
  nodes = NodeView(label + " nodes", count);
  X = CoordView(label + " X", count);
  auto hn = Kokkos::create_mirror_view(nodes);
  auto hX = Kokkos::create_mirror_view(X);
  for (size_t e = 0; e < count; ++e)
    for (size_t a = 0; a < nn; ++a) {
      const int n = nodeList[nn * e + a];
      hn(e, a) = n;
      for (int i = 0; i < 3; ++i) hX(e, a, i) = mesh.X[3 * n + i];
    }
  Kokkos::deep_copy(nodes, hn);
  Kokkos::deep_copy(X, hX);
}

}  // namespace

// ---------------------------------------------------------------- bricks

BrickEffect::BrickEffect(const Mesh& mesh, double c, double penalty)
    : Effect("brick"), c_(c), penalty_(penalty) {
  const size_t ne = mesh.numElements();
  loadEntities(mesh, mesh.connectivity, "brick", nodes_, X_);
  pressureAnchor = Kokkos::View<double*>("pbar", ne);
  pressure = Kokkos::View<double*>("p", ne);
  volume = Kokkos::View<double*>("v", ne);
  referenceVolume = Kokkos::View<double*>("V", ne);
  minJacobian = Kokkos::View<double*>("minJ", ne);
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("brick R", ne, 24);
  local_.K = Tensor3("brick K", ne, 24, 24);
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

void BrickEffect::launch(const NodalVectors& x, const NodalVectors&, bool tangent) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
  auto K = local_.K;
  auto V = referenceVolume, pbar = pressureAnchor, p = pressure, v = volume, minJ = minJacobian;
  const double c = c_, eps = penalty_;
  Kokkos::parallel_for(
      "brick residual+tangent", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)),
      KOKKOS_LAMBDA(int e) {
        double Xe[8][3], xe[8][3];
        for (int a = 0; a < 8; ++a)
          for (int i = 0; i < 3; ++i) {
            Xe[a][i] = X(e, a, i);
            xe[a][i] = x(nodes(e, a), i);
          }
        kernels::BrickState st;
        kernels::brickResidualTangent(Xe, xe, V(e), pbar(e), c, eps, &R(e, 0),
                                      tangent ? &K(e, 0, 0) : nullptr, st);
        p(e) = st.pressure;
        v(e) = st.volume;
        minJ(e) = st.minJ;
      });
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
        for (int a = 0; a < 8; ++a)
          for (int i = 0; i < 3; ++i) {
            Xe[a][i] = X(e, a, i);
            xe[a][i] = x(nodes(e, a), i);
          }
        kernels::brickCentroidStress(Xe, xe, p(e), c, sig);
        for (int k = 0; k < 6; ++k) s(e, k) = sig[k];
        m(e) = kernels::vonMises(sig);
      });
}

// ---------------------------------------------------------------- foundation

FoundationEffect::FoundationEffect(const std::string& name, const Mesh& mesh,
                                   const std::string& face, double k,
                                   std::array<bool, 3> components)
    : Effect(name), k_(k) {
  const auto& quads = mesh.faces.at(face);
  const size_t nf = quads.size() / 4;
  loadEntities(mesh, quads, "foundation", nodes_, X_);
  for (int i = 0; i < 3; ++i) mask_[i] = components[i] ? 1 : 0;
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("foundation R", nf, 12);
  local_.K = Tensor3("foundation K", nf, 12, 12);
}

void FoundationEffect::launch(const NodalVectors&, const NodalVectors& u, bool) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
  auto K = local_.K;
  const double k = k_;
  const int m0 = mask_[0], m1 = mask_[1], m2 = mask_[2];
  Kokkos::parallel_for(
      "foundation", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)), KOKKOS_LAMBDA(int f) {
        double Xf[4][3], uf[4][3];
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) {
            Xf[a][i] = X(f, a, i);
            uf[a][i] = u(nodes(f, a), i);
          }
        const int mask[3] = {m0, m1, m2};
        kernels::foundationResidualTangent(Xf, uf, k, mask, &R(f, 0), &K(f, 0, 0));
      });
}

std::array<double, 3> FoundationEffect::localForceOnBody() const {
  auto R = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), local_.R);
  std::array<double, 3> F{0, 0, 0};
  for (size_t f = 0; f < R.extent(0); ++f)
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) F[i] -= R(f, 3 * a + i);  // R = internal - external
  return F;
}

}  // namespace capstan
