// Q1P0 incompressible neo-Hookean brick (formulation.md §1).
//
// Cauchy stress sigma = -p I + 2c (B - I), integrated over the current volume:
//   R_u[a,i] = int J [2c (F D_a - d_a)_i - p d_a,i] dV,   d_a = F^{-T} D_a,
// where D_a = dN_a/dX. The element pressure is condensed with the penalty eps:
//   p(x) = pbar - (v - V) / (eps V),
// so the element residual is R_u(x, p(x)) and its exact tangent is
//   K(x, p) + g g^T / (eps V),   g = int J d_a dV = d v / d x.
// pbar is the pressure anchor the outer (augmentation) loop updates until v = V.
#pragma once

#include "hex_shape.hpp"

namespace capstan::kernels {

struct BrickState {
  double volume;    // current volume v
  double pressure;  // p(x)
  double minJ;      // smallest det F at a Gauss point (<= 0: inverted)
};

// Deformation gradient F[i][J] = sum_a x_a,i D_a,J.
KOKKOS_INLINE_FUNCTION void deformationGradient(const double x[8][3], const double D[8][3],
                                                double F[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J) {
      double s = 0;
      for (int a = 0; a < 8; ++a) s += x[a][i] * D[a][J];
      F[i][J] = s;
    }
}

// The geometry of a brick at its 8 Gauss points, each quantity an array
// [...][gp] (structure of arrays, see HexGauss2Gradients): every loop over gp
// below is one 8-wide vector operation.
struct BrickGaussPoints {
  double J0inv[3][3][8];  // dxi_j/dX_J (inverse of the reference Jacobian dX/dxi)
  double F[3][3][8];      // deformation gradient dx_i/dX_J
  double Finv[3][3][8];   // F^{-1}
  double J[8];            // det F
  double wJ[8];           // det(dX/dxi) det F: the current volume element (Gauss weights are 1)
};

// F from the natural derivatives: dX/dxi = sum_a X_a dN_a/dxi, dx/dxi likewise,
// F = (dx/dxi)(dX/dxi)^{-1}. (The same F as sum_a x_a D_a^T with D_a = dN_a/dX.)
KOKKOS_INLINE_FUNCTION void brickGaussPoints(const double X[8][3], const double x[8][3],
                                             BrickGaussPoints& q) {
  const HexGauss2Gradients& dN = hexGauss2();
  double J0[3][3][8], Fxi[3][3][8], detJ0[8];  // dX_i/dxi_j, dx_i/dxi_j
  // One coordinate i at a time: its 6 running sums over the nodes stay in
  // registers (all 18 at once, GCC keeps in memory; one at a time waits on
  // each multiply-add).
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      for (int gp = 0; gp < 8; ++gp) J0[i][j][gp] = Fxi[i][j][gp] = 0;
    for (int a = 0; a < 8; ++a)
      for (int j = 0; j < 3; ++j)
        for (int gp = 0; gp < 8; ++gp) {
          J0[i][j][gp] += X[a][i] * dN.byPoint[a][j][gp];
          Fxi[i][j][gp] += x[a][i] * dN.byPoint[a][j][gp];
        }
  }
  inverse3x8(J0, q.J0inv, detJ0);
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int gp = 0; gp < 8; ++gp)
        q.F[i][J][gp] = Fxi[i][0][gp] * q.J0inv[0][J][gp] + Fxi[i][1][gp] * q.J0inv[1][J][gp] +
                        Fxi[i][2][gp] * q.J0inv[2][J][gp];
  inverse3x8(q.F, q.Finv, q.J);
  for (int gp = 0; gp < 8; ++gp) q.wJ[gp] = detJ0[gp] * q.J[gp];
}

// Reference gradients D[J][a] = dN_a/dX_J of the 8 nodes at Gauss point gp
// (8 nodes in a row): D_a = (dX/dxi)^{-T} dN_a/dxi.
KOKKOS_INLINE_FUNCTION void brickReferenceGradients(const BrickGaussPoints& q, int gp, double D[3][8]) {
  const HexGauss2Gradients& dN = hexGauss2();
  for (int J = 0; J < 3; ++J)
    for (int a = 0; a < 8; ++a)
      D[J][a] = dN.byNode[gp][0][a] * q.J0inv[0][J][gp] + dN.byNode[gp][1][a] * q.J0inv[1][J][gp] +
                dN.byNode[gp][2][a] * q.J0inv[2][J][gp];
}

// Current volume (the sum of the volume elements) and the smallest det F.
KOKKOS_INLINE_FUNCTION double brickVolume(const BrickGaussPoints& q, double& minJ) {
  double v = 0;
  minJ = 1e300;
  for (int gp = 0; gp < 8; ++gp) {
    minJ = q.J[gp] < minJ ? q.J[gp] : minJ;
    v += q.wJ[gp];
  }
  return v;
}

