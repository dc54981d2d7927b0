// The one place that turns a scene into effects: every effect the scene names,
// built from the mesh and the scene, in the order the assembly evaluates them.
#pragma once

#include <memory>
#include <vector>

#include "body_force.hpp"
#include "bricks.hpp"
#include "contact.hpp"
#include "effect.hpp"
#include "foundation.hpp"
#include "friction.hpp"
#include "steady_friction.hpp"

namespace capstan {

struct Mesh;
struct Scene;

struct SceneEffects {
  // Every effect, owned, in evaluation order: the bricks, the foundations (in
  // the scene's support order), the body force, then per capstan its contact
  // and its friction. summary.json and checkpoints list the effects in this
  // order and the residual is summed in it, so it must not change.
  std::vector<std::unique_ptr<Effect>> all;
  BrickEffect* bricks = nullptr;
  std::vector<ContactEffect*> contacts;    // per capstan
  std::vector<FrictionEffect*> frictions;  // per capstan; null without friction
  std::vector<FrictionEffect*> frictionsPresent;  // the capstans' with friction only, in capstan order
  // The union of all capstans' candidate faces on this rank (4 overlapped node
  // ids each), and per capstan the union index of each of its faces (the
  // contact-face grid of fields.h5).
  std::vector<int> contactFaceNodes;
  std::vector<std::vector<int>> contactFaceOf;
};

// Effects the scene calls for, and nothing else. Collective (contact effects
// reduce their smallest face edge over the ranks).
SceneEffects buildEffects(const Mesh& mesh, const Scene& scene);

}  // namespace capstan
