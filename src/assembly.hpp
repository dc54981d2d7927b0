// The one assembly path: every effect's per-entity residual and tangent go
// through the same scatter into Tpetra's finite-element objects (owned plus
// shared rows, one export per assembly), then the supports' constraints are
// applied symmetrically and the rigid cores' chain rule is added. The effects
// come from src/effects/factory.hpp, the held dofs from src/constraints.hpp,
// the cores from src/rigid_cores.hpp.
#pragma once

#include <Tpetra_FEMultiVector.hpp>
#include <Tpetra_Import.hpp>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "assembly_types.hpp"
#include "constraints.hpp"
#include "effects/factory.hpp"
#include "mesh.hpp"
#include "rigid_cores.hpp"
#include "scene.hpp"

namespace capstan {

class Assembly {
 public:
  Assembly(const Mesh& mesh, const Scene& scene);

  const Mesh& mesh() const { return mesh_; }
  // Owned dofs: the owned nodes' (3 each, in node order), then on rank 0 the
  // rigid cores' (6 each).
  RCP<const Map> dofMap() const { return ownedDofMap_; }
  // Whether the dof with this local id in dofMap() is held (a constrained row).
  bool ownedConstrained(LO d) const { return constraints_.held(layout_.assemblyDof(d)); }
  const std::vector<RigidCore>& rigidCores() const { return cores_.records(); }
  RigidCores& cores() { return cores_; }
  // Local id in dofMap() of a rigid core's dof j (0..5) on rank 0, -1 elsewhere.
  LO ownedCoreDof(size_t core, int j) const {
    return layout_.coresOwned ? LO(3 * mesh_.numOwnedNodes + kCoreUnknowns * core + j) : -1;
  }
  RCP<FEMatrix> createMatrix() const;
  const Constraints& constraints() const { return constraints_; }
  BrickEffect& bricks() { return *effects_.bricks; }
  const std::vector<std::unique_ptr<Effect>>& effects() const { return effects_.all; }
  const std::vector<ContactEffect*>& contacts() const { return effects_.contacts; }
  // Per capstan (as contacts()): its friction effect, or null without friction.
  const std::vector<FrictionEffect*>& frictions() const { return effects_.frictions; }
  // The friction effects there are (loops over every friction: no nulls).
  const std::vector<FrictionEffect*>& frictionsPresent() const { return effects_.frictionsPresent; }
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
  // Translates the whole body with rigid core c by delta (its free components).
  void translateWithCore(Vector& u, size_t c, const std::array<double, 3>& delta) {
    cores_.translate(u.getDataNonConst(), c, delta);
  }
  // Sets the constrained entries of u to their values at time t, and the rigid
  // cores' face nodes to where the cores' values in u put them.
  void applyConstraints(Vector& u, double t);

  // Runs every effect at u into the residual f and tangent W (each if not null); a constrained row
  // has f = 0 and W's identity (u holds its value). With z and Kz: Kz = K z, unconstrained, from
  // these element tangents (the predictor's load). False if an element is inverted.
  bool evaluate(const Vector& u, Vector* f, FEMatrix* W, const Vector* z = nullptr, Vector* Kz = nullptr);
  // z = prescribed displacement increment from t0 to t1 (zero on free dofs).
  // turned: the cores' prescribed turns already in u (Constraints::increment).
  void constraintIncrement(Vector& z, double t0, double t1, bool turned = false) const;

  // Effect e's per-entity vectors (values: entities x dofs, e.g. d v_e / d x) as sparse rows over
  // dofMap()'s free dofs, by the matrix's chain rule (held dofs drop): row r is
  // cols/vals[rowStart[r], rowStart[r + 1]); entities: row r's entity, if given. A gradient
  // takes the columns' chain; a residual's entries (residual = true: a column dR/dmu) the rows'
  // (the cores' rows as the residual holds them: the torque over the core's radius).
  void chainRows(const Effect& e, const Matrix& values, std::vector<size_t>& rowStart, std::vector<GO>& cols,
                 std::vector<double>& vals, const std::vector<int>* entities = nullptr, bool residual = false) const;

  // Reaction force of each constrained support on the body, from the last
  // evaluation (global sum).
  std::vector<std::array<double, 3>> constraintReactions() const;
  // Current positions and displacements of the overlapped nodes (last evaluation).
  const NodalVectors& positions() const { return x_; }
  const NodalVectors& displacements() const { return u_; }
  double assemblySeconds() const { return assemblySeconds_; }
  // Seconds of evaluate() by phase, summed over the run (not in summary.json).
  struct PhaseSeconds {
    double import = 0;         // u (and z) to the overlapped dofs, the nodes' x and u
    double launch = 0;         // the effects' kernels, their tangents into W, min det F
    double scatter = 0;        // per-entity residuals (and K z) summed into owned rows
    double constraints = 0;    // held rows: f = 0, W's unit diagonal
    double coreCoupling = 0;   // the cores' rows and the chain rule at their face nodes
    double matrixExport = 0;   // W's shared rows added into their owners
  };
  const PhaseSeconds& phaseSeconds() const { return phases_; }

 private:
  // evaluate()'s phases, in order (each timed into phases_).
  void importState(const Vector& u, const Vector* z);
  bool launchEffects(FEMatrix* W, const Vector* z, std::vector<Matrix>& KzLocal);
  void scatterResiduals(Vector* f, FEMatrix* W, Vector* Kz, const std::vector<Matrix>& KzLocal);
  void constrainRows(Vector* f, FEMatrix* W);
  void coupleCores(Vector* f, FEMatrix* W, Vector* Kz);

  void sumEntityVectors(const std::vector<Matrix>& values);  // into residual_ (owned)
  void buildGraph();
  void buildTangentSinks();
  void buildDofMaps();

  const Mesh& mesh_;
  SceneEffects effects_;     // src/effects/factory.hpp: every effect, in evaluation order
  RigidCores cores_;
  Constraints constraints_;
  DofLayout layout_;         // the cores' (RigidCores::layout)
  size_t extraColumns_ = 0;  // per row beyond the bricks' 81 (steady friction)
  RCP<const Map> ownedDofMap_, overlapDofMap_;
  std::vector<LO> columnOf_;            // per assembly dof: local column of the matrix, or -1
  double time_ = 0;
  RCP<FEGraph> graph_;
  std::vector<std::vector<LO>> columns_;  // per effect: [entity * dofs + k] matrix column ids
  // Per effect: where its kernel adds each entity's tangent (effects/effect.hpp), found once: a
  // 4-byte CRS offset per 3-column block (< 2^31 entries a rank), held columns, copies kept for the
  // cores (docs/performance.md, "Assembly without stored element tangents").
  std::vector<TangentSink> sinks_;
  RCP<const Tpetra::Import<>> importer_;
  RCP<Vector> uOverlap_, zOverlap_;
  RCP<Tpetra::FEMultiVector<>> residual_;
  std::vector<double> rawOwnedResidual_;  // the owned residual before constraints (reactions, core sums)
  NodalVectors x_, u_;
  double assemblySeconds_ = 0;
  PhaseSeconds phases_;
};

}  // namespace capstan
