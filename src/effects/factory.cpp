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
      std::max(scene.pressurePenalty, scene.solver.get<double>("Minimum Solve Penalty") / scene.c);
  auto bricks = std::make_unique<BrickEffect>(mesh, scene.c, epsSolve,
                                              scene.solver.get<double>("Volume Tolerance"));
  out.bricks = bricks.get();
  out.all.push_back(std::move(bricks));

  // Foundations are supports that act as effects; the other supports hold
  // dofs (src/constraints.hpp).
  for (const auto& s : scene.supports) {
    if (s.type != "Foundation") continue;
    auto f = std::make_unique<FoundationEffect>("foundation:" + s.name, mesh, s.face, s.stiffness,
                                                s.components);
    out.foundations.push_back(f.get());
    out.all.push_back(std::move(f));
  }

  if (scene.bodyForce != std::array<double, 3>{0, 0, 0})
    out.all.push_back(std::make_unique<BodyForceEffect>(mesh, scene.bodyForce, scene.steps * scene.stepSize));

  std::map<std::array<int, 4>, int> faceIndex;  // a candidate face's sorted nodes -> its union index
  for (const auto& c : scene.capstans) {
    ContactEffect::Settings set;
    set.radius = c.radius;
    set.axisPoint = c.axisPoint;
    set.axisDirection = c.axisDirection;
    set.velocity = c.velocity;
    set.penalty = c.penalty;
    set.exact = c.method == "Augmented Lagrangian";
    set.minimumSolvePenalty = c.minimumSolvePenalty;
    set.c = scene.c;
    set.tolerance = c.penetrationTolerance;
    set.maxAugmentations = c.maxAugmentations;
    set.rule = c.quadrature;
    set.smoothing = c.smoothing;
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
    auto effect = std::make_unique<ContactEffect>("contact:" + c.name, mesh, quads, set);
    out.contacts.push_back(effect.get());
    out.frictions.push_back(nullptr);
    const ContactEffect& contact = *effect;
    out.all.push_back(std::move(effect));
    if (c.frictionLaw == "None") continue;  // no friction kernel at all
    FrictionEffect::Settings fs;
    fs.law = c.frictionLaw == "Tanh"     ? kernels::FrictionLaw::Tanh
             : c.frictionLaw == "Arctan" ? kernels::FrictionLaw::Arctan
                                         : kernels::FrictionLaw::Coulomb;
    fs.mu = c.frictionCoefficient;
    fs.regularization = c.regularization;
    fs.tangentPenalty = c.tangentialPenalty;
    fs.smoothing = c.frictionSmoothing;
    fs.angularVelocity = c.angularVelocity;
    auto friction = std::make_unique<FrictionEffect>("friction:" + c.name, mesh, quads, contact, fs);
    out.frictions.back() = friction.get();
    out.all.push_back(std::move(friction));
  }
  return out;
}

}  // namespace capstan
