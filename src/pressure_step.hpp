// The saddle-point pressure step: how the pressure loop moves the element
// pressure anchors, and exact contact's multipliers with them (Solver/Pressure
// Update = Saddle Point; docs/numerics.md).
//
// Newton converges with the multipliers held. The plain update pbar <- p(x)
// (Uzawa) shrinks each pressure mode's error by 1/(1 + lambda/eps), lambda its
// eigenvalue of the Schur complement; Q1P0's nearly spurious modes have
// lambda ~ h^2, so the finer the mesh, the more passes (G1: 45, 76, 228 per
// run on 1x, 2x, 4x, even with Anderson mixing), each a Newton solve. This
// step instead solves for the position change dx and the multipliers' changes
// dmu together, so that equilibrium holds and every constraint is met to first
// order (effects/effect.hpp, ConstraintRows: the element volumes, c_e = v_e - V_e with
// the anchors; exact contact's points in contact, c_q = g_q with lambda_q):
//
//     [ K     B F ] [dx ]   [ -R ]     K: Newton's tangent (the penalties)
//     [ B^T   D   ] [dmu] = [ -c ]     B: column j = d c_j / d x, F = diag(dR/dmu_j / B_j)
//
// (a Newton step on the mixed problem). Contact moves with the volumes: its
// plain update alone gains ~30x a pass, and each of its changes moves the
// volumes again (G1 2x: 6 passes a load step, set by contact).
// K already holds each constraint's penalty (e.g. G (eps M)^-1 G^T, M =
// diag(V_e)): this is the augmented-Lagrangian form, whose Schur complement
// D - B^T K^-1 B F is close to its diagonal approximation S (eps V_e for a
// volume, -eps for a contact point) on all but Q1P0's nearly spurious modes.
// GMRES, right-preconditioned by the block upper-triangular
//
//     P = [ K~  B F ; 0  S ],   K~^-1: Newton's preconditioner,
//
// needs about the iterations of one Newton solve plus those for the modes S
// misses, where the plain loop needs a Newton solve per pass.
//
// Those modes (Schur = Laplacian, the default): K = K0 + G (eps M)^-1 G^T on
// the volumes, so by Sherman-Morrison-Woodbury the volumes' Schur complement
// has the inverse (eps M)^-1 + (G^T K0^-1 G)^-1. Its second term is small
// except on the nearly spurious modes (G q ~ 0), where it is large; the
// diagonal S drops it, and those modes took 73-98 GMRES iterations in each
// load step's last pass (G1 4x). L = G^T diag(K0)^-1 G is small on the same
// modes (G q ~ 0 makes both small), so the step applies
//     S^-1 ~ (eps M)^-1 + omega L^-1
// on the volume rows, L^-1 by a few Jacobi-preconditioned CG iterations (L is
// a scalar element-by-element matrix, ~1/30 of K's nonzeros). A fixed number of
// CG iterations is not a linear operator, so GMRES is the flexible variant
// (it keeps P^-1 of each basis vector). omega and the CG iterations were
// chosen from G1 4x and 8x (docs/performance.md).
//
// Each constraint row is scaled by w_j = |F_j| |B_j| / |S_j|: a constraint
// error then counts as the force it causes through the penalty, comparable
// with R. B carries a rigid core's face-node entries to the core's free
// unknowns (as the matrix assembly does); held dofs are left out.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "assembly.hpp"
#include "saddle_point_lu.hpp"

namespace capstan {

class PressureStep {
 public:
  // How the constraint block's Schur complement is approximated (above).
  enum class Schur { Diagonal, Laplacian };
  // GMRES's preconditioner: Block (K^-1 and the Schur approximation) or LU
  // (the whole block matrix factored: SaddlePointLU).
  enum class Preconditioner { Block, LU };
  explicit PressureStep(Assembly& assembly, Schur schur = Schur::Laplacian,
                        Preconditioner preconditioner = Preconditioner::Block);

  // z = K~^-1 r, an approximate inverse of K.
  using Inverse = std::function<void(const Vector& r, Vector& z)>;
  struct Result {
    int iterations = 0;
    double reduction = 1;  // final / initial residual (both blocks, scaled)
    double initial = 0;    // the initial residual's norm (|R| and the scaled constraint errors)
    double volumeResidual = 0;  // max_e |V_e - v_e - g_e.dx| / V_e: the volume error the step leaves (to first order)
    double volumePredicted = 0;  // > 0: stopped early on this volume error predicted after Newton's next solve
    double predictionTarget = 0; // the target the prediction had to meet (volumeTarget / the miss ratio)
    int predictions = 0;         // stop-rule checks of that prediction (each one K~^-1)
    int contactRows = 0;        // contact points in the step (all ranks)
    bool lu = false;            // preconditioned by the factored block matrix (else block-triangular)
    std::string luRefused;      // non-empty: MUMPS refused to factor it (why), Block from then on
  };
  // At the last evaluation (f, K, the effects' states, the positions): dx (owned dofs, zero on
  // held ones) and dmu (each effect's, in its multipliers() layout, zero where it has no row).
  // GMRES stops on the volume error against volumeTarget (docs/numerics.md, "When a step stops").
  Result solve(const CrsMatrix& K, const Inverse& Kinv, const Vector& f, double tolerance, double volumeTarget,
               int maxIterations, Vector& dx, std::vector<Kokkos::View<double*>>& dmu);
  // The volume error measured after each Newton solve of the pressure loop: where the last step
  // stopped on its prediction, measured / predicted (at least 1) divides the next targets, since
  // K~^-1 misses part of K^-1 (docs/numerics.md, "When a step stops").
  void measuredAfterNewton(double volumeError);
  // The last step was taken shortened: its prediction does not apply.
  void shortened() { lastPredicted_ = 0; }
  // Constraint rows of the last solve (all ranks): volumes and contact points.
  long rows() const { return rows_; }
  // Whether the steps factor the whole block matrix (Preconditioner::LU), and
  // the switch back to the block-triangular preconditioner for good.
  bool factorsBlockMatrix() const { return preconditioner_ == Preconditioner::LU; }
  void useBlockPreconditioner() { preconditioner_ = Preconditioner::Block; }
  double seconds() const { return seconds_; }
  // What a step carries to the next (the stop rule's miss ratio and last prediction), for a
  // checkpoint: a restarted run repeats the uninterrupted one's arithmetic.
  std::array<double, 2> carried() const { return {missRatio_, lastPredicted_}; }
  void recall(const std::array<double, 2>& c) { missRatio_ = c[0], lastPredicted_ = c[1]; }

