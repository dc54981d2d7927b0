// Physical effects: each is a small object the scene switches on, owning its
// data and launching its Kokkos kernel over its entities (bricks or faces). All
// of them hand the same things to the one assembly path: per-entity dof ids and
// residuals (LocalSystem), and each entity's tangent to the assembly's
// TangentSink as it is formed.
#pragma once

#include <Kokkos_Core.hpp>

#include "../kernels/contact.hpp"
#include "../kernels/friction.hpp"

#include <array>
#include <string>
#include <type_traits>
#include <vector>

namespace capstan {

struct Mesh;

using ExecSpace = Kokkos::DefaultExecutionSpace;
// Row-major per entity, so a kernel works on contiguous element data.
using IntMatrix = Kokkos::View<int**, Kokkos::LayoutRight>;
using Matrix = Kokkos::View<double**, Kokkos::LayoutRight>;
using Tensor3 = Kokkos::View<double***, Kokkos::LayoutRight>;
using NodalVectors = Kokkos::View<double* [3], Kokkos::LayoutRight>;

struct LocalSystem {
  IntMatrix dofs;  // [entity][k]: overlapped dof ids (3 * node + component)
  Matrix R;        // [entity][k]
  bool stiff = false;  // whether the entities have a tangent (dead loads have none)
  // Optional: entities with active(e) == 0 contribute nothing this evaluation
  // (contact faces away from the capstan); empty = all active. The matrix
  // graph still holds them, so the sparsity pattern never changes.
  Kokkos::View<int*> active;
};

// What a kernel does with an active entity's tangent K_e (n x n, row-major,
// dof 3a+i) right after forming it, while it is still in cache. Element
// tangents are not stored: on G1 8x on one rank they took 790 MB, and the run's
// peak fell 18% without them (docs/performance.md, "Assembly without stored
// element tangents"). Each part is off when empty:
//   - values: K_e is added into the local CRS values of Newton's matrix (owned
//     plus shared rows) at offsets found once: rowBlock(e, k * n/3 + b) is the
//     offset of column 3b in row k (its 3 columns follow it), -1 where row k
//     is held; bit l of heldColumns(e) set: column l is held, not added;
//   - z, Kz: Kz(e, k) = sum_l K_e(k, l) z(e, l), the step predictor's K z;
//   - keepSlot, kept: a copy of K_e in kept(keepSlot(e)) where keepSlot(e) >= 0
//     (entities with a rigid core's face node, for the chain rule).
struct TangentSink {
  Kokkos::View<double*> values;
  Kokkos::View<int**, Kokkos::LayoutRight> rowBlock;
  Kokkos::View<int*> heldColumns;
  Matrix z, Kz;
  Kokkos::View<int*> keepSlot;
  Kokkos::View<double***, Kokkos::LayoutRight> kept;

  // Entity e's tangent K (n x n): into the matrix, K z and the kept copy.
  template <int n>
  KOKKOS_INLINE_FUNCTION void take(int e, const double* K) const {
    if (values.extent(0)) {
      // On one thread (Serial) a plain add: there an atomic add of a double is
      // a compare-and-swap loop for nothing.
      constexpr bool serial = std::is_same_v<Kokkos::DefaultExecutionSpace, Kokkos::Serial>;
      constexpr int nb = n / 3;
      double* const v = values.data();
      const int* const rows = &rowBlock(e, 0);
      const int held = heldColumns(e);
      for (int k = 0; k < n; ++k) {
        const int* const o = rows + k * nb;
        if (o[0] < 0) continue;  // a held row
        const double* const Kk = K + k * n;
        for (int b = 0; b < nb; ++b)
          for (int j = 0; j < 3; ++j) {
            if (held && (held & (1 << (3 * b + j)))) continue;
            if constexpr (serial) v[o[b] + j] += Kk[3 * b + j];
            else Kokkos::atomic_add(&v[o[b] + j], Kk[3 * b + j]);
          }
      }
    }
    if (z.extent(0))
      for (int k = 0; k < n; ++k) {
        double s = 0;
        for (int l = 0; l < n; ++l) s += K[k * n + l] * z(e, l);
        Kz(e, k) = s;
      }
    if (keepSlot.extent(0) && keepSlot(e) >= 0)
      for (int k = 0; k < n; ++k)
        for (int l = 0; l < n; ++l) kept(keepSlot(e), k, l) = K[k * n + l];
  }
};

// An effect's constraints, linearised at the last evaluation, for the
// saddle-point step (src/pressure_step.hpp), which solves for the position
// change and the multipliers' changes together. Row j, multiplier mu_j:
//     c_j(x + dx, mu_j + dmu_j) ~ c_j + gradient_j . dx + diagonal_j dmu_j = 0,
//     dR / dmu_j = force_j gradient_j,
// and schur_j approximates the Schur complement's diagonal
// diagonal_j - force_j gradient_j^T K^-1 gradient_j: Newton's K holds each
// constraint's penalty, which makes that diagonal approximation good.
struct ConstraintRows {
  std::vector<int> entity;      // row j's entity (its dofs: local().dofs(entity_j, .))
  std::vector<int> multiplier;  // mu_j's index in multipliers()
  Matrix gradient;              // [j][k]: d c_j / d x over the entity's dofs
  std::vector<double> force, diagonal, value, schur;
  // c_j's unit for the step's stop rule (|c_j| / scale_j against a relative
  // tolerance), or 0: the stop rule does not look at row j.
  std::vector<double> scale;
  size_t size() const { return entity.size(); }
  void clear() { entity.clear(), multiplier.clear(), force.clear(), diagonal.clear(), value.clear(), schur.clear(), scale.clear(); }
};

class Effect {
 public:
  explicit Effect(std::string name) : name_(std::move(name)) {}
  virtual ~Effect() = default;
  const std::string& name() const { return name_; }
  // Residual at current positions x and displacements u (overlapped nodes),
  // and with a sink the tangent, which goes to the sink entity by entity.
  void evaluate(const NodalVectors& x, const NodalVectors& u, const TangentSink* sink);
  const LocalSystem& local() const { return local_; }
  long launches() const { return launches_; }
  double seconds() const { return seconds_; }

