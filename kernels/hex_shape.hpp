// Trilinear hexahedron and bilinear quadrilateral shape functions.
//
// Node order (formulation.md §1): bottom face zeta=-1 counter-clockwise 0-1-2-3,
// then the top face 4-5-6-7 above it. Everything here is a pure function usable
// inside Kokkos kernels on any execution space.
#pragma once

#include <Kokkos_Core.hpp>

namespace capstan::kernels {

// Portable math (Kokkos 3.4 keeps these in Experimental; newer Kokkos in Kokkos).
KOKKOS_INLINE_FUNCTION double sqrt(double x) { return Kokkos::Experimental::sqrt(x); }
KOKKOS_INLINE_FUNCTION double fabs(double x) { return Kokkos::Experimental::fabs(x); }

// Natural coordinate signs of hexahedron node a (each -1 or +1).
KOKKOS_INLINE_FUNCTION constexpr double hexXiSign(int a) { return (((a + 1) >> 1) & 1) ? 1.0 : -1.0; }
KOKKOS_INLINE_FUNCTION constexpr double hexEtaSign(int a) { return ((a >> 1) & 1) ? 1.0 : -1.0; }
KOKKOS_INLINE_FUNCTION constexpr double hexZetaSign(int a) { return (a >> 2) ? 1.0 : -1.0; }

// Shape function values N[8] and natural derivatives dN[8][3] at (xi, eta, zeta).
KOKKOS_INLINE_FUNCTION void hexShape(double xi, double eta, double zeta, double N[8],
                                     double dN[8][3]) {
  for (int a = 0; a < 8; ++a) {
    const double sx = hexXiSign(a), sy = hexEtaSign(a), sz = hexZetaSign(a);
    const double fx = 1 + sx * xi, fy = 1 + sy * eta, fz = 1 + sz * zeta;
    N[a] = 0.125 * fx * fy * fz;
    dN[a][0] = 0.125 * sx * fy * fz;
    dN[a][1] = 0.125 * fx * sy * fz;
    dN[a][2] = 0.125 * fx * fy * sz;
  }
}

// Quadrilateral nodes at (-1,-1), (1,-1), (1,1), (-1,1).
KOKKOS_INLINE_FUNCTION void quadShape(double xi, double eta, double N[4], double dN[4][2]) {
  const double s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int a = 0; a < 4; ++a) {
    const double fx = 1 + s[a][0] * xi, fy = 1 + s[a][1] * eta;
    N[a] = 0.25 * fx * fy;
    dN[a][0] = 0.25 * s[a][0] * fy;
    dN[a][1] = 0.25 * fx * s[a][1];
  }
}

// 3x3 determinant and inverse (returns the determinant; inv valid if det != 0).
KOKKOS_INLINE_FUNCTION double det3(const double A[3][3]) {
  return A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
         A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
         A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
}

KOKKOS_INLINE_FUNCTION double inverse3(const double A[3][3], double inv[3][3]) {
  const double d = det3(A);
  const double s = 1.0 / d;
  inv[0][0] = (A[1][1] * A[2][2] - A[1][2] * A[2][1]) * s;
  inv[0][1] = (A[0][2] * A[2][1] - A[0][1] * A[2][2]) * s;
  inv[0][2] = (A[0][1] * A[1][2] - A[0][2] * A[1][1]) * s;
  inv[1][0] = (A[1][2] * A[2][0] - A[1][0] * A[2][2]) * s;
  inv[1][1] = (A[0][0] * A[2][2] - A[0][2] * A[2][0]) * s;
  inv[1][2] = (A[0][2] * A[1][0] - A[0][0] * A[1][2]) * s;
  inv[2][0] = (A[1][0] * A[2][1] - A[1][1] * A[2][0]) * s;
  inv[2][1] = (A[0][1] * A[2][0] - A[0][0] * A[2][1]) * s;
  inv[2][2] = (A[0][0] * A[1][1] - A[0][1] * A[1][0]) * s;
  return d;
}

// Reference-configuration gradients D[a][J] = dN_a/dX_J at a natural point, and
// the reference volume element det(dX/dxi).
KOKKOS_INLINE_FUNCTION double hexReferenceGradients(const double X[8][3], double xi, double eta,
                                                    double zeta, double D[8][3]) {
  double N[8], dN[8][3];
  hexShape(xi, eta, zeta, N, dN);
  double J0[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};  // J0[i][j] = dX_i/dxi_j
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) J0[i][j] += X[a][i] * dN[a][j];
  double J0inv[3][3];
  const double det = inverse3(J0, J0inv);
  for (int a = 0; a < 8; ++a)
    for (int J = 0; J < 3; ++J)
      D[a][J] = dN[a][0] * J0inv[0][J] + dN[a][1] * J0inv[1][J] + dN[a][2] * J0inv[2][J];
  return det;
}

