// Friction between a body face and a rigid, turning capstan (formulation.md §2,
// §3). Pure functions of one face's data.
//
// At a contact point x (normal traction t_n > 0, from kernels/contact.hpp) the
// capstan's surface moves in the increment by
//     u_c = ds + spin tau,   tau = b x e,   spin = omega dt R
// and slides over the body by du = u_c - (x - x_n) (x_n: the point at the last
// converged state), projected on the tangent plane: du_t = (I - e e^T) du.
// The friction traction on the body acts along du_t:
//   Tanh, Arctan:  t_f = mu t_n phi(|du_t|) du_t / |du_t|,
//                  phi = tanh(s / v) or (2/pi) atan(s / v), v = eps3 dt;
//   Coulomb:       trial t* = P_t h + du_t / eps_t (h: last step's traction,
//                  eps_t the tangential penalty); stick if |t*| <= mu t_n
//                  (t_f = t*), else slip (t_f = mu t_n t* / |t*|).
// Everything depends on x only through the point, so the tangent is built per
// point (dt_f/dx, 3x3, non-symmetric) and spread to the nodes by N_a N_b.
#pragma once

#include "contact.hpp"

namespace capstan::kernels {

enum class FrictionLaw { None = 0, Tanh = 1, Arctan = 2, Coulomb = 3 };

struct FrictionParameters {
  FrictionLaw law = FrictionLaw::None;
  double mu = 0;
  double v = 1e-3;             // regularised laws: eps3 (or eps4) x dt, a slip length
  double tangentPenalty = 1e-3;  // Coulomb: eps_t, slip per unit traction while sticking
  double ds[3] = {0, 0, 0};    // translation of the capstan in the increment
  double spin = 0;             // omega dt R: surface travel of the turning capstan
  // Coulomb: width delta of a smoothed stick/slip corner (0: the exact return
  // mapping). t = t* / m(s), s = |t*| / (mu t_n), m = (1 + s + sqrt((s-1)^2 +
  // delta^2)) / 2 >= max(1, s): |t| <= mu t_n still, stick traction softened by
  // about delta^2 / 4, |t| = mu t_n / (1 + delta/2) at the corner. Newton stalls
  // at the exact corner when points keep switching (rolling contact).
  double smoothing = 0;
  // Step predictor only: every point sticks (Coulomb: the trial traction, no
  // return mapping; regularised laws: their zero-slip slope, t = mu t_n du_t / v),
  // so the linear response moves the body with the capstan where friction holds.
  bool stickPredictor = false;
};

// psi(s) = phi(s) / s and chi(s) = psi'(s) / s of a regularised law, finite at
// s = 0 (series below z = s/v = 1e-2, where the closed forms cancel).
KOKKOS_INLINE_FUNCTION void regularisedLaw(FrictionLaw law, double s, double v, double& psi,
                                           double& chi) {
  const double z = s / v, v3 = v * v * v;
  const double scale = law == FrictionLaw::Arctan ? 0.63661977236758134308 : 1.0;  // 2/pi
  if (z < 1e-2) {
    // tanh z / z = 1 - z^2/3 + 2 z^4/15,  atan z / z = 1 - z^2/3 + z^4/5
    const double c4 = law == FrictionLaw::Arctan ? 0.2 : 2.0 / 15.0;
    psi = scale / v * (1 - z * z / 3 + c4 * z * z * z * z);
    chi = scale / v3 * (-2.0 / 3.0 + 4 * c4 * z * z);
    return;
  }
  if (law == FrictionLaw::Arctan) {
    const double a = Kokkos::Experimental::atan(z);
    psi = scale * a / s;
    chi = scale / v3 * (1 / (z * z * (1 + z * z)) - a / (z * z * z));
  } else if (z > 20) {  // tanh z = 1 to round-off
    psi = 1 / s;
    chi = -1 / (s * s * s);
  } else {
    const double t = Kokkos::Experimental::tanh(z), ch = Kokkos::Experimental::cosh(z);
    psi = t / s;
    chi = (1 / (ch * ch * z * z) - t / (z * z * z)) / v3;
  }
}

// What one friction point reports.
// A point's hold (frictionFaceResidualTangent's held): free, or Coulomb's branch fixed.
constexpr int kHeldInSlip = 1, kHeldInStick = 2;

struct FrictionPoint {
  double traction[3] = {0, 0, 0};  // friction traction on the body (per reference area)
  double normal = 0;               // t_n
  double slip = 0;                 // |du_t|
  int state = 0;                   // 0 no contact, 1 stick, 2 slip
  double weight = 0;               // quadrature weight x reference area element
  double e[3] = {0, 0, 0};         // unit vector from the axis towards the point
  // Work dissipated in the increment per reference area, t . (plastic slip):
  // t . du_t for the regularised laws; Coulomb t . (du_t - eps_t (t - h)),
  // zero while sticking (the rest of du_t is the elastic slip).
  double work = 0;
};

// Residual (R_a = -sum_q w N_a t_f) and tangent (if K is not null) of one face.
// xn: the face's nodes at the last converged state; lambda, eps, kappa: the
// normal contact's multipliers and penalties (as in contactFaceResidualTangent);
// history: Coulomb's traction per point from the last step (3 per point).
// Kn (if not null, with K): the tangent with respect to xn, dR/dxn (12 x 12),
// which steady rolling needs: there xn is the upstream nodes' position
// (src/effects/steady_friction.cpp), an unknown like x.
// held (if not null): per point, kHeldInSlip to take Coulomb's slip branch even
// inside the cone (a point the multiplier loop found toggling), kHeldInStick its
// stick branch even outside it (the loop's states frozen; FrictionEffect::notePass).
// Returns false (R, K untouched) if no point of the face is in contact.
KOKKOS_INLINE_FUNCTION bool frictionFaceResidualTangent(
    const double X[4][3], const double x[4][3], const double xn[4][3], const Cylinder& cyl,
    double eps, double kappa, const double* lambda, FaceRule rule, const FrictionParameters& fp,
    const double* history, double R[12], double* K, FrictionPoint pts[kMaxFacePoints],
    double* Kn = nullptr, const int* held = nullptr) {
  const int nq = facePointCount(rule);
  bool touching = false;
  for (int q = 0; q < nq && !touching; ++q) {
    double xi, eta, w, N[4], dN[4][2], xq[3] = {0, 0, 0}, e[3], d;
    facePoint(rule, q, xi, eta, w);
    quadShape(xi, eta, N, dN);
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) xq[i] += N[a] * x[a][i];
    const double g = cylinderGap(cyl, xq, e, d);
    double slope;
    touching = contactPressure(lambda[q] + (g - kappa * lambda[q]) / eps, cyl.smoothing, slope) > 0;
  }
  for (int q = 0; q < nq; ++q) pts[q] = FrictionPoint();
  if (!touching) return false;

