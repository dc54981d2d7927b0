// Body force (formulation.md §1 extended): a dead load b per unit reference
// volume, e.g. rho g. It does not depend on the motion, so its tangent is zero
// and the kernel returns only the residual R[3a+i] = -b_i * int N_a dV.
#pragma once

#include "hex_shape.hpp"

namespace capstan::kernels {

KOKKOS_INLINE_FUNCTION void brickBodyForce(const double X[8][3], const double b[3], double R[24]) {
  double w[8] = {0, 0, 0, 0, 0, 0, 0, 0};  // int N_a dV, 2x2x2 Gauss (exact for a parallelepiped)
  for (int q = 0; q < 8; ++q) {
    const double xi = gauss2(q & 1), eta = gauss2((q >> 1) & 1), zeta = gauss2(q >> 2);
    double N[8], dN[8][3], D[8][3];
    hexShape(xi, eta, zeta, N, dN);
    const double dV = hexReferenceGradients(X, xi, eta, zeta, D);
    for (int a = 0; a < 8; ++a) w[a] += N[a] * dV;
  }
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) R[3 * a + i] = -b[i] * w[a];
}

}  // namespace capstan::kernels
