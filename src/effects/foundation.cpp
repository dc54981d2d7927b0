#include "foundation.hpp"

#include "../../kernels/foundation.hpp"
#include "../mesh.hpp"
#include "entities.hpp"
#include "../step_record.hpp"

#include <Teuchos_CommHelpers.hpp>

namespace capstan {

using detail::dofsOf;
using detail::loadEntities;

FoundationEffect::FoundationEffect(const Mesh& mesh, const SupportSpec& support)
    : Effect("foundation:" + support.name), support_(support.name), k_(support.stiffness) {
  const auto& components = support.components;
  const auto& quads = mesh.faces.at(support.face);
  const size_t nf = quads.size() / 4;
  loadEntities(mesh, quads, "foundation", nodes_, X_);
  for (int i = 0; i < 3; ++i) mask_[i] = components[i] ? 1 : 0;
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("foundation R", nf, 12);
  local_.stiff = true;
}

void FoundationEffect::launch(const NodalVectors&, const NodalVectors& u, bool tangent, const TangentSink& sink) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
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
        double K[12 * 12];
        kernels::foundationResidualTangent(Xf, uf, k, mask, &R(f, 0), tangent ? K : nullptr);
        if (tangent) sink.take<12>(f, K);
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

void FoundationEffect::report(const Teuchos::Comm<int>& comm, StepRecord& rec) const {
  const auto local = localForceOnBody();
  std::array<double, 3> force{};
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, 3, local.data(), force.data());
  for (auto& s : rec.supports)
    if (s.name == support_) s.force = force;
}

}  // namespace capstan