  for (int k = 0; k < 12; ++k) R[k] = 0;
  if (K)
    for (int k = 0; k < 144; ++k) K[k] = 0;
  if (K && Kn)
    for (int k = 0; k < 144; ++k) Kn[k] = 0;
  const double* b = cyl.b;
  for (int q = 0; q < nq; ++q) {
    double xi, eta, w, N[4], dN[4][2];
    facePoint(rule, q, xi, eta, w);
    FrictionPoint& p = pts[q];
    p.weight = w * quadAreaElement(X, xi, eta, N);
    quadShape(xi, eta, N, dN);
    double xq[3] = {0, 0, 0}, xnq[3] = {0, 0, 0}, e[3], d;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) {
        xq[i] += N[a] * x[a][i];
        xnq[i] += N[a] * xn[a][i];
      }
    const double g = cylinderGap(cyl, xq, e, d);
    double slope;  // dtn/dx = -(slope/eps) e^T
    const double tn = contactPressure(lambda[q] + (g - kappa * lambda[q]) / eps, cyl.smoothing, slope);
    if (!(tn > 0)) continue;
    p.normal = tn;
    for (int i = 0; i < 3; ++i) p.e[i] = e[i];

    // Slip in the increment and its derivatives with respect to the point x.
    const double tau[3] = {b[1] * e[2] - b[2] * e[1], b[2] * e[0] - b[0] * e[2],
                           b[0] * e[1] - b[1] * e[0]};
    double du[3];
    for (int i = 0; i < 3; ++i) du[i] = fp.ds[i] + fp.spin * tau[i] - (xq[i] - xnq[i]);
    const double en = e[0] * du[0] + e[1] * du[1] + e[2] * du[2];
    double dut[3];
    for (int i = 0; i < 3; ++i) dut[i] = du[i] - en * e[i];
    double E[3][3];  // de/dx = (P - e e^T) / d
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        E[i][j] = ((i == j ? 1.0 : 0.0) - b[i] * b[j] - e[i] * e[j]) / d;
    double D[3][3];  // d(du)/dx = spin [b x] E - I
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        D[i][j] = fp.spin * (b[i1] * E[i2][j] - b[i2] * E[i1][j]) - (i == j ? 1.0 : 0.0);
      }
    double duE[3];  // du^T E
    for (int j = 0; j < 3; ++j) duE[j] = du[0] * E[0][j] + du[1] * E[1][j] + du[2] * E[2][j];
    double Dt[3][3];  // d(du_t)/dx = (I - e e^T) D - e (du^T E) - (e.du) E
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double s = 0;
        for (int k = 0; k < 3; ++k) s += ((i == k ? 1.0 : 0.0) - e[i] * e[k]) * D[k][j];
        Dt[i][j] = s - e[i] * duE[j] - en * E[i][j];
      }
    double P[3][3];  // d(du_t)/dxn = I - e e^T (e depends on x only)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) P[i][j] = (i == j ? 1.0 : 0.0) - e[i] * e[j];
    const double slip = sqrt(dut[0] * dut[0] + dut[1] * dut[1] + dut[2] * dut[2]);
    p.slip = slip;
    double t[3], T[3][3], Tn[3][3];  // traction, dt/dx and dt/dxn
    if (fp.law == FrictionLaw::Coulomb) {
      const double* h = history + 3 * q;
      const double eh = e[0] * h[0] + e[1] * h[1] + e[2] * h[2];
      double hE[3];
      for (int j = 0; j < 3; ++j) hE[j] = h[0] * E[0][j] + h[1] * E[1][j] + h[2] * E[2][j];
      double tr[3], Tr[3][3], Trn[3][3];  // trial traction and its derivatives
      for (int i = 0; i < 3; ++i) {
        tr[i] = h[i] - eh * e[i] + dut[i] / fp.tangentPenalty;
        for (int j = 0; j < 3; ++j) {
          Tr[i][j] = -e[i] * hE[j] - eh * E[i][j] + Dt[i][j] / fp.tangentPenalty;
          Trn[i][j] = P[i][j] / fp.tangentPenalty;
        }
      }
      const double mag = sqrt(tr[0] * tr[0] + tr[1] * tr[1] + tr[2] * tr[2]);
      if (fp.smoothing > 0 && fp.mu > 0 && !fp.stickPredictor) {  // smoothed corner
        const double s = mag / (fp.mu * tn);
        const double r = sqrt((s - 1) * (s - 1) + fp.smoothing * fp.smoothing);
        const double m = 0.5 * (1 + s + r), dm = 0.5 * (1 + (s - 1) / r);
        p.state = s <= 1 ? 1 : 2;
        double dS[3], dSn[3];  // ds/dx = (n^T Tr) / (mu t_n) - s / t_n dt_n/dx, dt_n/dx = -(slope/eps) e^T
        for (int j = 0; j < 3; ++j) {
          double nTr = 0, nTrn = 0;
          if (mag > 1e-300)
            for (int k = 0; k < 3; ++k) nTr += tr[k] / mag * Tr[k][j], nTrn += tr[k] / mag * Trn[k][j];
          dS[j] = nTr / (fp.mu * tn) + s / tn * slope * e[j] / eps;
          dSn[j] = nTrn / (fp.mu * tn);
        }
        for (int i = 0; i < 3; ++i) {
          t[i] = tr[i] / m;
          for (int j = 0; j < 3; ++j) {
            T[i][j] = Tr[i][j] / m - tr[i] / (m * m) * dm * dS[j];
            Tn[i][j] = Trn[i][j] / m - tr[i] / (m * m) * dm * dSn[j];
          }
        }
      } else if ((mag <= fp.mu * tn && !(held && held[q] == kHeldInSlip && mag > 0)) ||
                 (held && held[q] == kHeldInStick) || fp.stickPredictor) {  // stick
        p.state = 1;
        for (int i = 0; i < 3; ++i) {
          t[i] = tr[i];
          for (int j = 0; j < 3; ++j) T[i][j] = Tr[i][j], Tn[i][j] = Trn[i][j];
        }
      } else {  // slip: t = mu t_n n, n = tr / |tr|
        p.state = 2;
        double n[3];
        for (int i = 0; i < 3; ++i) n[i] = tr[i] / mag;
        for (int i = 0; i < 3; ++i) {
          t[i] = fp.mu * tn * n[i];
          for (int j = 0; j < 3; ++j) {
            double s = 0, sn = 0;
            for (int k = 0; k < 3; ++k) {
              s += ((i == k ? 1.0 : 0.0) - n[i] * n[k]) * Tr[k][j];
              sn += ((i == k ? 1.0 : 0.0) - n[i] * n[k]) * Trn[k][j];
            }
            T[i][j] = fp.mu * (n[i] * (-slope * e[j] / eps) + tn * s / mag);
            Tn[i][j] = fp.mu * tn * sn / mag;
          }
        }
      }
    } else {
      double psi, chi;
      regularisedLaw(fp.law, fp.stickPredictor ? 0.0 : slip, fp.v, psi, chi);
      if (fp.stickPredictor) chi = 0;
      p.state = slip <= fp.v ? 1 : 2;  // within the regularisation: counted as stick
      double dutDt[3];
      for (int j = 0; j < 3; ++j) dutDt[j] = dut[0] * Dt[0][j] + dut[1] * Dt[1][j] + dut[2] * Dt[2][j];
      for (int i = 0; i < 3; ++i) {
        t[i] = fp.mu * tn * psi * dut[i];
        for (int j = 0; j < 3; ++j) {
          T[i][j] = fp.mu * (psi * dut[i] * (-slope * e[j] / eps) + tn * chi * dut[i] * dutDt[j] +
                             tn * psi * Dt[i][j]);
          // dut^T P = dut^T (dut is tangent)
          Tn[i][j] = fp.mu * tn * (chi * dut[i] * dut[j] + psi * P[i][j]);
        }
      }
    }
    for (int i = 0; i < 3; ++i) p.traction[i] = t[i];
    p.work = 0;
    if (fp.law == FrictionLaw::Coulomb) {  // t . (du_t - eps_t (t - h_t)) = eps_t t . (t* - t)
      const double* h = history + 3 * q;
      const double eh = e[0] * h[0] + e[1] * h[1] + e[2] * h[2];
      for (int i = 0; i < 3; ++i) {
        const double trial = h[i] - eh * e[i] + dut[i] / fp.tangentPenalty;
        p.work += fp.tangentPenalty * t[i] * (trial - t[i]);
      }
      // Negative only at a point held in slip with its trial inside the cone (the
      // multiplier loop's last resort): the law sticks it there, and sticking
      // dissipates nothing (the sweep's steady drive on 1x43x1 reported -0.017).
      if (p.work < 0) p.work = 0;
    } else {
      for (int i = 0; i < 3; ++i) p.work += t[i] * dut[i];
    }
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) R[3 * a + i] -= p.weight * N[a] * t[i];
    if (!K) continue;
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 4; ++c) {
        const double s = p.weight * N[a] * N[c];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            K[(3 * a + i) * 12 + 3 * c + j] -= s * T[i][j];
            if (Kn) Kn[(3 * a + i) * 12 + 3 * c + j] -= s * Tn[i][j];
          }
      }
  }
  return true;
}

}  // namespace capstan::kernels