 private:
  struct Block {
    RCP<Vector> u, c;  // positions, constraints
  };
  Block newBlock() const;
  static double dot(const Block& a, const Block& b) { return a.u->dot(*b.u) + a.c->dot(*b.c); }
  static void update(double alpha, const Block& x, double beta, Block& y) {
    y.u->update(alpha, *x.u, beta);
    y.c->update(alpha, *x.c, beta);
  }
  // Every effect's rows at the current positions into B^T, the row vectors
  // and the constraint map (rebuilt when the number of rows changes).
  void fillRows();
  // L = G^T diag(K0)^-1 G on the volume rows (zero rows elsewhere) at K.
  void buildVolumeLaplacian(const CrsMatrix& K);
  // z ~ L^-1 r on the volume rows: kLaplacianIterations of Jacobi-CG.
  void applyVolumeLaplacianInverse(const Vector& r, Vector& z) const;
  // y = A x (the scaled saddle-point matrix) and z = P^-1 r.
  void applySystem(const CrsMatrix& K, const Block& x, Block& y) const;
  void applyPreconditioner(const Inverse& Kinv, const Block& r, Block& z);
  // max over the volume rows of |r_j| / (w_j scale_j): the relative volume
  // error in a residual's constraint block.
  double volumeError(const Vector& rc) const;
  // The volume error after the next Newton solve, for the residual (ru, rc):
  // volumeError(rc - w .* B^T K~^-1 ru).
  double predictedVolumeError(const Inverse& Kinv, const Vector& ru, const Vector& rc);

  Assembly& assembly_;
  std::vector<ConstraintRows> effectRows_;  // per effect of assembly_.effects()
  long rows_ = 0;
  RCP<const Map> rowMap_;             // this rank's constraint rows, effect after effect
  RCP<CrsMatrix> gradient_;           // B^T: row j holds B_j on the free dofs
  // Row j: dR/dmu_j on the free dofs, where some effect's rows give their own
  // columns (ConstraintRows::column); null: the columns are F_j B_j.
  RCP<CrsMatrix> columns_;
  // Rows of B^T over global dofs (Assembly::chainRows), refilled per solve;
  // the last pattern, to refill the matrix in place while it is unchanged.
  std::vector<size_t> rowStart_, lastRowStart_;
  std::vector<GO> cols_, lastCols_;
  std::vector<double> vals_;
  template <class T>
  Teuchos::ArrayView<const T> row(const std::vector<T>& v, size_t j) const {
    return Teuchos::ArrayView<const T>(v.data() + rowStart_[j], rowStart_[j + 1] - rowStart_[j]);
  }
  RCP<Vector> weight_;                // w_j (0 for a row with no free dof)
  RCP<Vector> force_, diagonal_;      // F_j, D_j
  RCP<Vector> schurInverse_;          // 1 / (w_j S_j) (0 likewise)
  RCP<Vector> volumeScale_;           // w_j scale_j on the volume rows, 0 elsewhere
  RCP<Vector> scratch_;               // applyPreconditioner's r_u - B F z_c
  RCP<Vector> scratchC_;              // applySystem's F x_c
  RCP<Vector> residualC_;             // the constraint block of GMRES's residual
  RCP<Vector> residualU_, predictU_;  // its position block; K~^-1 of it
  RCP<Vector> predictC_;              // rc - w .* B^T K~^-1 ru
  std::vector<Block> basis_;          // GMRES's Krylov basis, kept between solves
  std::vector<Block> preconditioned_; // P^-1 of each basis vector (flexible GMRES)
  Schur schur_;
  RCP<CrsMatrix> laplacian_;          // L (Schur::Laplacian)
  RCP<Vector> laplacianJacobi_;       // 1 / L_jj on the volume rows, 0 elsewhere
  RCP<Vector> volumeRowsOverW_;       // 1 / w_j on the volume rows, 0 elsewhere
  RCP<Vector> volumeRows_;            // 1 on the volume rows, 0 elsewhere
  mutable RCP<Vector> cgR_, cgP_, cgQ_, cgZ_, laplacianIn_, laplacianOut_;
  Preconditioner preconditioner_;
  std::unique_ptr<SaddlePointLU> lu_;  // the whole block matrix factored (useLU_)
  bool useLU_ = false;                 // this step's preconditioner: lu_
  double seconds_ = 0;
  double lastPredicted_ = 0;  // the last step's prediction, until measured (0: none)
  double missRatio_ = 1;      // measured / predicted, last measured
};

}  // namespace capstan
