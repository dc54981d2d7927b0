// Friction in steady rolling (formulation.md §8): the slip rate of the body on
// the capstan, s = (I - e e^T)(v - v_c), with the body's surface velocity
// v = omega dx/dtheta an upwind difference along each ring of nodes (first or
// second order, Analysis/Upwind Order). It reuses the incremental friction
// kernel (kernels/friction.hpp) read over the time tau_f the material takes
// to cross face f: the "last converged" position of face node a is where its
// material was tau_f earlier,
//     xn_a = x_a - sigma omega tau_f (dx/dtheta)_a = x_a - sigma omega sum_k W_ak x_k,
// (sigma: the sign of the flow about +z; W: the difference's weights times
// tau_f over the entity's nodes), the capstan travels omega_c R tau_f, and
// the regularised laws' slip scale is eps3 tau_f. xn depends on x, on the
// upstream nodes and on the core's angular velocity omega: the chain rule of
// dR/dxn (the kernel's Kn) gives their columns. Coulomb always uses the
// tangential multipliers (augmented Lagrangian): sticking points stick exactly.
#pragma once

#include "friction.hpp"

#include <string>
#include <vector>

namespace capstan {

struct Scene;

class SteadyFrictionEffect : public FrictionEffect {
 public:
  SteadyFrictionEffect(const std::string& name, const Mesh& mesh, const std::vector<int>& quads,
                       const ContactEffect& contact, const FrictionSettings& settings, const Scene& scene);

  // omega: the free or prescribed angular velocity of the inner face's Rigid
  // Core (a Fixed inner face: omega = 0, no column).
  void bindCores(const RigidCores& cores) override;
  void setInterval(double, double) override {}  // nothing moves with time
  void setPredicting(bool) override {}
  Kokkos::View<double*> history() override { return {}; }
  // The multipliers carry over to the next steady state; there is no history.
  void commit(const NodalVectors&) override {}
  bool augmented() const override { return settings_.law == FrictionSettings::Law::Coulomb; }
  // Its laws solve on their own down to 3e-7 of the capstan's speed (the scene's floor).
  double residualRoundOff(const Teuchos::Comm<int>&) const override { return 0; }
  bool accelerated() const override { return true; }
  int multiplierSites(std::vector<int>&) const override { return 0; }  // the mesh stands still: no shift
  // Stick rows as FrictionEffect's, but the slip spans the entity, the traction the face's nodes:
  // du = spin tau_c - sum_a N_a flow tau_f (dx/dtheta)_a, so dc/dx_k = -flow sum_a N_a W_ak tau and
  // dc/domega = -dflow sum_a N_a tau . travel_a (ConstraintRows::column: -w N_a tau).
  void constraintRows(const NodalVectors& x, ConstraintRows& rows) const override;
  // Steady rolling's start: friction off (a frictionless footprint first).
  void setEnabled(bool on) { enabled_ = on; }
  bool acting() const override { return enabled_; }
  // Steady rolling's start from rest: a wider law in the scene's (Tanh for Coulomb), slip speed
  // scale `speedFraction` of the capstan's surface speed, so the start does not depend on the
  // speed. useSceneLaw() ends it; `seed`: Coulomb's multipliers from the last tractions.
  void useStartLaw(double speedFraction);
  void useSceneLaw(bool seed);
  // The scene's slip speed scale over the capstan's surface speed; 0 under Coulomb.
  double sceneSlipFraction() const;
  // Coulomb's tangential penalty eps_t (the stick's slope, not where it ends:
  // the multipliers make it exact either way): `factor` x the automatic value
  // (the contact's solve penalty), or the scene's with factor 0.
  void setStick(double factor) {
    parameters_.tangentPenalty = factor > 0 ? factor * contact_.solvePenalty() : sceneTangentPenalty_;
  }
  // The flow's angular velocity scale: the no-slip estimate about +z.
  double referenceAngularVelocity() const { return omegaRef_; }

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  // Per face: its entity's nodes (the face's 4, then the upstream ones, padded
  // by repeats), and the weights W(a, k) of face node a's difference.
  static constexpr int kNodes = 8;
  Kokkos::View<int* [kNodes], Kokkos::LayoutRight> entityNodes_;
  Kokkos::View<double* [4][kNodes], Kokkos::LayoutRight> weights_;
  Kokkos::View<double*> crossing_;  // tau_f
  std::string coreName_;   // the inner face's Rigid Core, or empty (Fixed)
  const RigidCores* cores_ = nullptr;
  int core_ = -1;
  double omegaRef_ = 0;    // about +z
  double axisSign_ = 1;    // the core's axis direction . z
  double sigma_ = 1;       // sign of the flow about +z
  bool enabled_ = true;
  double sceneRegularization_ = 0;  // while useStartLaw() holds
  FrictionSettings::Law sceneLaw_ = FrictionSettings::Law::Coulomb;
  double sceneTangentPenalty_ = 0;
  bool startLaw_ = false;
  double surfaceSpeed() const;
};

}  // namespace capstan
