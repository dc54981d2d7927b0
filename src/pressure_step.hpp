// The saddle-point pressure step: how the pressure loop moves the element
// pressure anchors (Solver/Pressure Update = Saddle Point; docs/numerics.md).
//
// Newton converges with the anchors pbar held. The plain update pbar <- p(x)
// (Uzawa) shrinks each pressure mode's error by 1/(1 + lambda/eps), lambda its
// eigenvalue of the Schur complement; Q1P0's nearly spurious modes have
// lambda ~ h^2, so the finer the mesh, the more passes (G1: 45, 76, 228 per
// run on 1x, 2x, 4x, even with Anderson mixing), each a Newton solve. This
// step instead solves for the position change dx and the anchor change dp
// together, so that equilibrium holds and every element's volume is exact to
// first order:
//
//     [ K     -G ] [dx]   [ -R    ]     K: Newton's tangent (penalty eps)
//     [ G^T    0 ] [dp] = [ V - v ]     G: column e = g_e = d v_e / d x
//
// (R depends on pbar through -p g_e, so dR/dpbar = -G: a Newton step on the
// mixed problem.) K already holds G (eps M)^-1 G^T, M = diag(V_e): this is the
// augmented-Lagrangian form, whose pressure Schur complement G^T K^-1 G is
// close to eps M on all but those nearly spurious modes. GMRES, right-
// preconditioned by the block upper-triangular
//
//     P = [ K~  -G ; 0  eps M ],   K~^-1: Newton's preconditioner,
//
// needs about the iterations of one Newton solve plus a few for those modes,
// where the plain loop needs a Newton solve per pass.
//
// The constraint rows are scaled by w_e = |g_e| / (eps V_e): a volume error
// then counts as the force it causes through the penalty, comparable with R.
// G carries a rigid core's face-node entries to the core's free unknowns (as
// the matrix assembly does); held dofs are left out.
#pragma once

#include <functional>
#include <vector>

#include "assembly.hpp"

namespace capstan {

class PressureStep {
 public:
  explicit PressureStep(Assembly& assembly);

  // z = K~^-1 r, an approximate inverse of K.
  using Inverse = std::function<void(const Vector& r, Vector& z)>;
  struct Result {
    int iterations = 0;
    double reduction = 1;  // final / initial residual (both blocks, scaled)
    double volumeResidual = 0;  // max_e |V_e - v_e - g_e.dx| / V_e: the volume error the step leaves (to first order)
  };
  // At the last evaluation (f its residual, K its tangent, the bricks' volumes
  // and positions): dx (owned dofs, zero on held ones) and dp (per element).
  // GMRES stops once the volume error the step leaves (max_e, relative) is at
  // most volumeTarget: then this pass meets the volume tolerance. Failing
  // that, at the residual reduction `tolerance`, if the volume error left is
  // still above 10 volumeTarget (the next pass, quadratically closer, finishes
  // the job); close to the target it goes on (for at most as many iterations
  // again), since a pass (a Newton solve and a pressure step) costs more than
  // the iterations that remain. volumeTarget 0: the reduction alone.
  Result solve(const CrsMatrix& K, const Inverse& Kinv, const Vector& f, double tolerance, double volumeTarget,
               int maxIterations, Vector& dx, Kokkos::View<double*> dp);
  double seconds() const { return seconds_; }

 private:
  struct Block {
    RCP<Vector> u, p;
  };
  Block newBlock() const;
  static double dot(const Block& a, const Block& b) { return a.u->dot(*b.u) + a.p->dot(*b.p); }
  static void update(double alpha, const Block& x, double beta, Block& y) {
    y.u->update(alpha, *x.u, beta);
    y.p->update(alpha, *x.p, beta);
  }
  // The volume gradients at the current positions into G^T (rows: elements).
  void fillVolumeGradient();
  // y = A x (the scaled saddle-point matrix) and z = P^-1 r.
  void applySystem(const CrsMatrix& K, const Block& x, Block& y) const;
  void applyPreconditioner(const Inverse& Kinv, const Block& r, Block& z);
  // max_e |r_p,e| / (w_e V_e): the relative volume error in a residual's constraint block.
  double volumeError(const Vector& rp) const;

  Assembly& assembly_;
  RCP<const Map> elementMap_;
  RCP<CrsMatrix> gradient_;           // G^T: row e holds g_e on the free dofs
  // Element rows of G^T over global dofs (Assembly::chainRows), refilled per solve.
  std::vector<size_t> rowStart_;
  std::vector<GO> cols_;
  std::vector<double> vals_;
  template <class T>
  Teuchos::ArrayView<const T> row(const std::vector<T>& v, size_t e) const {
    return Teuchos::ArrayView<const T>(v.data() + rowStart_[e], rowStart_[e + 1] - rowStart_[e]);
  }
  Matrix g_;                          // per element g_e (all 24 dofs)
  RCP<Vector> weight_;                // w_e (0 for an element with no free dof)
  RCP<Vector> schurInverse_;          // 1 / (w_e eps V_e) (0 likewise)
  RCP<Vector> scratch_;               // applyPreconditioner's r_u + G z_p
  RCP<Vector> residualP_;             // the constraint block of GMRES's residual
  std::vector<Block> basis_;          // GMRES's Krylov basis, kept between solves
  double seconds_ = 0;
};

}  // namespace capstan
