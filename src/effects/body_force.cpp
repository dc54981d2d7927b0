#include "body_force.hpp"

#include "../../kernels/body_force.hpp"
#include "../mesh.hpp"
#include "entities.hpp"

namespace capstan {

using detail::dofsOf;
using detail::loadEntities;

BodyForceEffect::BodyForceEffect(const Mesh& mesh, std::array<double, 3> b, double endTime)
    : Effect("body force"), endTime_(endTime) {
  Kokkos::View<int* [8], Kokkos::LayoutRight> nodes;
  Kokkos::View<double* [8][3], Kokkos::LayoutRight> X;
  loadEntities(mesh, mesh.connectivity, "body force", nodes, X);
  local_.dofs = dofsOf(nodes);
  local_.R = Matrix("body force R", nodes.extent(0), 24);
  fullLoad_ = Matrix("body force load", nodes.extent(0), 24);
  auto load = fullLoad_;
  const double b0 = b[0], b1 = b[1], b2 = b[2];
  Kokkos::parallel_for(
      "body force", Kokkos::RangePolicy<ExecSpace>(0, X.extent(0)), KOKKOS_LAMBDA(int e) {
        double Xe[8][3];
        for (int a = 0; a < 8; ++a)
          for (int i = 0; i < 3; ++i) Xe[a][i] = X(e, a, i);
        const double bb[3] = {b0, b1, b2};
        kernels::brickBodyForce(Xe, bb, &load(e, 0));
      });
}

// A dead load ramped with time: the loads integrated once, scaled.
void BodyForceEffect::launch(const NodalVectors&, const NodalVectors&, bool, const TangentSink&) {
  auto R = local_.R;
  auto load = fullLoad_;
  const double scale = scale_;
  Kokkos::parallel_for(
      "body force scale", Kokkos::RangePolicy<ExecSpace>(0, R.extent(0)), KOKKOS_LAMBDA(int e) {
        for (int k = 0; k < 24; ++k) R(e, k) = scale * load(e, k);
      });
}

}  // namespace capstan
