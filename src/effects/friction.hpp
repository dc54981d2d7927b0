#pragma once

#include "contact.hpp"

#include "../../kernels/friction.hpp"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace capstan {

// Friction of one capstan on its contact faces (kernels/friction.hpp); reads
// the normal contact state of its ContactEffect (same faces, same points).
class FrictionEffect : public Effect {
 public:
  FrictionEffect(const std::string& name, const Mesh& mesh, const std::vector<int>& quads,
                 const ContactEffect& contact, const FrictionSettings& settings);

  void setInterval(double tStart, double tEnd) override;
  // Tanh and Arctan: the slip scale v is eps3 dt x `scale` (1: the scene's
  // law; src/regularisation_continuation.hpp widens it for a failed solve).
  void setRegularisationScale(double scale);
  // Whether the law in force is a regularised one (steady rolling's start puts Tanh in Coulomb's place).
  bool regularisedLaw() const {
    return settings_.law == FrictionSettings::Law::Tanh || settings_.law == FrictionSettings::Law::Arctan;
  }
  // Coulomb with the exact stick/slip corner (Friction/Smoothing = 0): whether
  // a failed solve may be retried through a smoothed corner, and that corner's
  // width for the retry (0: the scene's own again; RegularisationContinuation).
  bool exactCorner() const { return settings_.law == FrictionSettings::Law::Coulomb && settings_.smoothing == 0; }
  void setCornerSmoothing(double delta) { parameters_.smoothing = delta; }
  // Whether the law acts now (steady rolling's frictionless footprint turns it off).
  virtual bool acting() const { return true; }
  // Tanh and Arctan: the capstan surface's travel over the slip scale v
  // (scale 1), (|omega| R + |velocity|) / eps3, independent of dt; 0 otherwise.
  double travelOverSlipScale() const;
  // Tanh, Arctan: the residual's round-off floor at the last evaluation (all ranks), eps |x| times
  // the slope mu t_n / v: where it passes Newton's tolerance the solve stalls (0 for other laws;
  // docs/friction.md, "Above the floor: the steep law's round-off as the later passes' tolerance").
  virtual double residualRoundOff(const Teuchos::Comm<int>& comm) const;
  // Predictor: every contact point sticks (kernels/friction.hpp).
  void setPredicting(bool on) override { parameters_.stickPredictor = on; }
  Kokkos::View<double*> history() override { return history_; }
  void commit(const NodalVectors& x) override;

  // Coulomb with augmented Lagrangian contact: a tangential multiplier per point replaces last
  // step's traction in the trial traction and moves to the traction after each solve (Uzawa):
  // sticking points stick exactly whatever eps_t. Violation: eps_t |t - lambda_T|.
  virtual bool augmented() const {
    return settings_.law == FrictionSettings::Law::Coulomb && contact_.settings().exact();
  }
  Kokkos::View<double*> multipliers() override {
    return augmented() ? tangentialMultipliers_ : Kokkos::View<double*>();
  }
  void multiplierMap(const Kokkos::View<double*>& next) const override;
  bool accelerated() const override { return false; }
  // The stick multipliers sit at the contact's points.
  int multiplierSites(std::vector<int>& nodes) const override {
    return augmented() ? contact_.multiplierSites(nodes) : 0;
  }
  // Coulomb's sticking points in the saddle-point step: the slip c = tau . du_t along b x e and the
  // axis b, multiplier the stick traction along tau, dR/dmu = -w N tau, Schur diagonal -eps_t; the
  // plain update gains only 1.3-2x a pass (docs/friction.md, "The multiplier loop in rolling").
  void constraintRows(const NodalVectors& x, ConstraintRows& rows) const override;
  // Rows only at the nodal rule's points (one per face node, as exact contact
  // has): with Gauss points, 2 rows per point outnumber the nodes' tangential
  // dofs and the step's system is singular.
  bool stepsForItself() const override {
    return augmented() && parameters_.smoothing == 0 && contact_.rule() == kernels::FaceRule::Nodal;
  }
  // Where the multiplier loop stopped gaining, holds states so they settle: mayHold, a point
  // cycling A, B, A, B, A in slip at the cone; lastResort, any changed 4+ times; freeze, all others
  // as they are (stick till it leaves the cone). Released at the next solve. True: a hold changed.
  bool notePass(bool mayHold, bool lastResort, bool freeze);
  long heldPoints() const { return heldPoints_; }
  void releaseHeldSlips();
  double constraintViolation() const override;
  double constraintTolerance() const override { return contact_.constraintTolerance(); }
  std::string constraintName() const override { return name() + " stick slip"; }
  // Adds friction to its capstan's record (reported by the contact before it).
  void report(const Teuchos::Comm<int>& comm, StepRecord& rec) const override;

