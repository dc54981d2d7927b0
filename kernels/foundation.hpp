// Elastic foundation on a face (formulation.md §4): traction t = -k (x - X) per
// reference area on the selected components. Linear, so the tangent is the
// (consistent) face mass matrix times k.
#pragma once

#include "hex_shape.hpp"

namespace capstan::kernels {

// Reference area element |dX/dxi x dX/deta| of a bilinear quad at (xi, eta).
KOKKOS_INLINE_FUNCTION double quadAreaElement(const double X[4][3], double xi, double eta,
                                              double N[4]) {
  double dN[4][2];
  quadShape(xi, eta, N, dN);
  double t1[3] = {0, 0, 0}, t2[3] = {0, 0, 0};
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      t1[i] += X[a][i] * dN[a][0];
      t2[i] += X[a][i] * dN[a][1];
    }
  const double n0 = t1[1] * t2[2] - t1[2] * t2[1];
  const double n1 = t1[2] * t2[0] - t1[0] * t2[2];
  const double n2 = t1[0] * t2[1] - t1[1] * t2[0];
  return sqrt(n0 * n0 + n1 * n1 + n2 * n2);
}

// R[3a+i] = k m_i sum_b M_ab u_b,i ; K = k m_i delta_ik M_ab (m: component mask).
// K null: the residual alone (line searches and constraint checks form no tangent).
KOKKOS_INLINE_FUNCTION void foundationResidualTangent(const double X[4][3], const double u[4][3],
                                                      double k, const int mask[3],
                                                      double R[12], double* K) {
  double M[4][4] = {};
  for (int q = 0; q < 4; ++q) {
    double N[4];
    const double dA = quadAreaElement(X, gauss2(q & 1), gauss2(q >> 1), N);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) M[a][b] += N[a] * N[b] * dA;
  }
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      double s = 0;
      for (int b = 0; b < 4; ++b) s += M[a][b] * u[b][i];
      R[3 * a + i] = mask[i] ? k * s : 0.0;
    }
  if (!K) return;
  for (int r = 0; r < 144; ++r) K[r] = 0;
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      for (int b = 0; b < 4; ++b) K[(3 * a + i) * 12 + 3 * b + i] = mask[i] ? k * M[a][b] : 0.0;
}

}  // namespace capstan::kernels
