// What a rolling scene (an annulus on a rigid core, driven by a spinning
// capstan) needs beyond the effects: the no-slip reference speed and why a
// braked roller may have no equilibrium.
#pragma once

#include <string>

#include "scene.hpp"

namespace capstan {

struct RigidCore;

// The core's angular velocity when its outer (undeformed) surface rolls
// without slip on the first spinning capstan (external contact: it turns
// against the capstan); 0 when there is none. The speed ratio is the core's
// angular velocity over this.
double noSlipAngularVelocity(const Scene& scene, const RigidCore& core);
// The speed ratio of a core turning at angularVelocity: that over the no-slip one; NaN where
// there is none.
double speedRatio(const Scene& scene, const RigidCore& core, double angularVelocity);

// Why a step may have no equilibrium at all: a core's applied torque beyond
// what friction in the nip can carry ("; support ...: ..."), or empty.
std::string brakeDiagnosis(const Scene& scene);

// Why a free roller may find no position of rest: a core free to turn (or on a capstan without
// friction), pressed by its Force onto the scene's only capstan and free to translate in two
// directions normal to the capstan's axis, rolls (slides) off the capstan, as a ball off the top
// of a dome (its one position of rest is unstable). The description
// ("support ...: ..."), or empty; the scene warns of it and a failed run repeats it.
std::string rollOffDiagnosis(const Scene& scene);

// Why quasi-static rolling may miss the nip: a spinning capstan's surface moving more than
// kMostNipCellsPerStep of the annulus' narrowest cells round in a step, beyond which the speed
// ratio strays (the description, "capstan ...: ..."), or empty; the scene warns of it.
std::string fastRollingDiagnosis(const Scene& scene);

// What to try where a rolling step on an annulus under Coulomb's exact stick stalled (failure: its
// reason), or empty: stick and slip can chatter on a fine nip over a thick outer cell, where a Tanh
// law or more radial cells converge (docs/steady-rolling.md, "Stick and slip that cycle").
std::string stickChatterHint(const Scene& scene, const std::string& failure);

}  // namespace capstan