  // The load increment being solved, from tStart (the last converged state) to
  // tEnd: effects that move with time (capstans) evaluate at tEnd.
  virtual void setInterval(double /*tStart*/, double /*tEnd*/) {}

  // Augmentation, the outer loop around each Newton solve (element pressure
  // anchors, contact multipliers): the multipliers are held fixed in a Newton
  // solve; after it converges they move to their fixed-point map G, until each
  // effect's constraint violation is within its tolerance. Effects without
  // multipliers return an empty view.
  virtual Kokkos::View<double*> multipliers() { return {}; }
  // G(multipliers) at the last evaluation, into `next` (same size).
  virtual void multiplierMap(const Kokkos::View<double*>& /*next*/) const {}
  // History: state from the last converged increment (friction's positions and
  // stick tractions), changed only by commit(x) when an increment converges, at
  // its converged positions x (the last evaluation).
  virtual Kokkos::View<double*> history() { return {}; }
  virtual void commit(const NodalVectors& /*x*/) {}

  // The step predictor's evaluations: effects may use a simpler, more robust
  // linearisation there (it is only a first guess; Newton's tangent is exact).
  virtual void setPredicting(bool /*on*/) {}

  // Whether Anderson mixing may accelerate this effect's multiplier loop.
  virtual bool accelerated() const { return true; }
  // Brings mixed multipliers back into their admissible set (e.g. lambda >= 0).
  virtual void projectMultipliers() {}
  // This rank's rows for the saddle-point step, at positions x (the last
  // evaluation's); none by default (a plain multiplier update).
  virtual void constraintRows(const NodalVectors& /*x*/, ConstraintRows& rows) const { rows.clear(); }
  // Largest violation of the constraint on this rank at the last evaluation,
  // and the tolerance it must meet (same units).
  virtual double constraintViolation() const { return 0; }
  virtual double constraintTolerance() const { return 0; }
  virtual std::string constraintName() const { return name(); }

 protected:
  // tangent: whether to form the tangent and hand it to sink.
  virtual void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) = 0;
  LocalSystem local_;

 private:
  std::string name_;
  long launches_ = 0;
  double seconds_ = 0;
};

// Q1P0 incompressible neo-Hookean bricks, the whole body.
class BrickEffect : public Effect {
 public:
  BrickEffect(const Mesh& mesh, double c, double penalty, double volumeTolerance);
  Kokkos::View<double*> pressureAnchor;  // pbar per element (outer loop updates it)
  Kokkos::View<double*> pressure;        // p(x) at the last evaluation
  Kokkos::View<double*> volume;          // v at the last evaluation
  Kokkos::View<double*> referenceVolume; // V
  Kokkos::View<double*> minJacobian;     // smallest Gauss-point det F
  // Element Cauchy stress (xx yy zz xy yz xz) and von Mises at the centroids.
  void centroidStress(const NodalVectors& x, Matrix& stress, Kokkos::View<double*>& mises) const;
  double c() const { return c_; }
  // The penalty eps of the Newton solves (the scene's eps1, raised to
  // Solver/Minimum Solve Penalty).
  double solvePenalty() const { return penalty_; }
  // d v_e / d x at positions x (overlapped nodes), 24 per element (dof 3a+i).
  void volumeGradients(const NodalVectors& x, Matrix& g) const;
  // c_e = v_e - V_e with the anchor pbar_e: force -1 (dR/dpbar = -g_e),
  // Schur complement eps V_e, every element a row.
  void constraintRows(const NodalVectors& x, ConstraintRows& rows) const override;

