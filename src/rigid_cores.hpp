// The scene's rigid cores (supports of type Rigid Core): their unknowns, the
// face nodes that follow them, and the chain rule that carries the body's
// residual and tangent at those nodes to the cores' unknowns. The assembly
// asks them for their part of each phase (src/assembly.cpp).
#pragma once

#include <Teuchos_ArrayRCP.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "../kernels/rigid_core.hpp"
#include "assembly_types.hpp"
#include "effects/effect.hpp"

namespace capstan {

struct Scene;
class Constraints;

// A rigid core as the assembly keeps it: unknowns q = (T, theta), global dofs on rank 0; face nodes
// eliminated (u = T + (R(theta) - I)(X - A), kernels/rigid_core.hpp). Steady rolling
// (formulation.md §8): the mesh stands, face nodes at X + T, 4th unknown omega (torque balance).
struct RigidCore {
  std::string name;
  std::array<double, 3> axisPoint{}, axisDirection{}, force{};
  double torque = 0, rampTime = 1, torqueRampTime = 1;
  std::array<bool, 4> free{};  // Tx Ty Tz theta
  int support = -1;            // its support id in Constraints
  int firstDof = 0;            // assembly dof of Tx
  // At the last evaluation (global): q, and the force and torque of the core
  // on the body (the reactions at its face's nodes).
  std::array<double, 3> translation{};
  double rotation = 0;
  double angularVelocity = 0;  // steady rolling: the fourth unknown
  // Steady rolling's start (LoadStepper): omega held at this value by its own
  // row (omega - heldAngularVelocity = 0) while free, where NaN: not held.
  double heldAngularVelocity = std::numeric_limits<double>::quiet_NaN();
  bool holding() const { return !std::isnan(heldAngularVelocity); }
  // A torque as the core's torque row holds it: over the radius (below), and nothing
  // while omega is held (the row is then omega - held).
  double torqueRow(double torque) const { return holding() ? 0.0 : torque / radius; }
  std::array<double, 3> forceOnBody{};
  double torqueOnBody = 0;
  double geometric = 0;  // sum over the face's nodes of R . w (the theta-theta tangent term)
  // The face's largest distance from the axis. The torque balance's row is divided by it (a
  // force at the face), so Newton's merit |R| weighs it like the force rows in any units.
  double radius = 1;
  // External loads at time t: ramped linearly to rampTime (the torque to
  // torqueRampTime), then held.
  double loadFactor(double t) const { return std::min(1.0, t / rampTime); }
  double torqueFactor(double t) const { return std::min(1.0, t / torqueRampTime); }
};

class RigidCores {
 public:
  // The scene's cores in scene order, each with the next 6 assembly dofs after
  // the node dofs. A face node belongs to the first core that names it.
  RigidCores(const Mesh& mesh, const Scene& scene);

  bool empty() const { return cores_.empty(); }
  size_t size() const { return cores_.size(); }
  const DofLayout& layout() const { return layout_; }
  const std::vector<RigidCore>& records() const { return cores_; }
  // The core named `name` (a Rigid Core support), or -1.
  int find(const std::string& name) const;
  void setSupport(int core, int id) { cores_[core].support = id; }
  // Per overlapped node: its core, or -1.
  int coreOf(size_t node) const { return coreOfNode_[node]; }
  // Whether an assembly dof is a face node's, which follows its core.
  bool follows(int dof) const { return dof < layout_.nodeDofs && coreOfNode_[dof / 3] >= 0; }
  // A face node's displacement and derivatives at the cores' last q (read()).
  const kernels::CoreFollower& follower(size_t node) const { return followers_[node]; }
  // The chain rule's coefficients for a face-node dof: rows (the moment of
  // the reactions: the torque balance) take b; columns take d u_dof / d q,
  // (Tx, Ty, Tz, theta) of the core it follows at the cores' last q, which
  // in steady rolling has no omega part (the face nodes sit at X + T).
  std::array<double, 4> chain(int dof) const {
    const int i = dof % 3;
    return {i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0, followers_[dof / 3].b[i]};
  }
  std::array<double, 4> chainColumn(int dof) const {
    auto B = chain(dof);
    if (steady_) B[3] = 0;
    return B;
  }
  bool steady() const { return steady_; }
  // Steady rolling's start: hold core c's free omega at `value` (NaN: free again).
  void holdAngularVelocity(size_t c, double value) { cores_[c].heldAngularVelocity = value; }

  // The cores' q from the overlapped u, and each face node's follower data.
  void read(const Teuchos::ArrayRCP<const double>& uOverlap);
  // The owned face nodes of u (owned values) where the cores' last q puts them.
  void placeFaceNodes(const Teuchos::ArrayRCP<double>& u) const;
  // Turns the whole body (owned values of u), with each core whose rotation is
  // free, rigidly about the core's axis by dTheta[core], and that core's theta.
  void roll(const Teuchos::ArrayRCP<double>& u, const std::vector<double>& dTheta) const;
  // Translates the whole body (owned values of u) and core c's translation by delta.
  void translate(const Teuchos::ArrayRCP<double>& u, size_t c, const std::array<double, 3>& delta) const;