// Current volume of the element (2x2x2 Gauss) and the smallest Gauss-point J.
KOKKOS_INLINE_FUNCTION double brickVolume(const double X[8][3], const double x[8][3],
                                          double& minJ) {
  BrickGaussPoints q;
  brickGaussPoints(X, x, q);
  return brickVolume(q, minJ);
}

// g = d v / d x (24, dof 3a+i) = int J F^{-T} D_a dV: how the element's
// current volume changes with its nodes' positions. The residual's pressure
// part is -p g; the saddle-point pressure step (src/pressure_step.hpp) uses g
// as the element's row of the linearised volume constraint.
KOKKOS_INLINE_FUNCTION void brickVolumeGradient(const double X[8][3], const double x[8][3], double g[24]) {
  BrickGaussPoints q;
  brickGaussPoints(X, x, q);
  double gn[3][8] = {};  // g_a,i as [i][a]
  for (int gp = 0; gp < 8; ++gp) {
    double D[3][8];
    brickReferenceGradients(q, gp, D);
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 8; ++a)
        gn[i][a] +=
            q.wJ[gp] * (q.Finv[0][i][gp] * D[0][a] + q.Finv[1][i][gp] * D[1][a] + q.Finv[2][i][gp] * D[2][a]);
  }
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) g[3 * a + i] = gn[i][a];
}

// The tangent from the Gauss-point vectors of brickKernel (see there), all
// stored [gp][component][node]: d[gp][k][b] = d_b,k, H[gp][i][a] = H_ai,
// e[gp][k][a] = e_ak, D[gp][J][b] = D_b,J, cD = 2c wJ D; g[k][b] = g_bk:
//   K[ai][bk] = sum_gp (H_ai d_bk + e_ak d_bi) + delta_ik S_ab + g_ai g_bk/(eps V),
//   S_ab = sum_gp cD_a.D_b;  p(x) enters R_u as -p g: the g g^T / (eps V).
// For one node a, K's 3x3 blocks K[ai][bk] for all b are kept as 9 rows over
// the 8 nodes b, blk[i][k][b]: each term of the sums is then a multiply-add
// of a scalar (H_ai or e_ak) and an 8-node row (d_.k or d_.i), one vector
// operation whichever index it transposes, and the rows are interleaved into
// K's (dof 3b+k) as they are stored. (Rows over K's 24 dofs instead need the
// e d term transposed within node pairs.) S is formed in full (a row of 8 b's
// is one vector operation), in its own loop: accumulated inside the block
// loop, GCC keeps its row in scalars.
KOKKOS_INLINE_FUNCTION void brickTangent(const double d[8][3][8], const double H[8][3][8],
                                         const double e[8][3][8], const double D[8][3][8],
                                         const double cD[8][3][8], const double g[3][8], double eps, double V,
                                         double* K) {
  double S[8][8];
  for (int a = 0; a < 8; ++a) {
    for (int b = 0; b < 8; ++b) S[a][b] = 0;
    for (int gp = 0; gp < 8; ++gp)
      for (int J = 0; J < 3; ++J)
        for (int b = 0; b < 8; ++b) S[a][b] += cD[gp][J][a] * D[gp][J][b];
  }
  const double s = 1.0 / (eps * V);
  for (int a = 0; a < 8; ++a) {
    double blk[3][3][8];
    for (int i = 0; i < 3; ++i) {
      const double sg = s * g[i][a];
      for (int k = 0; k < 3; ++k)
        for (int b = 0; b < 8; ++b) blk[i][k][b] = sg * g[k][b];
    }
    for (int gp = 0; gp < 8; ++gp) {
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
          for (int b = 0; b < 8; ++b) {
            blk[i][k][b] += H[gp][i][a] * d[gp][k][b];
            blk[i][k][b] += e[gp][k][a] * d[gp][i][b];
          }
    }
    for (int i = 0; i < 3; ++i)
      for (int b = 0; b < 8; ++b) blk[i][i][b] += S[a][b];
    for (int i = 0; i < 3; ++i)
      for (int b = 0; b < 8; ++b)
        for (int k = 0; k < 3; ++k) K[(3 * a + i) * 24 + 3 * b + k] = blk[i][k][b];
  }
}