  struct Figures {
    std::array<double, 3> force{};  // friction of the body on the capstan
    double torque = 0;              // about the capstan's axis
    long stick = 0, slip = 0;
    double frictionIntegral = 0;    // sum of w |t_f|
    double normalIntegral = 0;      // sum of w t_n
    double maxRatio = 0;            // largest |t_f| / (mu t_n)
    double work = 0;                // sum of w x the work dissipated in the increment
  };
  Figures figures() const;
  // Per face and point at the last evaluation (host copy): traction (3), t_n,
  // slip (in the increment; steady rolling: per unit time), state, weight,
  // e (3), work (likewise).
  enum Field { kTraction = 0, kNormal = 3, kSlip, kState, kFWeight, kFE, kWork = kFE + 3 };
  using Points = Kokkos::View<double** [11], Kokkos::LayoutRight>;
  Points::HostMirror pointsOnHost() const { return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_); }
  // Slip rate per unit of the points' slip: 1 / the increment's length.
  double slipRateScale() const { return dt_ > 0 ? 1 / dt_ : 0.0; }
  // Per face: mean friction traction (3), stick and slip point counts, mean
  // slip rate (the increment's slip over its length; steady: the slip rate).
  void faceFields(std::vector<double>& traction, std::vector<double>& stick,
                  std::vector<double>& slip, std::vector<double>& slipRate) const;

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

  // Shared with SteadyFrictionEffect (src/effects/steady_friction.hpp).
  const ContactEffect& contact_;
  Kokkos::View<int* [4], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [4][3], Kokkos::LayoutRight> X_;
  // [face][0..11]: node positions at the last converged state; then
  // [face][12 + 3q + i]: Coulomb's traction at point q from that state.
  Kokkos::View<double*> history_;
  Kokkos::View<double*> tangentialMultipliers_;  // [(face * kMaxFacePoints + q) * 3 + i]
  Kokkos::View<int*> heldBranch_;                // [face * kMaxFacePoints + q]: notePass's holds
  struct PointCycle {     // one point's stick/slip states over the passes (notePass)
    int beforeLast = -1;  // two passes ago
    int last = -1;        // the last pass
    int returns = 0;      // passes back to the state of two passes before
    int changes = 0;      // passes whose state (in contact) differed from the last
    int hold = 0;         // 0 free, kernels::kHeldInSlip or kHeldInStick
  };
  std::vector<PointCycle> cycles_;  // [face * kMaxFacePoints + q]
  long heldPoints_ = 0;
  static constexpr int kHistoryPerFace = 12 + 3 * kernels::kMaxFacePoints;
  // Coulomb's sticking points, two rows each (constraintRows): value, multiplier, force, Schur
  // diagonal, direction into rows; fill(f, N, e, tau, circumferential, g) writes a row's gradient
  // over `width` dofs into g (zeroed); grad and column get every row's gradient and dR/dmu.
  using StickRowFill =
      std::function<void(size_t f, const double N[4], const double* e, const double tau[3], bool circumferential,
                         double* g)>;
  void stickRows(ConstraintRows& rows, int width, const StickRowFill& fill, std::vector<double>& grad,
                 std::vector<double>& column) const;
  static Matrix rowMatrix(const char* label, size_t rows, int width, const std::vector<double>& values);
  Points points_;
  FrictionSettings settings_;
  double dt_ = 0;  // the increment's length (setInterval)
  double regularisationScale_ = 1;
  double positionScale_ = 0;  // the largest |X| of the faces' nodes
  kernels::FrictionParameters parameters_;
};

}  // namespace capstan
