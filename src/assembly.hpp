// The one assembly path: every effect's per-entity residual and tangent go
// through the same scatter into Tpetra's finite-element objects (owned plus
// shared rows, one export per assembly), then the supports' constraints are
// applied symmetrically.
#pragma once

#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_FECrsGraph.hpp>
#include <Tpetra_FECrsMatrix.hpp>
#include <Tpetra_FEMultiVector.hpp>
#include <Tpetra_Import.hpp>
#include <Tpetra_Vector.hpp>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "../kernels/rigid_core.hpp"
#include "effects/factory.hpp"
#include "mesh.hpp"
#include "scene.hpp"

namespace capstan {

using Vector = Tpetra::Vector<>;
using CrsMatrix = Tpetra::CrsMatrix<>;
using FEMatrix = Tpetra::FECrsMatrix<>;
using FEGraph = Tpetra::FECrsGraph<>;

// Dofs held by Fixed, Roller and Displacement supports (u = velocity * t), and
// by rigid cores: their face's nodes follow the core, and the core's held
// components (translation, rotation, unused slots) are fixed or prescribed.
// Indexed by "assembly dof": 3 * overlapped node + component, then 6 per rigid
// core (Tx Ty Tz theta and two unused slots, so the dofs stay in blocks of 3).
struct Constraints {
  std::vector<std::string> supportNames;  // index = support id
  std::vector<int> supportOf;             // per assembly dof: support id or -1
  std::vector<double> velocity;           // per assembly dof
};

// A rigid core (SupportSpec type Rigid Core) as the assembly keeps it: its
// unknowns q = (T, theta) are global dofs owned by rank 0; its face's nodes
// are eliminated (u = T + (R(theta) - I)(X - A), kernels/rigid_core.hpp).
struct RigidCore {
  std::string name;
  std::array<double, 3> axisPoint{}, axisDirection{}, force{};
  double torque = 0, rampTime = 1;
  std::array<bool, 4> free{};  // Tx Ty Tz theta
  int support = -1;            // its support id in Constraints
  int firstDof = 0;            // assembly dof of Tx
  // At the last evaluation (global): q, and the force and torque of the core
  // on the body (the reactions at its face's nodes).
  std::array<double, 3> translation{};
  double rotation = 0;
  std::array<double, 3> forceOnBody{};
  double torqueOnBody = 0;
  double geometric = 0;  // sum over the face's nodes of R . w (the theta-theta tangent term)
  // External loads at time t: ramped linearly to rampTime, then held.
  double loadFactor(double t) const { return std::min(1.0, t / rampTime); }
};

class Assembly {
 public:
  Assembly(const Mesh& mesh, const Scene& scene);

  const Mesh& mesh() const { return mesh_; }
  // Owned dofs: the owned nodes' (3 each, in node order), then on rank 0 the
  // rigid cores' (6 each).
  RCP<const Map> dofMap() const { return ownedDofMap_; }
  // Whether the dof with this local id in dofMap() is held (a constrained row).
  bool ownedConstrained(LO d) const { return constraints_.supportOf[assemblyDof(d)] >= 0; }
  const std::vector<RigidCore>& rigidCores() const { return cores_; }
  // Local id in dofMap() of a rigid core's dof j (0..5) on rank 0, -1 elsewhere.
  LO ownedCoreDof(size_t core, int j) const {
    return coresOwned_ ? LO(3 * mesh_.numOwnedNodes + 6 * core + j) : -1;
  }
  RCP<FEMatrix> createMatrix() const;
  const Constraints& constraints() const { return constraints_; }
  BrickEffect& bricks() { return *effects_.bricks; }
  const std::vector<std::unique_ptr<Effect>>& effects() const { return effects_.all; }
  const std::vector<FoundationEffect*>& foundations() const { return effects_.foundations; }
  const std::vector<ContactEffect*>& contacts() const { return effects_.contacts; }
  // Per capstan (as contacts()): its friction effect, or null without friction.
  const std::vector<FrictionEffect*>& frictions() const { return effects_.frictions; }
  // The union of all capstans' candidate faces on this rank (4 overlapped node
  // ids each), and for capstan i the union index of each of its faces.
  const std::vector<int>& contactFaceNodes() const { return effects_.contactFaceNodes; }
  const std::vector<int>& contactFacesOf(size_t capstan) const { return effects_.contactFaceOf[capstan]; }

  // The increment being solved (effects that move with time evaluate at tEnd).
  void setInterval(double tStart, double tEnd) {
    time_ = tEnd;
    for (auto& e : effects_.all) e->setInterval(tStart, tEnd);
  }

  // Turns the whole body, with each rigid core whose rotation is free, rigidly
  // about the core's axis by dTheta[core] (a rolling body's first guess).
  void rollWithCores(Vector& u, const std::vector<double>& dTheta);
  // Sets the constrained entries of u to their values at time t, and the rigid
  // cores' face nodes to where the cores' values in u put them.
  void applyConstraints(Vector& u, double t);

