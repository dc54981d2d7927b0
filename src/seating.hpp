// A free core's body seated against its capstan before the first step. A scene can start with a
// capstan overlapping the body by far more than its surface cells are thick (a tilted capstan axis
// turns the Hertz ring's 0.01 overlap into 0.21 at one end). The first Newton solve must then
// squeeze that overlap out of the thin cells at the surface, and fails at every cut: a cut does
// not lessen an overlap present at t = 0. Where the body's core is free to translate (held by
// contact and its own force) and the overlap exceeds the shortest contact face edge, the body is
// moved rigidly with it, along its free directions, until the overlap is a quarter of that edge.
// Only the first guess moves; the problem and its solution stay as they are (docs/numerics.md,
// "Predictors").
#pragma once

#include "log.hpp"
#include "model.hpp"

namespace capstan {

// Seating applies where the largest overlap exceeds this fraction of the shortest contact face edge,
// and brings it down to kSeatedOverlap of it. Designed preloads stay below: the Hertz ring starts
// at 0.28 of its edge, the 3D drive at 0.66 (seated from 0.5, its step 1 took 8 Newton iterations
// against 10 and its 20 steps the same speed ratio to 4e-11).
constexpr double kSeatingOverlap = 1.0;
constexpr double kSeatedOverlap = 0.25;

// Moves u (constraints at the interval's end applied) where seating applies and its residual is
// below `bare`, the residual at u as given. Returns the translation's length (0: not moved).
double seatFreeCore(Model& m, Log& log, double t, double bare);

}  // namespace capstan
