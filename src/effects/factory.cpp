#include "factory.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>

#include "../mesh.hpp"
#include "../scene.hpp"

namespace capstan {

SceneEffects buildEffects(const Mesh& mesh, const Scene& scene) {
  SceneEffects out;
  const double epsSolve =
      SolverSettings::solvePenalty(scene.pressurePenalty, scene.solver.minimumSolvePenalty, scene.c);
  auto bricks = std::make_unique<BrickEffect>(mesh, scene.c, epsSolve,
                                              scene.solver.volumeTolerance);
  out.bricks = bricks.get();
  out.all.push_back(std::move(bricks));

  // Foundations are supports that act as effects; the other supports hold
  // dofs (src/constraints.hpp).
  for (const auto& s : scene.supports) {
    if (s.type != SupportSpec::Type::Foundation) continue;
    auto f = std::make_unique<FoundationEffect>(mesh, s);
    out.all.push_back(std::move(f));
  }

  if (scene.bodyForce != std::array<double, 3>{0, 0, 0})
    out.all.push_back(std::make_unique<BodyForceEffect>(mesh, scene.bodyForce, scene.steps * scene.stepSize));

  std::map<std::array<int, 4>, int> faceIndex;  // a candidate face's sorted nodes -> its union index
  for (const auto& c : scene.capstans) {
    // Candidate faces, each once even if two named faces share one. Every
    // capstan's faces also get an index in the union of all candidate faces
    // (the contact-face grid of fields.h5).
    std::vector<int> quads;
    std::set<std::array<int, 4>> mine;
    out.contactFaceOf.emplace_back();
    for (const auto& name : c.contactFaces) {
      const auto& q = mesh.faces.at(name);
      for (size_t f = 0; f < q.size(); f += 4) {
        std::array<int, 4> key{q[f], q[f + 1], q[f + 2], q[f + 3]};
        std::sort(key.begin(), key.end());
        if (!mine.insert(key).second) continue;
        auto [it, fresh] = faceIndex.insert({key, int(faceIndex.size())});
        if (fresh) out.contactFaceNodes.insert(out.contactFaceNodes.end(), q.begin() + f, q.begin() + f + 4);
        quads.insert(quads.end(), q.begin() + f, q.begin() + f + 4);
        out.contactFaceOf.back().push_back(it->second);
      }
    }
    const bool exactStick = scene.analysis.steady() && c.friction.law == FrictionSettings::Law::Coulomb;
    auto effect = std::make_unique<ContactEffect>("contact:" + c.name, mesh, quads, c, scene.c, exactStick);
    out.contacts.push_back(effect.get());
    out.frictions.push_back(nullptr);
    const ContactEffect& contact = *effect;
    out.all.push_back(std::move(effect));
    if (!c.friction.on()) continue;  // no friction kernel at all
    std::unique_ptr<FrictionEffect> friction;
    if (scene.analysis.steady())
      friction = std::make_unique<SteadyFrictionEffect>("friction:" + c.name, mesh, quads, contact, c.friction, scene);
    else
      friction = std::make_unique<FrictionEffect>("friction:" + c.name, mesh, quads, contact, c.friction);
    out.frictions.back() = friction.get();
    out.frictionsPresent.push_back(friction.get());
    out.all.push_back(std::move(friction));
  }
  return out;
}

}  // namespace capstan