  // Pressure anchors: G(pbar) = p(x); violation max |v/V - 1|.
  Kokkos::View<double*> multipliers() override { return pressureAnchor; }
  void multiplierMap(const Kokkos::View<double*>& next) const override;
  double constraintViolation() const override;
  double constraintTolerance() const override { return volumeTolerance_; }
  std::string constraintName() const override { return "volume change"; }

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Kokkos::View<int* [8], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [8][3], Kokkos::LayoutRight> X_;
  double c_, penalty_, volumeTolerance_;
};

// Elastic foundation on one face: t = -k (x - X) on the listed components.
class FoundationEffect : public Effect {
 public:
  FoundationEffect(const std::string& name, const Mesh& mesh, const std::string& face, double k,
                   std::array<bool, 3> components);
  // Total force the foundation exerts on the body (this rank's faces).
  std::array<double, 3> localForceOnBody() const;

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Kokkos::View<int* [4], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [4][3], Kokkos::LayoutRight> X_;
  double k_;
  int mask_[3];
};

// Dead body force b per unit reference volume on every brick (Loads/Body Force),
// ramped with time: b t / endTime. No stiffness (local().stiff is false).
class BodyForceEffect : public Effect {
 public:
  BodyForceEffect(const Mesh& mesh, std::array<double, 3> b, double endTime);
  void setInterval(double, double tEnd) override { scale_ = tEnd / endTime_; }

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Matrix fullLoad_;  // the nodal loads of b itself, integrated once (they never change)
  double endTime_, scale_ = 0;
};

// Normal contact of candidate faces with one rigid capstan (kernels/contact.hpp).
// Penalty or augmented Lagrangian; faces the capstan does not touch are
// inactive and cost only their gap check.
class ContactEffect : public Effect {
 public:
  struct Settings {
    double radius = 1;
    std::array<double, 3> axisPoint{}, axisDirection{0, 0, 1}, velocity{};
    double penalty = 1e-3;       // eps2 of the scene
    bool exact = false;          // augmented Lagrangian: g = 0 (else the penalty answer g = eps2 t_n)
    // Newton solves use eps = max(eps2, this); < 0: automatic, for the nodal
    // rule 1e-2 h / c (h the smallest candidate face edge), a penalty 100 times
    // stiffer than the body's surface, so the multiplier loop gains about two
    // digits per pass; for Gauss rules 0.
    double minimumSolvePenalty = -1;
    double c = 1;                // the body's material constant
    double tolerance = 0;        // on eps |t_n - lambda| (length); 0 = 1e-4 x smallest edge
    int maxAugmentations = 50;
    int rule = 0;                // kernels::FaceRule
    double smoothing = 0;        // pressure scale of the contact law's smoothed corner (0: max(0, .))
  };
  ContactEffect(const std::string& name, const Mesh& mesh, const std::vector<int>& quads,
                const Settings& settings);

  void setInterval(double tStart, double tEnd) override;
  // Multipliers only where they change the answer: the augmented Lagrangian,
  // or a penalty solved at a larger penalty than the scene's.
  bool augmented() const { return compliance_ < solvePenalty_; }
  double solvePenalty() const { return solvePenalty_; }
  Kokkos::View<double*> multipliers() override {
    return augmented() ? lambda_ : Kokkos::View<double*>();
  }
  void multiplierMap(const Kokkos::View<double*>& next) const override;
  void projectMultipliers() override;
  // Plain Uzawa: each update removes most of the penetration already (the
  // penalty is much stiffer than the body), and mixing across the kink of
  // max(0, .) where points enter or leave contact made the loop wander.
  bool accelerated() const override { return false; }
  double constraintViolation() const override;
  // Exact contact's points in contact (t_n > 0; the augmented Lagrangian
  // without a smoothed corner): c_q = g_q - kappa lambda_q, gradient -N_a e,
  // force w (1 - kappa / eps) (w: reference area weight), Schur complement
  // -eps. Other points keep the plain update.
  void constraintRows(const NodalVectors& x, ConstraintRows& rows) const override;
  double constraintTolerance() const override { return settings_.tolerance; }
  std::string constraintName() const override { return name() + " penetration"; }
  int maxAugmentations() const { return settings_.maxAugmentations; }

