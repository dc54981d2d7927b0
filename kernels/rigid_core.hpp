// Rigid core: a face bonded to a rigid body that translates by T and turns by
// theta about the unit axis d through A (right-hand rule). A node at X on the
// face then sits at
//
//     x = A + T + R(theta) (X - A),    so    u = T + (R(theta) - I)(X - A),
//
// and the body's residual at the face's nodes reaches the core's unknowns
// q = (T, theta) through the chain rule (src/rigid_cores.cpp):
//
//     du/dT = I,   du/dtheta = b = d x R(X - A),   d2u/dtheta2 = w = d x b.
//
// b is the velocity of the node per unit spin (its lever arm turned by 90
// degrees); w points back to the axis (centripetal). Pure functions of one
// node's data, usable inside any Kokkos loop.
#pragma once

#include <Kokkos_Core.hpp>

#include <cmath>

namespace capstan::kernels {

struct CoreFollower {
  double u[3];  // displacement of the node
  double b[3];  // du/dtheta
  double w[3];  // d2u/dtheta2
};

// Rodrigues: R(theta) v = v cos + (d x v) sin + d (d . v)(1 - cos), d unit.
KOKKOS_INLINE_FUNCTION void rotateAboutAxis(const double d[3], double theta, const double v[3], double out[3]) {
  const double c = std::cos(theta), s = std::sin(theta);
  const double dv = d[0] * v[0] + d[1] * v[1] + d[2] * v[2];
  const double dxv[3] = {d[1] * v[2] - d[2] * v[1], d[2] * v[0] - d[0] * v[2], d[0] * v[1] - d[1] * v[0]};
  for (int i = 0; i < 3; ++i) out[i] = v[i] * c + dxv[i] * s + d[i] * dv * (1 - c);
}

KOKKOS_INLINE_FUNCTION CoreFollower coreFollower(const double A[3], const double d[3], const double T[3],
                                                 double theta, const double X[3]) {
  CoreFollower f;
  const double r0[3] = {X[0] - A[0], X[1] - A[1], X[2] - A[2]};
  double r[3];
  rotateAboutAxis(d, theta, r0, r);
  for (int i = 0; i < 3; ++i) f.u[i] = T[i] + r[i] - r0[i];
  f.b[0] = d[1] * r[2] - d[2] * r[1];
  f.b[1] = d[2] * r[0] - d[0] * r[2];
  f.b[2] = d[0] * r[1] - d[1] * r[0];
  f.w[0] = d[1] * f.b[2] - d[2] * f.b[1];
  f.w[1] = d[2] * f.b[0] - d[0] * f.b[2];
  f.w[2] = d[0] * f.b[1] - d[1] * f.b[0];
  return f;
}

}  // namespace capstan::kernels