  // Sums over the owned core nodes of v (owned values, a residual or K z): per
  // core {force (3), torque, R . w}, global (collective). rowSums: the same as
  // the cores' rows hold them ({force (3), torque / radius}, 0 for a held omega).
  std::vector<std::array<double, 5>> sums(const double* v) const;
  std::vector<std::array<double, 4>> rowSums(const double* v) const;
  // The reactions at the face nodes from the owned residual (collective).
  void setReactions(const double* ownedResidual);
  // The residual of a core's free unknown (assembly dof `dof`) at time t: the
  // reactions it exerts on the body balance the external load on it.
  double residual(int dof, double t) const {
    const auto& core = cores_[(dof - layout_.nodeDofs) / 6];
    const int j = (dof - layout_.nodeDofs) % 6;
    if (j == 3 && core.holding()) return core.angularVelocity - core.heldAngularVelocity;
    return j < 3 ? core.forceOnBody[j] - core.loadFactor(t) * core.force[j]
                 : core.torqueRow(core.torqueOnBody - core.torqueFactor(t) * core.torque);
  }

  // The matrix graph. findCoupling: each stiff effect's entities with a face
  // node (their tangents are kept for the chain rule) and each core's row length.
  void findCoupling(const std::vector<std::unique_ptr<Effect>>& effects);
  const std::vector<int>& coupled(size_t effect) const { return coupled_[effect]; }
  // Entries in each row of core c: one per dof of the elements at its face,
  // and every core's 6.
  size_t rowEntries(size_t core) const { return rowEntries_[core]; }
  // Appends to cols (global ids, by gid(assembly dof)) the free unknowns of the
  // cores whose face nodes are among an entity's n dofs.
  template <class Gid>
  void appendFreeUnknowns(const int* dofs, size_t n, const Gid& gid, std::vector<GO>& cols) const {
    if (cores_.empty()) return;
    std::set<int> touched;
    for (size_t k = 0; k < n; ++k)
      if (dofs[k] < layout_.nodeDofs && coreOfNode_[dofs[k] / 3] >= 0) touched.insert(coreOfNode_[dofs[k] / 3]);
    for (int c : touched)
      for (int j = 0; j < 4; ++j)
        if (cores_[c].free[j]) cols.push_back(gid(cores_[c].firstDof + j));
  }
  // The free unknowns a face-node dof moves with, f(core dof, du_dof/dq): its
  // own translation component and the rotation (kept even where du/dtheta is
  // 0, so that every evaluation has the same columns).
  template <class F>
  void forEachFreeUnknown(int dof, const F& f) const {
    const RigidCore& core = cores_[coreOfNode_[dof / 3]];
    const auto B = chainColumn(dof);
    for (int q = 0; q < 4; ++q)
      if (core.free[q] && (q == 3 || q == dof % 3)) f(core.firstDof + q, B[q]);
  }
  // The free cores' rows a residual entry at a face-node dof adds to, f(core dof, factor): its
  // force component, and the torque balance by its lever arm over the core's radius.
  template <class F>
  void forEachFreeRow(int dof, const F& f) const {
    const RigidCore& core = cores_[coreOfNode_[dof / 3]];
    const auto B = chain(dof);
    for (int q = 0; q < 3; ++q)
      if (core.free[q] && q == dof % 3) f(core.firstDof + q, B[q]);
    if (core.free[3] && !core.holding()) f(core.firstDof + 3, core.torqueRow(B[3]));
  }

  // The chain rule at the cores' face nodes: the kept element-matrix entries
  // that touch a face node (sinks[i].kept for effect i), carried to the cores'
  // free unknowns in W (local columns columnOf[assembly dof]).
  void assembleCoupling(FEMatrix& W, const std::vector<std::unique_ptr<Effect>>& effects,
                        const std::vector<TangentSink>& sinks, const std::vector<LO>& columnOf,
                        const Constraints& constraints);

 private:
  static double distanceFromAxis(const RigidCore& core, const double* X);
  const Mesh& mesh_;
  bool steady_ = false;  // Analysis/Type = Steady Rolling
  DofLayout layout_;
  std::vector<RigidCore> cores_;
  std::vector<int> coreOfNode_;                   // per overlapped node: its rigid core or -1
  std::vector<kernels::CoreFollower> followers_;  // per overlapped node, at the cores' last q
  std::vector<std::vector<int>> coupled_;         // per effect: entities with a core face node
  std::vector<size_t> rowEntries_;                // per core
  struct CouplingScratch {                        // assembleCoupling's dense accumulators
    std::vector<double> toCore, fromCore, coreCore;
    std::vector<char> touched;
  } coupling_;
};

}  // namespace capstan
