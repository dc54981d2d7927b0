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

// Current volume of the element (2x2x2 Gauss) and the smallest Gauss-point J.
KOKKOS_INLINE_FUNCTION double brickVolume(const double X[8][3], const double x[8][3],
                                          double& minJ) {
  double v = 0;
  minJ = 1e300;
  for (int q = 0; q < 8; ++q) {
    double D[8][3];
    const double w = hexReferenceGradients(X, gauss2(q & 1), gauss2((q >> 1) & 1),
                                           gauss2(q >> 2), D);
    double F[3][3];
    deformationGradient(x, D, F);
    const double J = det3(F);
    minJ = J < minJ ? J : minJ;
    v += J * w;
  }
  return v;
}

// The tangent from the Gauss-point vectors of brickKernel (see there):
//   K[ai][bk] = sum_gp H_ai d_bk + T[ak][bi] + delta_ik S_ab + g_ai g_bk/(eps V).
KOKKOS_INLINE_FUNCTION void brickTangent(const double dq[8][24], const double Hq[8][24], const double eq[8][24],
                                         const double S[8][8], const double g[24], double eps, double V,
                                         double* K) {
  // T first (its rows are read transposed within node-pair blocks), then K,
  // three rows (one node's components) at a time so that each load of d
  // feeds three multiply-adds; p(x) enters R_u as -p g: g g^T / (eps V).
  double T[24][24];
  for (int a = 0; a < 8; ++a) {
    double acc[3][24] = {};
    for (int gp = 0; gp < 8; ++gp)
      for (int t = 0; t < 24; ++t)
        for (int i = 0; i < 3; ++i) acc[i][t] += eq[gp][3 * a + i] * dq[gp][t];
    for (int i = 0; i < 3; ++i)
      for (int t = 0; t < 24; ++t) T[3 * a + i][t] = acc[i][t];
  }
  const double s = 1.0 / (eps * V);
  for (int a = 0; a < 8; ++a) {
    double row[3][24];
    for (int i = 0; i < 3; ++i)
      for (int t = 0; t < 24; ++t) row[i][t] = s * g[3 * a + i] * g[t];
    for (int gp = 0; gp < 8; ++gp)
      for (int t = 0; t < 24; ++t)
        for (int i = 0; i < 3; ++i) row[i][t] += Hq[gp][3 * a + i] * dq[gp][t];
    for (int i = 0; i < 3; ++i) {
      for (int b = 0; b < 8; ++b) {
        for (int k = 0; k < 3; ++k) row[i][3 * b + k] += T[3 * a + k][3 * b + i];
        row[i][3 * b + i] += b >= a ? S[a][b] : S[b][a];
      }
      for (int t = 0; t < 24; ++t) K[(3 * a + i) * 24 + t] = row[i][t];
    }
  }
}

// The brick kernel: residual R[24] (dof 3a+i) and tangent K[24*24]
// (row-major) of one brick. V: reference volume.
//
// Two passes over the 8 Gauss points: the first computes F and the volume v
// (the pressure p(v) enters every term of the second), keeping the reference
// gradients and F so that the second pass does not recompute them. The
// second pass keeps, per Gauss point, three 24-vectors (dof index ai):
//   d_a = F^{-T} D_a,  H_a = wJ (2c G_a - q d_a),  e_a = wJ q d_a,
// and the tangent is then assembled from small matrix products over the
// Gauss points, whose 24-wide rows the compiler vectorises:
//   K[ai][bk] = sum_gp H_ai d_bk + T[ak][bi] + delta_ik S_ab + g_ai g_bk/(eps V)
//   T[ak][bi] = sum_gp e_ak d_bi,   S_ab = sum_gp wJ 2c D_a.D_b.
// (Accumulating the 3x3 node-pair blocks per Gauss point instead, with
// 3-wide inner loops, measured 1.18x slower.)
//
// The body, compiled once with and once without the tangent so that the
// residual-only evaluations (line searches, constraint checks) carry none of
// the tangent's stores or branches.
// g = d v / d x (24, dof 3a+i) = int J F^{-T} D_a dV: how the element's
// current volume changes with its nodes' positions. The residual's pressure
// part is -p g; the saddle-point pressure step (src/pressure_step.hpp) uses g
// as the element's row of the linearised volume constraint.
KOKKOS_INLINE_FUNCTION void brickVolumeGradient(const double X[8][3], const double x[8][3], double g[24]) {
  for (int r = 0; r < 24; ++r) g[r] = 0;
  for (int gp = 0; gp < 8; ++gp) {
    double D[8][3], F[3][3], Finv[3][3];
    const double w = hexReferenceGradients(X, gauss2(gp & 1), gauss2((gp >> 1) & 1), gauss2(gp >> 2), D);
    deformationGradient(x, D, F);
    const double wJ = w * inverse3(F, Finv);
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i)
        g[3 * a + i] += wJ * (Finv[0][i] * D[a][0] + Finv[1][i] * D[a][1] + Finv[2][i] * D[a][2]);
  }
}

