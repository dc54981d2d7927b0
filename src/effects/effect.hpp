// Physical effects: each is a small object the scene switches on, owning its
// data and launching its Kokkos kernel over its entities (bricks or faces). All
// of them hand the same things to the one assembly path: per-entity dof ids and
// residuals (LocalSystem), and each entity's tangent to the assembly's
// TangentSink as it is formed. One file per effect in src/effects/;
// src/effects/factory.hpp builds those a scene names.
#pragma once

#include <Kokkos_Core.hpp>
#include <Teuchos_Comm.hpp>

#include <array>
#include <string>
#include <type_traits>
#include <vector>

namespace capstan {

struct Mesh;
class RigidCores;

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
  // The entities' residual and tangent rows are their first rowDofs dofs; the
  // others are columns only (steady friction's upstream nodes and omega).
  // 0: every dof has a row.
  int rowDofs = 0;
  // Optional: entities with active(e) == 0 contribute nothing this evaluation
  // (contact faces away from the capstan); empty = all active. The matrix
  // graph still holds them, so the sparsity pattern never changes.
  Kokkos::View<int*> active;
};

// An effect's active flags on the host (empty: every entity is active).
inline Kokkos::View<int*>::HostMirror activeOnHost(const LocalSystem& L) {
  return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), L.active);
}

// What a kernel does with an active entity's tangent K_e (n x n, row-major) while it is in cache:
// adds it into Newton's CRS values, forms the predictor's K z, keeps a copy; empty parts are off
// (docs/performance.md, "Assembly without stored element tangents").
struct TangentSink {
  Kokkos::View<double*> values;  // Newton's local CRS values (owned and shared rows)
  // rowBlock(e, k * n/3 + b): offset of column 3b in row k (-1: row k held); bit l of heldColumns(e):
  // column l held, not added.
  Kokkos::View<int**, Kokkos::LayoutRight> rowBlock;
  Kokkos::View<int*> heldColumns;
  Matrix z, Kz;                 // Kz(e, k) = sum_l K_e(k, l) z(e, l)
  Kokkos::View<int*> keepSlot;  // >= 0: K_e copied to kept(keepSlot(e)) (a rigid core's face node)
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

// An effect's constraints linearised for the saddle-point step (src/pressure_step.hpp). Row j,
// mu_j: c_j + gradient_j . dx + diagonal_j dmu_j = 0, dR/dmu_j = force_j gradient_j; schur_j ~
// diagonal_j - force_j gradient_j^T K^-1 gradient_j, good as K holds each constraint's penalty.
struct ConstraintRows {
  std::vector<int> entity;      // row j's entity (its dofs: local().dofs(entity_j, .))
  std::vector<int> multiplier;  // mu_j's index in multipliers()
  Matrix gradient;              // [j][k]: d c_j / d x over the entity's dofs
  std::vector<double> force, diagonal, value, schur;
  // c_j's unit for the step's stop rule (|c_j| / scale_j against a relative
  // tolerance), or 0: the stop rule does not look at row j.
  std::vector<double> scale;
  // Empty: mu_j is one multiplier. Otherwise 3 per row: mu_j is the component
  // of a vector multiplier (multipliers()[multiplier_j + i], i < 3) along this
  // unit direction (a stick traction along a tangent of the capstan).
  std::vector<double> direction;
  // Empty: dR/dmu_j = force_j gradient_j. Otherwise [j][k]: dR/dmu_j over the
  // entity's dofs, where it differs (steady friction: a stick row's slip spans
  // the upstream nodes, its traction only the face's).
  Matrix column;
  size_t size() const { return entity.size(); }
  void clear() {
    entity.clear(), multiplier.clear(), force.clear(), diagonal.clear(), value.clear(), schur.clear(), scale.clear();
    direction.clear();
    column = Matrix();
  }
};

struct StepRecord;

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

  // Called once by the assembly, after it numbered the rigid cores' unknowns
  // and before it builds the matrix graph: an effect whose entities couple to
  // a core's unknowns adds them to its dofs here (steady friction's omega).
  virtual void bindCores(const RigidCores& /*cores*/) {}

  // The load increment being solved, from tStart (the last converged state) to
  // tEnd: effects that move with time (capstans) evaluate at tEnd.
  virtual void setInterval(double /*tStart*/, double /*tEnd*/) {}

  // Augmentation, the outer loop around each Newton solve: the multipliers (pressure anchors,
  // contact) are held in a solve, then move to their fixed-point map G, until every effect's
  // violation is within its tolerance. Effects without multipliers return an empty view.
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
  // Where the multipliers sit, for moving them with the material (the
  // streamline shift, src/streamline_shift.hpp): per site, the returned count
  // of overlapped node ids (-1: an unused site); multipliers() holds sites x
  // components values. 0: these multipliers do not move so.
  virtual int multiplierSites(std::vector<int>& /*nodes*/) const { return 0; }
  // This rank's rows for the saddle-point step, at positions x (the last
  // evaluation's); none by default (a plain multiplier update).
  virtual void constraintRows(const NodalVectors& /*x*/, ConstraintRows& rows) const { rows.clear(); }
  // Whether this effect's violation alone calls for the saddle-point step
  // (it has rows there); otherwise the step is taken for the volumes only.
  virtual bool stepsForItself() const { return false; }
  // Largest violation of the constraint on this rank at the last evaluation,
  // and the tolerance it must meet (same units).
  virtual double constraintViolation() const { return 0; }
  virtual double constraintTolerance() const { return 0; }
  virtual std::string constraintName() const { return name(); }
  // The most multiplier updates per load step before the step fails; 0: the
  // augmentation loop's own limit (Solver/Max Pressure Iterations).
  virtual int maxAugmentations() const { return 0; }
  // Adds its figures at the last evaluation to a converged step's record
  // (src/step_record.hpp). Collective: every rank calls it.
  virtual void report(const Teuchos::Comm<int>& /*comm*/, StepRecord& /*rec*/) const {}

 protected:
  // tangent: whether to form the tangent and hand it to sink.
  virtual void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) = 0;
  LocalSystem local_;

 private:
  std::string name_;
  long launches_ = 0;
  double seconds_ = 0;
};

}  // namespace capstan