  // This rank's share of the capstan's figures at the last evaluation. The
  // contact angles are measured about the axis from `reference` (a unit vector
  // normal to the axis; zero: angles not wanted).
  struct Figures {
    std::array<double, 3> force{};  // body on capstan
    double torque = 0;              // body on capstan, about its axis
    double maxPenetration = 0, peakPressure = 0, area = 0;
    long points = 0;
    double angleMin = 0, angleMax = 0;  // +-inf-like sentinels when no point
  };
  Figures figures(const std::array<double, 3>& reference) const;
  // Per face: mean contact pressure, largest gap, mean traction on the body (3).
  void faceFields(std::vector<double>& pressure, std::vector<double>& gap,
                  std::vector<double>& traction) const;
  const std::array<double, 3>& axisDirection() const { return beta_; }
  double radius() const { return settings_.radius; }
  // Predictor: the contact tangent without its geometric stiffness (see
  // kernels/contact.hpp).
  void setPredicting(bool on) override { predicting_ = on; }
  // What friction on the same faces needs: the cylinder now, the normal
  // multipliers, the penalties and the rule.
  kernels::Cylinder cylinder() const;
  Kokkos::View<double*> normalMultipliers() const { return lambda_; }
  double compliance() const { return compliance_; }
  int rule() const { return settings_.rule; }
  const Settings& settings() const { return settings_; }
  size_t numFaces() const { return nodes_.extent(0); }

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Kokkos::View<int* [4], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [4][3], Kokkos::LayoutRight> X_;
  Kokkos::View<double*> lambda_;  // [face * kMaxFacePoints + q]
  // Per face and point at the last evaluation: gap, pressure, weight, area, e (3), x (3).
  Kokkos::View<double** [10], Kokkos::LayoutRight> points_;
  Settings settings_;
  std::array<double, 3> beta_{};  // unit axis direction
  double time_ = 0;
  bool predicting_ = false;
  double solvePenalty_ = 1e-3;  // eps of the Newton solves
  double compliance_ = 1e-3;    // kappa: g = kappa t_n at the fixed point (0: exact contact)
};

// Friction of one capstan on its contact faces (kernels/friction.hpp); reads
// the normal contact state of its ContactEffect (same faces, same points).
class FrictionEffect : public Effect {
 public:
  struct Settings {
    kernels::FrictionLaw law = kernels::FrictionLaw::None;
    double mu = 0;
    double regularization = 1e-3;  // eps3 / eps4: slip speed scale
    double tangentPenalty = 0;     // Coulomb eps_t; 0: the contact's solve penalty
    double smoothing = 0;          // Coulomb: width of the smoothed stick/slip corner
    double angularVelocity = 0;
  };
  FrictionEffect(const std::string& name, const Mesh& mesh, const std::vector<int>& quads,
                 const ContactEffect& contact, const Settings& settings);

  void setInterval(double tStart, double tEnd) override;
  // Predictor: every contact point sticks (kernels/friction.hpp).
  void setPredicting(bool on) override { parameters_.stickPredictor = on; }
  Kokkos::View<double*> history() override { return history_; }
  void commit(const NodalVectors& x) override;

  // Coulomb with the augmented Lagrangian contact: a tangential multiplier per
  // point replaces last step's traction in the trial traction and is updated
  // to the traction after each converged solve (Uzawa), so sticking points
  // stick exactly (no elastic slip of size eps_t t) whatever the tangential
  // penalty. Violation: eps_t |t - lambda_T|, the slip of a sticking point.
  bool augmented() const {
    return settings_.law == kernels::FrictionLaw::Coulomb && contact_.settings().exact;
  }
  Kokkos::View<double*> multipliers() override {
    return augmented() ? tangentialMultipliers_ : Kokkos::View<double*>();
  }
  void multiplierMap(const Kokkos::View<double*>& next) const override;
  bool accelerated() const override { return false; }
  double constraintViolation() const override;
  double constraintTolerance() const override { return contact_.settings().tolerance; }
  std::string constraintName() const override { return name() + " stick slip"; }

  struct Figures {
    std::array<double, 3> force{};  // friction of the body on the capstan
    double torque = 0;              // about the capstan's axis
    long stick = 0, slip = 0;
    double frictionIntegral = 0;    // sum of w |t_f|
    double normalIntegral = 0;      // sum of w t_n
    double maxRatio = 0;            // largest |t_f| / (mu t_n)
  };
  Figures figures() const;
  // Per face: mean friction traction (3), stick and slip point counts.
  void faceFields(std::vector<double>& traction, std::vector<double>& stick,
                  std::vector<double>& slip) const;

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  const ContactEffect& contact_;
  Kokkos::View<int* [4], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [4][3], Kokkos::LayoutRight> X_;
  // [face][0..11]: node positions at the last converged state; then
  // [face][12 + 3q + i]: Coulomb's traction at point q from that state.
  Kokkos::View<double*> history_;
  Kokkos::View<double*> tangentialMultipliers_;  // [(face * kMaxFacePoints + q) * 3 + i]
  // Per face and point at the last evaluation: traction (3), t_n, slip, state, weight, e (3).
  Kokkos::View<double** [10], Kokkos::LayoutRight> points_;
  Settings settings_;
  kernels::FrictionParameters parameters_;
};

}  // namespace capstan