// The brick kernel: residual R[24] (dof 3a+i) and tangent K[24*24]
// (row-major) of one brick. V: reference volume.
//
// First the geometry at all 8 Gauss points (brickGaussPoints, vectorised
// over the points), which gives the volume v and so the pressure p(v) that
// enters every term after it. Then, point by point, vectors over the 8 nodes
// (dof 3a+i stored as [i][a]; a loop over the nodes is one vector operation):
//   D_a = dN_a/dX,  d_a = F^{-T} D_a,  G_a = F D_a,
//   H_a = wJ (2c G_a - q d_a),  e_a = wJ q d_a,
// with R = sum_gp H and g = sum_gp wJ d. The tangent is then assembled from
// products over the Gauss points (brickTangent):
//   K[ai][bk] = sum_gp (H_ai d_bk + e_ak d_bi) + delta_ik S_ab + g_ai g_bk/(eps V),
//   S_ab = sum_gp wJ 2c D_a.D_b.
//
// The body, compiled once with and once without the tangent so that the
// residual-only evaluations (line searches, constraint checks) carry none of
// the tangent's stores or branches.
template <bool wantTangent>
KOKKOS_INLINE_FUNCTION void brickKernel(const double X[8][3], const double x[8][3], double V, double pbar,
                                        double c, double eps, double* R, double* K, BrickState& out) {
  BrickGaussPoints q;
  brickGaussPoints(X, x, q);
  const double v = brickVolume(q, out.minJ);
  out.volume = v;
  const double p = pbar - (v - V) / (eps * V);
  out.pressure = p;
  const double c2 = 2 * c, qs = p + c2;  // sigma = -q I + 2c B
  double Rn[3][8] = {}, g[3][8] = {};  // R_a,i and g_a,i as [i][a]
  // brickTangent's operands, [gp][component][node] (one slot without the tangent)
  constexpr int n = wantTangent ? 8 : 1;
  double D[n][3][8], cD[n][3][8], d[n][3][8], H[n][3][8], e[n][3][8];
  for (int gp = 0; gp < 8; ++gp) {
    const int slot = wantTangent ? gp : 0;
    const double wJ = q.wJ[gp], cw = c2 * wJ, qw = qs * wJ;
    brickReferenceGradients(q, gp, D[slot]);
    const double(*Da)[8] = D[slot];
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 8; ++a) {
        // spatial gradient F^{-T} D_a and push-forward F D_a
        const double da =
            q.Finv[0][i][gp] * Da[0][a] + q.Finv[1][i][gp] * Da[1][a] + q.Finv[2][i][gp] * Da[2][a];
        const double Ga = q.F[i][0][gp] * Da[0][a] + q.F[i][1][gp] * Da[1][a] + q.F[i][2][gp] * Da[2][a];
        const double Ha = cw * Ga - qw * da;
        Rn[i][a] += Ha;
        g[i][a] += wJ * da;
        if constexpr (wantTangent) {
          // dP/dF contracted with D_a, D_b (P = 2cJ F - qJ F^{-T}, q at fixed p):
          //   wJ [2c (G_a,i d_b,k + delta_ik D_a.D_b) - q (d_a,i d_b,k - d_a,k d_b,i)]
          d[gp][i][a] = da;
          H[gp][i][a] = Ha;
          e[gp][i][a] = qw * da;
        }
      }
    if constexpr (wantTangent)
      for (int J = 0; J < 3; ++J)
        for (int a = 0; a < 8; ++a) cD[gp][J][a] = cw * Da[J][a];
  }
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) R[3 * a + i] = Rn[i][a];
  if constexpr (wantTangent) brickTangent(d, H, e, D, cD, g, eps, V, K);
}

// Residual R[24] and, if K is not null, the tangent K[24*24] of one brick.
KOKKOS_INLINE_FUNCTION void brickResidualTangent(const double X[8][3], const double x[8][3],
                                                 double V, double pbar, double c, double eps,
                                                 double* R, double* K, BrickState& out) {
  if (K)
    brickKernel<true>(X, x, V, pbar, c, eps, R, K, out);
  else
    brickKernel<false>(X, x, V, pbar, c, eps, R, nullptr, out);
}


// Cauchy stress at the centroid, Voigt order xx yy zz xy yz xz.
KOKKOS_INLINE_FUNCTION void brickCentroidStress(const double X[8][3], const double x[8][3],
                                                double p, double c, double sigma[6]) {
  double D[8][3], F[3][3];
  hexReferenceGradients(X, 0, 0, 0, D);
  deformationGradient(x, D, F);
  double B[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) B[i][j] = F[i][0] * F[j][0] + F[i][1] * F[j][1] + F[i][2] * F[j][2];
  sigma[0] = -p + 2 * c * (B[0][0] - 1);
  sigma[1] = -p + 2 * c * (B[1][1] - 1);
  sigma[2] = -p + 2 * c * (B[2][2] - 1);
  sigma[3] = 2 * c * B[0][1];
  sigma[4] = 2 * c * B[1][2];
  sigma[5] = 2 * c * B[0][2];
}

KOKKOS_INLINE_FUNCTION double vonMises(const double s[6]) {
  const double m = (s[0] + s[1] + s[2]) / 3;
  const double a = s[0] - m, b = s[1] - m, cc = s[2] - m;
  return sqrt(1.5 * (a * a + b * b + cc * cc + 2 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])));
}

}  // namespace capstan::kernels