template <bool wantTangent>
KOKKOS_INLINE_FUNCTION void brickKernel(const double X[8][3], const double x[8][3], double V, double pbar,
                                        double c, double eps, double* R, double* K, BrickState& out) {
  double Dq[8][8][3], Fq[8][3][3], wq[8];
  double v = 0, minJ = 1e300;
  for (int gp = 0; gp < 8; ++gp) {
    wq[gp] = hexReferenceGradients(X, gauss2(gp & 1), gauss2((gp >> 1) & 1), gauss2(gp >> 2), Dq[gp]);
    deformationGradient(x, Dq[gp], Fq[gp]);
    const double J = det3(Fq[gp]);
    minJ = J < minJ ? J : minJ;
    v += J * wq[gp];
  }
  out.volume = v;
  out.minJ = minJ;
  const double p = pbar - (v - V) / (eps * V);
  out.pressure = p;
  const double q = p + 2 * c;  // sigma = -q I + 2c B
  double g[24];
  for (int r = 0; r < 24; ++r) R[r] = g[r] = 0;
  double dq[wantTangent ? 8 : 1][24], Hq[wantTangent ? 8 : 1][24], eq[wantTangent ? 8 : 1][24], S[8][8];
  if (wantTangent)
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) S[a][b] = 0;
  for (int gp = 0; gp < 8; ++gp) {
    const double(*D)[3] = Dq[gp];
    const double(*F)[3] = Fq[gp];
    double Finv[3][3];
    const double wJ = wq[gp] * inverse3(Fq[gp], Finv);
    const double c2 = 2 * c * wJ, qw = q * wJ;
    const int slot = wantTangent ? gp : 0;
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) {
        // spatial gradient F^{-T} D_a and push-forward F D_a
        const double da = Finv[0][i] * D[a][0] + Finv[1][i] * D[a][1] + Finv[2][i] * D[a][2];
        const double Ga = F[i][0] * D[a][0] + F[i][1] * D[a][1] + F[i][2] * D[a][2];
        R[3 * a + i] += wJ * (2 * c * Ga - q * da);
        g[3 * a + i] += wJ * da;
        if (!wantTangent) continue;
        // dP/dF contracted with D_a, D_b (P = 2cJ F - qJ F^{-T}, q at fixed p):
        //   wJ [2c (G_a,i d_b,k + delta_ik D_a.D_b) - q (d_a,i d_b,k - d_a,k d_b,i)]
        dq[slot][3 * a + i] = da;
        Hq[slot][3 * a + i] = c2 * Ga - qw * da;
        eq[slot][3 * a + i] = qw * da;
      }
    if (!wantTangent) continue;
    for (int a = 0; a < 8; ++a)
      for (int b = a; b < 8; ++b) S[a][b] += c2 * (D[a][0] * D[b][0] + D[a][1] * D[b][1] + D[a][2] * D[b][2]);
  }
  if constexpr (wantTangent) brickTangent(dq, Hq, eq, S, g, eps, V, K);
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
