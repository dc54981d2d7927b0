#include "constraints.hpp"

#include <Teuchos_CommHelpers.hpp>

#include "rigid_cores.hpp"
#include "scene.hpp"

namespace capstan {

Constraints::Constraints(const Mesh& mesh, const Scene& scene, RigidCores& cores) : layout_(cores.layout()) {
  const size_t ndof = size_t(layout_.size());
  supportOf.assign(ndof, -1);
  velocity.assign(ndof, 0.0);
  constant.assign(ndof, 0);
  for (const auto& s : scene.supports) {
    if (s.type == SupportSpec::Type::Foundation) continue;  // an effect (src/effects/factory.hpp), no held dofs
    const int id = int(supportNames.size());
    supportNames.push_back(s.name);
    if (s.isCore()) {
      const int c = cores.find(s.name);
      const RigidCore& core = cores.records()[c];
      cores.setSupport(c, id);
      for (size_t n = 0; n < mesh.numOverlapNodes(); ++n)
        if (cores.coreOf(n) == c)
          for (int i = 0; i < 3; ++i) supportOf[3 * n + i] = id;
      for (int j = 0; j < kCoreUnknowns; ++j) {
        if (j < 4 && core.free[j]) continue;  // an unknown of the Newton solve
        supportOf[core.firstDof + j] = id;
        velocity[core.firstDof + j] = j == 3 && s.rotation == SupportSpec::Rotation::Prescribed ? s.angularVelocity : 0.0;
        constant[core.firstDof + j] = j == 3 && scene.analysis.steady();
      }
      continue;
    }
    // Fixed, Roller, Displacement: the first support in the scene that holds a
    // dof owns it (and its reaction).
    for (int n : mesh.faceNodes(s.face))
      for (int i = 0; i < 3; ++i) {
        if (!s.components[i] || supportOf[3 * n + i] >= 0) continue;
        supportOf[3 * n + i] = id;
        velocity[3 * n + i] = s.type == SupportSpec::Type::Displacement ? s.velocity[i] : 0.0;
      }
  }
}

void Constraints::apply(Vector& u, double t, const RigidCores& cores) const {
  auto data = u.getDataNonConst();
  for (LO d = 0; d < LO(data.size()); ++d) {
    const int a = layout_.assemblyDof(d);
    if (supportOf[a] >= 0 && !cores.follows(a)) data[d] = constant[a] ? velocity[a] : velocity[a] * t;
  }
}

void Constraints::increment(Vector& z, double t0, double t1, const RigidCores& cores, bool turned) const {
  auto data = z.getDataNonConst();
  for (LO d = 0; d < LO(data.size()); ++d) {
    const int a = layout_.assemblyDof(d);
    if (cores.follows(a)) {
      // Linearised at the cores' last state: dT + b dtheta, held parts only.
      const auto& core = cores.records()[cores.coreOf(a / 3)];
      const int i = a % 3;
      const double dT = supportOf[core.firstDof + i] >= 0 ? velocity[core.firstDof + i] * (t1 - t0) : 0.0;
      const int r = core.firstDof + 3;
      const double dTheta = supportOf[r] >= 0 && !constant[r] && !turned ? velocity[r] * (t1 - t0) : 0.0;
      data[d] = dT + cores.follower(a / 3).b[i] * dTheta;
    } else {
      data[d] = supportOf[a] >= 0 && !constant[a] ? velocity[a] * (t1 - t0) : 0.0;
    }
  }
}

std::vector<std::array<double, 3>> Constraints::reactions(const std::vector<double>& ownedResidual,
                                                          const Comm& comm) const {
  const size_t ns = supportNames.size();
  std::vector<double> local(3 * ns, 0.0), global(3 * ns, 0.0);
  for (size_t d = 0; d < ownedResidual.size(); ++d) {
    const int a = layout_.assemblyDof(LO(d));
    if (supportOf[a] >= 0) local[3 * supportOf[a] + a % 3] += ownedResidual[d];
  }
  if (ns) Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, int(3 * ns), local.data(), global.data());
  std::vector<std::array<double, 3>> out(ns);
  for (size_t s = 0; s < ns; ++s) out[s] = {global[3 * s], global[3 * s + 1], global[3 * s + 2]};
  return out;
}

void Constraints::locateDiagonal(LO ownedDofs, const std::vector<LO>& columnOf,
                                 const std::function<int(LO, LO)>& offset) {
  std::vector<int> diagonal;
  for (LO d = 0; d < ownedDofs; ++d)
    if (supportOf[layout_.assemblyDof(d)] >= 0) diagonal.push_back(offset(d, columnOf[layout_.assemblyDof(d)]));
  diagonal_ = Kokkos::View<int*>("constrained diagonal", diagonal.size());
  auto hd = Kokkos::create_mirror_view(diagonal_);
  for (size_t j = 0; j < diagonal.size(); ++j) hd(j) = diagonal[j];
  Kokkos::deep_copy(diagonal_, hd);
}

void Constraints::setDiagonal(FEMatrix& W) const {
  const auto values = W.getLocalMatrixDevice().values;
  const auto diagonal = diagonal_;
  Kokkos::parallel_for(
      "constrained diagonal", Kokkos::RangePolicy<ExecSpace>(0, diagonal.extent(0)),
      KOKKOS_LAMBDA(int j) { values(diagonal(j)) = 1.0; });
  Kokkos::fence();
}

}  // namespace capstan
