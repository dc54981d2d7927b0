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
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "effects.hpp"
#include "mesh.hpp"
#include "scene.hpp"

namespace capstan {

using Vector = Tpetra::Vector<>;
using CrsMatrix = Tpetra::CrsMatrix<>;
using FEMatrix = Tpetra::FECrsMatrix<>;
using FEGraph = Tpetra::FECrsGraph<>;

// Dofs held by Fixed, Roller and Displacement supports: u = velocity * t.
struct Constraints {
  std::vector<std::string> supportNames;  // index = support id
  std::vector<int> supportOf;             // per overlapped dof: support id or -1
  std::vector<double> velocity;           // per overlapped dof
};

class Assembly {
 public:
  Assembly(const Mesh& mesh, const Scene& scene);

  const Mesh& mesh() const { return mesh_; }
  RCP<const Map> dofMap() const { return mesh_.ownedDofMap; }
  RCP<FEMatrix> createMatrix() const;
  const Constraints& constraints() const { return constraints_; }
  BrickEffect& bricks() { return *bricks_; }
  const std::vector<std::unique_ptr<Effect>>& effects() const { return effects_; }
  const std::vector<FoundationEffect*>& foundations() const { return foundations_; }
  const std::vector<ContactEffect*>& contacts() const { return contacts_; }
  // Per capstan (as contacts()): its friction effect, or null without friction.
  const std::vector<FrictionEffect*>& frictions() const { return frictions_; }
  // The union of all capstans' candidate faces on this rank (4 overlapped node
  // ids each), and for capstan i the union index of each of its faces.
  const std::vector<int>& contactFaceNodes() const { return contactFaceNodes_; }
  const std::vector<int>& contactFacesOf(size_t capstan) const { return contactFaceOf_[capstan]; }

  // The increment being solved (effects that move with time evaluate at tEnd).
  void setInterval(double tStart, double tEnd) {
    for (auto& e : effects_) e->setInterval(tStart, tEnd);
  }

  // Sets the constrained entries of u to their values at time t.
  void applyConstraints(Vector& u, double t) const;

  // Runs every effect at displacement u and assembles the residual f (if not
  // null) and the tangent W (if not null). Constrained rows: f = 0 and W has the
  // identity in row and column (u already holds the prescribed values, so the
  // Newton update there is zero and the elimination keeps W's structure).
  // Returns false if an element is inverted (det F <= 0 at a Gauss point).
  bool evaluate(const Vector& u, Vector* f, FEMatrix* W);

  // y = K z with the element tangents of the last evaluation (no constraints
  // applied): the load a prescribed increment z causes, for the step predictor.
  void tangentAction(const Vector& z, Vector& y);
  // z = prescribed displacement increment from t0 to t1 (zero on free dofs).
  void constraintIncrement(Vector& z, double t0, double t1) const;

  // Reaction force of each constrained support on the body, from the last
  // evaluation (global sum).
  std::vector<std::array<double, 3>> constraintReactions() const;
  // Current positions and displacements of the overlapped nodes (last evaluation).
  const NodalVectors& positions() const { return x_; }
  const NodalVectors& displacements() const { return u_; }
  double assemblySeconds() const { return assemblySeconds_; }

 private:
  void sumEntityVectors(const std::vector<Matrix>& values);  // into residual_ (owned)
  void findEntryOffsets();

  const Mesh& mesh_;
  std::vector<std::unique_ptr<Effect>> effects_;
  BrickEffect* bricks_ = nullptr;
  std::vector<FoundationEffect*> foundations_;
  std::vector<ContactEffect*> contacts_;
  std::vector<FrictionEffect*> frictions_;
  std::map<std::array<int, 4>, int> contactFaceIndex_;
  std::vector<int> contactFaceNodes_;
  std::vector<std::vector<int>> contactFaceOf_;
  Constraints constraints_;
  RCP<FEGraph> graph_;
  std::vector<std::vector<LO>> columns_;  // per effect: [entity * dofs + k] matrix column ids
  // Per effect: where each element-matrix entry (entity, k, l) lands in the
  // values of the local (owned plus shared) CRS matrix, -1 for entries of
  // constrained rows or columns. Found once, so assembly is a plain scatter.
  std::vector<Kokkos::View<long***, Kokkos::LayoutRight>> entryOffsets_;
  Kokkos::View<long*> constrainedDiagonal_;  // offsets of the owned constrained diagonals
  RCP<const Tpetra::Import<>> importer_;
  RCP<Vector> uOverlap_;
  RCP<Tpetra::FEMultiVector<>> residual_;
  std::vector<double> rawOwnedResidual_;
  NodalVectors x_, u_;
  double assemblySeconds_ = 0;
};

}  // namespace capstan