// 2-point Gauss abscissa.
KOKKOS_INLINE_FUNCTION constexpr double gauss2(int i) { return (i ? 1.0 : -1.0) * 0.57735026918962576451; }

// ---- The 2x2x2 Gauss rule, its 8 points side by side
//
// Gauss point gp (0..7) sits at xi = gauss2(gp & 1), eta = gauss2((gp >> 1) & 1),
// zeta = gauss2(gp >> 2), weight 1. The brick kernels do the same arithmetic at
// all 8 points, so they keep each per-point quantity as an array [...][8] with
// the point index last (structure of arrays): a loop over gp is then one
// 8-wide vector operation. The natural derivatives dN_a/dxi_j of the shape
// functions at these points are the same for every element: a table made at
// compile time, in two layouts,
//   byPoint[a][j][gp]: 8 Gauss points in a row (for sums over the nodes, e.g. dX/dxi),
//   byNode[gp][j][a]:  8 nodes in a row (for per-node vectors at one point).
struct HexGauss2Gradients {
  double byPoint[8][3][8];
  double byNode[8][3][8];
};

KOKKOS_INLINE_FUNCTION constexpr HexGauss2Gradients hexGauss2Gradients() {
  HexGauss2Gradients t{};
  for (int gp = 0; gp < 8; ++gp) {
    const double xi = gauss2(gp & 1), eta = gauss2((gp >> 1) & 1), zeta = gauss2(gp >> 2);
    for (int a = 0; a < 8; ++a) {  // as hexShape
      const double sx = hexXiSign(a), sy = hexEtaSign(a), sz = hexZetaSign(a);
      const double fx = 1 + sx * xi, fy = 1 + sy * eta, fz = 1 + sz * zeta;
      const double dN[3] = {0.125 * sx * fy * fz, 0.125 * fx * sy * fz, 0.125 * fx * fy * sz};
      for (int j = 0; j < 3; ++j) t.byPoint[a][j][gp] = t.byNode[gp][j][a] = dN[j];
    }
  }
  return t;
}

// The table, one copy in read-only memory (a static constant-initialised
// local: allowed in device code; a plain local constexpr would be rebuilt on
// the stack at every call).
KOKKOS_INLINE_FUNCTION const HexGauss2Gradients& hexGauss2() {
  static constexpr HexGauss2Gradients t = hexGauss2Gradients();
  return t;
}

// Inverses (and determinants) of 8 3x3 matrices at once, A[i][j][gp]: as
// inverse3, one vector operation per entry.
KOKKOS_INLINE_FUNCTION void inverse3x8(const double A[3][3][8], double inv[3][3][8], double det[8]) {
  for (int q = 0; q < 8; ++q) {
    const double c00 = A[1][1][q] * A[2][2][q] - A[1][2][q] * A[2][1][q];
    const double c10 = A[1][2][q] * A[2][0][q] - A[1][0][q] * A[2][2][q];
    const double c20 = A[1][0][q] * A[2][1][q] - A[1][1][q] * A[2][0][q];
    const double d = A[0][0][q] * c00 + A[0][1][q] * c10 + A[0][2][q] * c20;
    const double s = 1.0 / d;
    det[q] = d;
    inv[0][0][q] = c00 * s;
    inv[1][0][q] = c10 * s;
    inv[2][0][q] = c20 * s;
    inv[0][1][q] = (A[0][2][q] * A[2][1][q] - A[0][1][q] * A[2][2][q]) * s;
    inv[1][1][q] = (A[0][0][q] * A[2][2][q] - A[0][2][q] * A[2][0][q]) * s;
    inv[2][1][q] = (A[0][1][q] * A[2][0][q] - A[0][0][q] * A[2][1][q]) * s;
    inv[0][2][q] = (A[0][1][q] * A[1][2][q] - A[0][2][q] * A[1][1][q]) * s;
    inv[1][2][q] = (A[0][2][q] * A[1][0][q] - A[0][0][q] * A[1][2][q]) * s;
    inv[2][2][q] = (A[0][0][q] * A[1][1][q] - A[0][1][q] * A[1][0][q]) * s;
  }
}

}  // namespace capstan::kernels
