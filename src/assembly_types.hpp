// What Assembly, RigidCores and Constraints share: the Tpetra objects the
// assembly fills, and its numbering of the unknowns.
#pragma once

#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_FECrsGraph.hpp>
#include <Tpetra_FECrsMatrix.hpp>
#include <Tpetra_Vector.hpp>

#include "mesh.hpp"
#include "support_settings.hpp"

namespace capstan {

using Vector = Tpetra::Vector<>;
using CrsMatrix = Tpetra::CrsMatrix<>;
using FEMatrix = Tpetra::FECrsMatrix<>;
using FEGraph = Tpetra::FECrsGraph<>;

// "Assembly dofs": 3 * overlapped node + component, then kCoreUnknowns per
// rigid core. The cores' dofs are global, owned by rank 0.
struct DofLayout {
  int nodeDofs = 0;          // 3 x overlapped nodes: the first core dof
  int ownedNodeDofs = 0;     // 3 x owned nodes
  int cores = 0;             // rigid cores
  bool coresOwned = false;   // this rank owns the cores' dofs

  DofLayout() = default;
  DofLayout(const Mesh& mesh, size_t numCores)
      : nodeDofs(int(3 * mesh.numOverlapNodes())), ownedNodeDofs(int(3 * mesh.numOwnedNodes)), cores(int(numCores)),
        coresOwned(numCores > 0 && mesh.comm->getRank() == 0) {}
  int size() const { return nodeDofs + kCoreUnknowns * cores; }
  // Assembly dofs <-> local ids of the Tpetra maps. Overlapped order: owned
  // node dofs, (rank 0) the cores' dofs, ghost node dofs, (other ranks) the
  // cores' dofs: Tpetra's finite-element objects need the owned ids first.
  LO overlapLid(int dof) const {
    if (dof >= nodeDofs) return LO(coresOwned ? ownedNodeDofs + (dof - nodeDofs) : dof);
    return LO(coresOwned && dof >= ownedNodeDofs ? dof + kCoreUnknowns * cores : dof);
  }
  int assemblyDof(LO ownedLid) const {
    return ownedLid < LO(ownedNodeDofs) ? int(ownedLid) : nodeDofs + int(ownedLid - LO(ownedNodeDofs));
  }
};

}  // namespace capstan