  // Runs every effect at displacement u and assembles the residual f (if not
  // null) and the tangent W (if not null). Constrained rows: f = 0 and W has the
  // identity in row and column (u already holds the prescribed values, so the
  // Newton update there is zero and the elimination keeps W's structure).
  // With z and Kz (and W): also Kz = K z with the element tangents of this
  // evaluation, no constraints applied: the load a prescribed increment z
  // causes, for the step predictor (the tangents are not kept to form it later).
  // Returns false if an element is inverted (det F <= 0 at a Gauss point).
  bool evaluate(const Vector& u, Vector* f, FEMatrix* W, const Vector* z = nullptr, Vector* Kz = nullptr);
  // z = prescribed displacement increment from t0 to t1 (zero on free dofs).
  void constraintIncrement(Vector& z, double t0, double t1) const;

  // Per-entity vectors of effect e over its dofs (values: entities x dofs,
  // e.g. each brick's d v_e / d x) as sparse rows over the free global dofs of
  // dofMap(), with the chain rule the matrix assembly applies: a rigid core's
  // face-node entries go to the core's free unknowns (the translations, and
  // the rotation through du/dtheta at the last evaluation); held dofs drop.
  // Row r is cols/vals[rowStart[r] .. rowStart[r + 1]), each column once.
  // entities: row r's entity, if not one row per entity in order.
  void chainRows(const Effect& e, const Matrix& values, std::vector<size_t>& rowStart, std::vector<GO>& cols,
                 std::vector<double>& vals, const std::vector<int>* entities = nullptr) const;

  // Reaction force of each constrained support on the body, from the last
  // evaluation (global sum).
  std::vector<std::array<double, 3>> constraintReactions() const;
  // Current positions and displacements of the overlapped nodes (last evaluation).
  const NodalVectors& positions() const { return x_; }
  const NodalVectors& displacements() const { return u_; }
  double assemblySeconds() const { return assemblySeconds_; }

 private:
  void sumEntityVectors(const std::vector<Matrix>& values);  // into residual_ (owned)
  void buildTangentSinks();
  // Assembly dofs <-> local ids of the Tpetra maps. Overlapped order: owned
  // node dofs, (rank 0) the cores' dofs, ghost node dofs, (other ranks) the
  // cores' dofs: Tpetra's finite-element objects need the owned ids first.
  LO overlapLid(int dof) const;
  int assemblyDof(LO ownedLid) const {
    const LO ownedNodeDofs = LO(3 * mesh_.numOwnedNodes);
    return ownedLid < ownedNodeDofs ? int(ownedLid) : nodeDofs_ + int(ownedLid - ownedNodeDofs);
  }
  void buildDofMaps();
  // The cores' q from the overlapped u, and each face node's follower data.
  void readCores(const Teuchos::ArrayRCP<const double>& uOverlap);
  // Sums over the owned core nodes of v (owned values, a residual or K z): per
  // core {force (3), torque, R . w}, global.
  std::vector<std::array<double, 5>> coreSums(const Teuchos::ArrayRCP<const double>& v) const;
  // d u_dof / d (Tx, Ty, Tz, theta) of the core that a face-node dof follows
  // (at the cores' last q): the chain rule's coefficients.
  std::array<double, 4> coreChain(int dof) const {
    const int i = dof % 3;
    return {i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0, followers_[dof / 3].b[i]};
  }
  // The chain rule at the cores' face nodes: element-matrix entries that touch
  // a face node, carried to the core's free unknowns.
  void assembleCoreCoupling(FEMatrix& W);

  const Mesh& mesh_;
  int nodeDofs_ = 0;                    // 3 x overlapped nodes: the first core dof
  std::vector<RigidCore> cores_;
  std::vector<int> coreOfNode_;         // per overlapped node: its rigid core or -1
  std::vector<kernels::CoreFollower> followers_;  // per overlapped node, at the cores' last q
  bool coresOwned_ = false;             // this rank owns the cores' dofs
  RCP<const Map> ownedDofMap_, overlapDofMap_;
  std::vector<LO> columnOf_;            // per assembly dof: local column of the matrix, or -1
  std::vector<std::vector<int>> coupled_;  // per effect: entities with a core face node
  struct CouplingScratch {                  // assembleCoreCoupling's dense accumulators
    std::vector<double> toCore, fromCore, coreCore;
    std::vector<char> touched;
  } coupling_;
  double time_ = 0;
  SceneEffects effects_;  // src/effects/factory.hpp: every effect, in evaluation order
  Constraints constraints_;
  RCP<FEGraph> graph_;
  std::vector<std::vector<LO>> columns_;  // per effect: [entity * dofs + k] matrix column ids
  // Per effect: where its kernel puts each entity's tangent (effects/effect.hpp): the
  // CRS offsets of its 3-column blocks and held columns, found once (4-byte
  // offsets, one per block: a sixth of the memory and traffic of one 8-byte
  // offset per entry; a rank's matrix holds fewer than 2^31 entries), and the
  // kept copies for the rigid-core chain rule. Each evaluation adds the
  // matrix's values (and the predictor's K z).
  std::vector<TangentSink> sinks_;
  Kokkos::View<int*> constrainedDiagonal_;  // offsets of the owned constrained diagonals
  RCP<const Tpetra::Import<>> importer_;
  RCP<Vector> uOverlap_, zOverlap_;
  RCP<Tpetra::FEMultiVector<>> residual_;
  std::vector<double> rawOwnedResidual_;
  NodalVectors x_, u_;
  double assemblySeconds_ = 0;
};

}  // namespace capstan
