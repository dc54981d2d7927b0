// Normal contact of a body face with a rigid, undiscretized cylinder (the
// capstan, formulation.md §2). Pure functions of one face's data.
//
// For a surface point x: d = |P (x - a)|, e = P (x - a) / d, g = R - d
// (penetration, > 0 inside). The normal traction on the body, per reference
// area, is
//
//     t = t_n e,    t_n = max(0, lambda + (g - kappa lambda) / eps)
//
// which covers both methods with one formula:
//   penalty eps2:           kappa = eps = eps2, lambda = 0  ->  t_n = max(0, g / eps2)
//   augmented Lagrangian:   kappa = 0, lambda the multiplier ->  t_n = max(0, lambda + g / eps)
// and, in general, the outer loop's fixed point lambda = t_n satisfies
// g = kappa t_n: the penalty answer for kappa, reached with a Newton solve at the
// (possibly larger, better conditioned) penalty eps.
#pragma once

#include "foundation.hpp"
#include "hex_shape.hpp"

namespace capstan::kernels {

// The cylinder at the current time: axis point a, unit direction b, radius R.
struct Cylinder {
  double a[3], b[3], R;
  // The contact law's corner: t_n = max(0, tn) (0), or a smooth max with this
  // pressure scale (see contactPressure).
  double smoothing = 0;
};

// Contact pressure from the trial normal traction tn: max(0, tn), or with
// smoothing eta > 0 the smooth max (tn + sqrt(tn^2 + eta^2)) / 2, which differs
// from it by at most eta / 2 and removes the corner where points enter and
// leave contact. Newton stalls at that corner when contact points keep
// crossing it (a rolling body brings new points into the nip every step).
// Below tn = -1e4 eta the pressure (under 2.5e-5 eta) is cut to 0, so faces
// away from the capstan stay inactive. slope = d t_n / d tn.
KOKKOS_INLINE_FUNCTION double contactPressure(double tn, double eta, double& slope) {
  if (eta > 0) {
    if (tn < -1e4 * eta) {
      slope = 0;
      return 0;
    }
    const double r = sqrt(tn * tn + eta * eta);
    slope = 0.5 * (1 + tn / r);
    return 0.5 * (tn + r);
  }
  slope = tn > 0 ? 1.0 : 0.0;
  return tn > 0 ? tn : 0.0;
}

// Face quadrature rules: 2x2 Gauss (default), 3x3 Gauss, or nodal (2x2 Lobatto,
// one point at each node: contact is then checked where the nodes are).
enum class FaceRule { Gauss2 = 0, Gauss3 = 1, Nodal = 2 };
constexpr int kMaxFacePoints = 9;

KOKKOS_INLINE_FUNCTION int facePointCount(FaceRule rule) {
  return rule == FaceRule::Gauss3 ? 9 : 4;
}

// Natural coordinates and weight of point q of a rule.
KOKKOS_INLINE_FUNCTION void facePoint(FaceRule rule, int q, double& xi, double& eta, double& w) {
  if (rule == FaceRule::Gauss3) {
    const double s = 0.77459666924148337704;  // sqrt(3/5)
    const double p[3] = {-s, 0.0, s}, wt[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    xi = p[q % 3], eta = p[q / 3], w = wt[q % 3] * wt[q / 3];
  } else if (rule == FaceRule::Nodal) {
    const double s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    xi = s[q][0], eta = s[q][1], w = 1.0;
  } else {
    xi = gauss2(q & 1), eta = gauss2(q >> 1), w = 1.0;
  }
}

// Distance d of x from the axis and the unit vector e from the axis towards x.
// Returns the penetration g = R - d. On the axis itself (d = 0, far inside any
// real contact) e is any unit vector normal to the axis, so nothing is NaN.
KOKKOS_INLINE_FUNCTION double cylinderGap(const Cylinder& c, const double x[3], double e[3],
                                          double& d) {
  double r[3] = {x[0] - c.a[0], x[1] - c.a[1], x[2] - c.a[2]};
  const double along = r[0] * c.b[0] + r[1] * c.b[1] + r[2] * c.b[2];
  for (int i = 0; i < 3; ++i) r[i] -= along * c.b[i];
  d = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  if (d > 1e-300) {
    for (int i = 0; i < 3; ++i) e[i] = r[i] / d;
  } else {  // any unit vector normal to b
    const int k = fabs(c.b[0]) < 0.9 ? 0 : 1;
    double t[3] = {0, 0, 0};
    t[k] = 1;
    const double tb = t[0] * c.b[0] + t[1] * c.b[1] + t[2] * c.b[2];
    for (int i = 0; i < 3; ++i) t[i] -= tb * c.b[i];
    const double n = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int i = 0; i < 3; ++i) e[i] = t[i] / n;
  }
  return c.R - d;
}

// How deep the capstan cuts into a face between its contact points: the largest
// penetration R - d over a 7x7 grid of the bilinear face, its place in `at`, and
// the face's longest edge (deformed) in `edge`. Contact holds the face's points
// only; a capstan that the faces have closed behind (the body pushed through it)
// or that fits between points far apart cuts a face much deeper than the sagitta
// h^2 / 8R a touching face has.
KOKKOS_INLINE_FUNCTION double faceCut(const double x[4][3], const Cylinder& c, double at[3], double& edge) {
  edge = 0;
  for (int a = 0; a < 4; ++a) {
    const int b = (a + 1) % 4;
    const double l = sqrt((x[b][0] - x[a][0]) * (x[b][0] - x[a][0]) + (x[b][1] - x[a][1]) * (x[b][1] - x[a][1]) +
                          (x[b][2] - x[a][2]) * (x[b][2] - x[a][2]));
    edge = l > edge ? l : edge;
  }
  double deepest = -1e300, e[3], d;
  for (int k = 0; k < 3; ++k) at[k] = x[0][k];
  for (int i = 0; i <= 6; ++i)
    for (int j = 0; j <= 6; ++j) {
      const double xi = i / 6.0, eta = j / 6.0;
      const double N[4] = {(1 - xi) * (1 - eta), xi * (1 - eta), xi * eta, (1 - xi) * eta};
      double p[3] = {0, 0, 0};
      for (int a = 0; a < 4; ++a)
        for (int k = 0; k < 3; ++k) p[k] += N[a] * x[a][k];
      const double g = cylinderGap(c, p, e, d);
      if (g > deepest) {
        deepest = g;
        for (int k = 0; k < 3; ++k) at[k] = p[k];
      }
    }
  return deepest;
}

// What one contact point reports (for the multiplier update and the outputs).
struct ContactPoint {
  double gap = 0;        // g = R - d
  double pressure = 0;   // t_n
  double weight = 0;     // quadrature weight x reference area element
  double area = 0;       // quadrature weight x current area element
  double e[3] = {0, 0, 0};
  double x[3] = {0, 0, 0};
};

// Residual (internal - external: R_a = -sum_q w dA N_a t) and, if K is not
// null, its consistent tangent dR/dx (12 x 12, row-major) of one face with
// nodes X (reference) and x (current). lambda: one multiplier per rule point.
// Returns true if any point is in contact (t_n > 0); otherwise R and K are left
// untouched, as the face contributes nothing: the caller skips it. The
// tangent of t = t_n e is
//     dt/dx = -(1/eps) e e^T + (t_n / d) (P - e e^T),   de/dx = (P - e e^T) / d.
// geometric = false leaves out the second (rotation of e) term: only for a
// step predictor, whose state can penetrate by a whole load increment, where
// t_n / d is large and makes the tangent indefinite.
KOKKOS_INLINE_FUNCTION bool contactFaceResidualTangent(const double X[4][3], const double x[4][3],
                                                       const Cylinder& cyl, double eps,
                                                       double kappa, const double* lambda,
                                                       FaceRule rule, double R[12], double* K,
                                                       ContactPoint pts[kMaxFacePoints],
                                                       bool geometric = true) {
  const int nq = facePointCount(rule);
  bool touching = false;
  double N[kMaxFacePoints][4], slope[kMaxFacePoints];
  for (int q = 0; q < nq; ++q) {
    double xi, eta, w, dN[4][2];
    facePoint(rule, q, xi, eta, w);
    ContactPoint& p = pts[q];
    p.weight = w * quadAreaElement(X, xi, eta, N[q]);
    p.area = w * quadAreaElement(x, xi, eta, N[q]);
    quadShape(xi, eta, N[q], dN);
    for (int i = 0; i < 3; ++i) p.x[i] = 0;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) p.x[i] += N[q][a] * x[a][i];
    double d;
    p.gap = cylinderGap(cyl, p.x, p.e, d);
    const double tn = lambda[q] + (p.gap - kappa * lambda[q]) / eps;
    p.pressure = contactPressure(tn, cyl.smoothing, slope[q]);
    touching = touching || p.pressure > 0;
  }
  if (!touching) return false;

  for (int k = 0; k < 12; ++k) R[k] = 0;
  if (K)
    for (int k = 0; k < 144; ++k) K[k] = 0;
  for (int q = 0; q < nq; ++q) {
    const ContactPoint& p = pts[q];
    if (!(p.pressure > 0)) continue;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) R[3 * a + i] -= p.weight * N[q][a] * p.pressure * p.e[i];
    if (!K) continue;
    const double d = cyl.R - p.gap;
    const double geo = geometric && d > 1e-300 ? p.pressure / d : 0.0;
    // C = -dt/dx = (slope/eps) e e^T - (t_n/d)(P - e e^T)
    double C[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double P = (i == j ? 1.0 : 0.0) - cyl.b[i] * cyl.b[j];
        C[i][j] = slope[q] * p.e[i] * p.e[j] / eps - geo * (P - p.e[i] * p.e[j]);
      }
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        const double s = p.weight * N[q][a] * N[q][b];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) K[(3 * a + i) * 12 + 3 * b + j] += s * C[i][j];
      }
  }
  return true;
}

}  // namespace capstan::kernels
