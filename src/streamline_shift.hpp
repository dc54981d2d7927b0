// The streamline shift: the first guess of a rolling increment that keeps the
// body's shape standing in space (docs/numerics.md, "Predictors").
//
// A roller in steady rolling keeps its shape in space while its material turns
// through it: the nip's flattening stays at the nip. So after an increment that
// turns the core by dTheta, each material point X sits where the point dTheta
// downstream of it sat before, x_new(X) = x_old(Rot(dTheta) X). The value there
// is interpolated along X's ring of nodes (the nodes at its radius and axial
// position about the core's axis), linearly in angle on x_old turned back by
// each node's angle (a plain interpolation of positions would cut the ring's
// chords, by about as much as the indentation on the slice's mesh). The rigid
// roll (Predictors::rollWithCores) instead carries the flattening round with
// the material, which Newton must then undo.
//
// The multipliers (pressure anchors, contact pressures, stick tractions) stand
// in space as well, so they move the same way (shiftMultipliers): each site's
// value becomes the one dTheta downstream along its ring of sites (the sites
// on the same rings of nodes), linear in angle. Tractions are spatial vectors
// and are not turned.
//
// Every rank holds every node's reference position and, per shift, every
// node's displacement (a replicated import): O(nodes) memory per rank.
#pragma once

#include <map>
#include <vector>

#include "assembly_types.hpp"

namespace capstan {

struct Mesh;
struct RigidCore;
class Effect;

class StreamlineShift {
 public:
  StreamlineShift(const Mesh& mesh, const RCP<const Map>& ownedDofs);
  // u (owned dofs) from the converged state to the shifted one, for core
  // `core` (as u puts it: its translation) turning by dTheta; rotationLid: the
  // local id of its rotation unknown in u, or -1 on ranks that do not own it.
  void apply(Vector& u, const RigidCore& core, size_t coreIndex, double dTheta, LO rotationLid);
  // An effect's multipliers moved likewise (Effect::multiplierSites); nothing
  // for effects without sites. Collective.
  void shiftMultipliers(Effect& effect, const RigidCore& core, size_t coreIndex, double dTheta);

 private:
  struct Rings {
    std::vector<std::vector<std::pair<double, GO>>> rings;  // per ring: (angle, node), by angle
    std::vector<double> angle;                              // per node: its angle
    std::vector<int> ring;                                  // per node: its ring
  };
  const Rings& ringsOf(const RigidCore& core, size_t coreIndex);

  const Mesh& mesh_;
  RCP<const Map> all_;                 // every node's dofs on every rank
  RCP<Tpetra::Import<>> import_;       // owned dofs -> all_
  std::vector<double> X_;              // every node's reference position
  std::map<size_t, Rings> rings_;      // per core
};

}  // namespace capstan
