// The supports that hold dofs: Fixed, Roller, Displacement, and the held parts
// of the rigid cores. Foundations are effects (src/effects/foundation.hpp).
#pragma once

#include <Kokkos_Core.hpp>

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "assembly_types.hpp"

namespace capstan {

struct Scene;
class RigidCores;

// Dofs held by Fixed, Roller and Displacement supports (u = velocity * t), and
// by rigid cores: their face's nodes follow the core, and the core's held
// components (translation, rotation, unused slots) are fixed or prescribed.
// Indexed by assembly dof (assembly_types.hpp, DofLayout).
class Constraints {
 public:
  Constraints() = default;
  // Support ids in scene order (foundations aside); records each core's id.
  Constraints(const Mesh& mesh, const Scene& scene, RigidCores& cores);

  std::vector<std::string> supportNames;  // index = support id
  std::vector<int> supportOf;             // per assembly dof: support id or -1
  std::vector<double> velocity;           // per assembly dof
  // Per assembly dof: held at `velocity` itself, not velocity * t (steady
  // rolling's prescribed angular velocity: the core's unknown is omega there).
  std::vector<char> constant;

  bool held(int dof) const { return supportOf[dof] >= 0; }
  // Sets u's held entries (owned values) to their values at time t, except a
  // core's face nodes (they follow the core: RigidCores::placeFaceNodes).
  void apply(Vector& u, double t, const RigidCores& cores) const;
  // z = prescribed displacement increment from t0 to t1 (zero on free dofs);
  // a core's face nodes linearised at the cores' last state.
  // turned: the cores' prescribed turns are already in u (Predictors' roll), so left out.
  void increment(Vector& z, double t0, double t1, const RigidCores& cores, bool turned = false) const;
  // Reaction force of each support on the body: the sum of the owned residual
  // (before constraints) over its held dofs, global (collective).
  std::vector<std::array<double, 3>> reactions(const std::vector<double>& ownedResidual, const Comm& comm) const;

  // The held rows' diagonal in the matrix: its CRS offsets found once
  // (offset(local row, local column)), then set to 1 at each assembly.
  void locateDiagonal(LO ownedDofs, const std::vector<LO>& columnOf, const std::function<int(LO, LO)>& offset);
  void setDiagonal(FEMatrix& W) const;

 private:
  DofLayout layout_;
  Kokkos::View<int*> diagonal_;  // offsets of the owned constrained diagonals
};

}  // namespace capstan
