// The saddle-point step's whole matrix factored by MUMPS: an exact inverse of
// the step's block system (src/pressure_step.hpp), for its GMRES to use as
// preconditioner where the block-triangular one (K^-1 and a diagonal Schur
// complement) needs hundreds of iterations: a fine nip's thousands of stick
// rows couple through K^-1 far from any diagonal (docs/steady-rolling.md,
// "The saddle-point step's LU").
//
//   [ K     T^T ] [z_u]   [r_u]      T: the rows' forces on the positions
//   [ wG    wD  ] [z_c] = [r_c]      (F G, or the rows' own columns), G: B^T,
//                                    w, D: the rows' weights and diagonals
//
// A row with weight 0 (no free dof) keeps z_c = r_c (a unit diagonal).
#pragma once

#include <memory>

#include "assembly_types.hpp"
#include "direct_solver.hpp"

namespace capstan {

class SaddlePointLU {
 public:
  using CrsMatrix = Tpetra::CrsMatrix<>;

  SaddlePointLU();
  ~SaddlePointLU();

  // Assembles and factors the block matrix (collective). K: the positions'
  // tangent (row map the positions' map), G and T on the rows' map with the
  // positions as domain, w and D on the rows' map.
  void factor(const CrsMatrix& K, const CrsMatrix& G, const CrsMatrix& T, const Vector& w, const Vector& D,
              const Vector& schurInverse);
  // z = the block matrix' inverse applied to r, block by block.
  void solve(const Vector& ru, const Vector& rc, Vector& zu, Vector& zc);

 private:
  std::unique_ptr<MumpsSolver> mumps_;
  Teuchos::RCP<const Map> map_;  // positions' rows, then the constraint rows (GIDs offset)
  Teuchos::RCP<const Map> uMap_, cMap_;
  Teuchos::RCP<Tpetra::MultiVector<>> b_, x_;
};

}  // namespace capstan
