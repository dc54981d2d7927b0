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
KOKKOS_INLINE_FUNCTION double hexXiSign(int a) { return (((a + 1) >> 1) & 1) ? 1.0 : -1.0; }
KOKKOS_INLINE_FUNCTION double hexEtaSign(int a) { return ((a >> 1) & 1) ? 1.0 : -1.0; }
KOKKOS_INLINE_FUNCTION double hexZetaSign(int a) { return (a >> 2) ? 1.0 : -1.0; }

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
KOKKOS_INLINE_FUNCTION double gauss2(int i) { return (i ? 1.0 : -1.0) * 0.57735026918962576451; }

}  // namespace capstan::kernels
