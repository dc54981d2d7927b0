// Friction face kernel (kernels/friction.hpp): tangent against central finite
// differences for every law, Coulomb's stick and slip branches, rolling and
// translating capstans; the regularised laws' psi = phi/s and chi = psi'/s,
// finite at zero slip; the traction never exceeds mu t_n.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "kernels/friction.hpp"

using namespace capstan::kernels;

namespace {

Cylinder cylinder(const double dir[3]) {
  Cylinder c;
  const double a[3] = {0.25, 2.0, 0.3};
  const double n = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  for (int i = 0; i < 3; ++i) c.a[i] = a[i], c.b[i] = dir[i] / n;
  c.R = 2.0;
  return c;
}

// A warped quad just under the capstan (all of it in contact at the start).
void face(double x[4][3], double dy, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(-0.03, 0.03);
  const double base[4][3] = {{-0.1, 0, 0}, {0.5, 0, 0}, {0.5, 0, 0.6}, {-0.1, 0, 0.6}};
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) x[a][i] = base[a][i] + d(gen) + (i == 1 ? dy : 0.0);
}

struct Case {
  const char* name;
  FrictionLaw law;
  double mu, v, tangentPenalty;
  double ds[3], spin;
  double axis[3];
  double history;      // Coulomb: magnitude of last step's traction
  int expectState;     // every point: 1 stick, 2 slip (0: do not check)
  double smoothing = 0;  // Coulomb: the smoothed stick/slip corner's width
  int held = 0;          // Coulomb: every point's hold, kHeldInSlip or kHeldInStick (FrictionEffect::notePass)
};

std::vector<double> residual(const double X[4][3], const double x[4][3], const double xn[4][3],
                             const Cylinder& c, const FrictionParameters& fp, const double* lambda,
                             const double* h, const int* held = nullptr) {
  std::vector<double> R(12, 0.0);
  FrictionPoint pts[kMaxFacePoints];
  if (!frictionFaceResidualTangent(X, x, xn, c, 1e-2, 1e-2, lambda, FaceRule::Gauss2, fp, h, R.data(),
                                   nullptr, pts, nullptr, held))
    std::fill(R.begin(), R.end(), 0.0);
  return R;
}

class FrictionTangent : public ::testing::TestWithParam<Case> {};

TEST_P(FrictionTangent, MatchesCentralDifferences) {
  const Case k = GetParam();
  const Cylinder cyl = cylinder(k.axis);
  FrictionParameters fp;
  fp.law = k.law;
  fp.mu = k.mu;
  fp.v = k.v;
  fp.tangentPenalty = k.tangentPenalty;
  for (int i = 0; i < 3; ++i) fp.ds[i] = k.ds[i];
  fp.spin = k.spin;
  fp.smoothing = k.smoothing;
  double lambda[kMaxFacePoints] = {}, h[3 * kMaxFacePoints];
  int heldAll[kMaxFacePoints];
  std::fill(heldAll, heldAll + kMaxFacePoints, k.held);
  const int* held = k.held ? heldAll : nullptr;
  for (int q = 0; q < kMaxFacePoints; ++q) {
    h[3 * q] = k.history * (1 + 0.1 * q);
    h[3 * q + 1] = 0.2 * k.history;
    h[3 * q + 2] = -0.3 * k.history;
  }
  int checked = 0;
  for (int pos = 0; pos < 6; ++pos) {
    double X[4][3], x[4][3], xn[4][3];
    face(X, -0.1, 5 + pos);
    face(xn, 0.058 + 0.004 * pos, 50 + pos);  // last converged state
    face(x, 0.060 + 0.004 * pos, 500 + pos);  // now: moved a little since then
    std::vector<double> R(12), K(144), Kn(144);
    FrictionPoint pts[kMaxFacePoints];
    ASSERT_TRUE(frictionFaceResidualTangent(X, x, xn, cyl, 1e-2, 1e-2, lambda, FaceRule::Gauss2, fp, h,
                                            R.data(), K.data(), pts, Kn.data(), held))
        << k.name << ": face not in contact at position " << pos;
    bool nearSwitch = false;
    for (int q = 0; q < 4; ++q) {
      const double tmag = std::sqrt(pts[q].traction[0] * pts[q].traction[0] +
                                    pts[q].traction[1] * pts[q].traction[1] +
                                    pts[q].traction[2] * pts[q].traction[2]);
      EXPECT_GT(pts[q].normal, 0) << k.name;
      if (k.held == kHeldInStick)  // the stick branch outside the cone (this case's trial traction)
        EXPECT_GT(tmag, k.mu * pts[q].normal) << k.name << ": held in stick, not outside the cone";
      else
        EXPECT_LE(tmag, k.mu * pts[q].normal * (1 + 1e-12)) << k.name << ": |t_f| > mu t_n";
      if (k.expectState) {
        EXPECT_EQ(pts[q].state, k.expectState) << k.name << " point " << q;
      }
      if (k.held == kHeldInSlip) {
        EXPECT_NEAR(tmag, k.mu * pts[q].normal, 1e-12 * k.mu * pts[q].normal) << k.name << ": at the cone";
      }
      // Coulomb: central differences must not straddle the stick/slip switch.
      if (k.law == FrictionLaw::Coulomb && pts[q].state == 1 && k.held != kHeldInStick)
        nearSwitch = nearSwitch || tmag > k.mu * pts[q].normal * (1 - 1e-4);
    }
    if (nearSwitch) continue;
    // The largest error of the tangent `T` against central differences of the
    // residual with respect to `y` (x, or xn), relative to the largest entry.
    auto fdError = [&](double (&y)[4][3], const std::vector<double>& T, double& scale) {
      const double hx = 1e-6;
      double maxErr = 0;
      scale = 0;
      for (int col = 0; col < 12; ++col) {
        y[col / 3][col % 3] += hx;
        const auto Rp = residual(X, x, xn, cyl, fp, lambda, h, held);
        y[col / 3][col % 3] -= 2 * hx;
        const auto Rm = residual(X, x, xn, cyl, fp, lambda, h, held);
        y[col / 3][col % 3] += hx;
        for (int row = 0; row < 12; ++row) {
          const double fd = (Rp[row] - Rm[row]) / (2 * hx);
          maxErr = std::max(maxErr, std::fabs(T[row * 12 + col] - fd));
          scale = std::max(scale, std::fabs(fd));
        }
      }
      return maxErr / scale;
    };
    double scale = 0, scaleN = 0;
    EXPECT_LT(fdError(x, K, scale), 1e-6) << k.name << " position " << pos;
    // dR/dxn (steady rolling: xn is the upstream nodes' position, an unknown).
    const double errN = fdError(xn, Kn, scaleN);
    EXPECT_GT(scaleN, 0) << k.name;
    EXPECT_LT(errN, 1e-6) << k.name << " position " << pos << " (dR/dxn)";
    ++checked;
  }
  EXPECT_GE(checked, 4) << k.name;
}

const double kZ[3] = {0, 0, 1};

INSTANTIATE_TEST_SUITE_P(
    Friction, FrictionTangent,
    ::testing::Values(
        Case{"tanh, rolling", FrictionLaw::Tanh, 0.3, 1e-2, 0, {0, 0, 0}, 0.05, {0, 0, 1}, 0, 2},
        Case{"tanh, translating, skewed axis", FrictionLaw::Tanh, 0.3, 1e-2, 0, {0.02, -0.01, 0.01}, 0, {0.2, -0.1, 1}, 0, 0},
        Case{"tanh, rolling, slip within the regularisation", FrictionLaw::Tanh, 0.9, 0.5, 0, {0, 0, 0}, 0.01, {0, 0, 1}, 0, 1},
        Case{"arctan, rolling and translating", FrictionLaw::Arctan, 0.5, 1e-2, 0, {0.01, 0, 0.02}, 0.04, {0.1, 0, 1}, 0, 0},
        Case{"arctan, small slip", FrictionLaw::Arctan, 0.5, 1.0, 0, {0, 0, 0}, 0.003, {0, 0, 1}, 0, 1},
        Case{"coulomb stick, rolling", FrictionLaw::Coulomb, 5.0, 0, 0.1, {0, 0, 0}, 0.01, {0, 0, 1}, 0.05, 1},
        Case{"coulomb slip, rolling", FrictionLaw::Coulomb, 0.1, 0, 1e-3, {0, 0, 0}, 0.05, {0, 0, 1}, 0.05, 2},
        Case{"coulomb slip, translating, skewed", FrictionLaw::Coulomb, 0.2, 0, 1e-3, {0.03, 0, 0.02}, 0, {0.2, 0.1, 1}, 0.1, 2},
        Case{"coulomb stick, skewed, history", FrictionLaw::Coulomb, 10.0, 0, 0.05, {0.001, 0, 0}, 0.002, {0.1, -0.2, 1}, 0.2, 1},
        Case{"coulomb, smoothed corner", FrictionLaw::Coulomb, 0.3, 0, 1e-2, {0, 0, 0}, 0.01, {0, 0, 1}, 0.05, 0, 0.3},
        // The stick case's points held in slip: the slip branch inside the cone.
        Case{"coulomb stick held in slip", FrictionLaw::Coulomb, 5.0, 0, 0.1, {0, 0, 0}, 0.01, {0, 0, 1}, 0.05, 2, 0,
             kHeldInSlip},
        // The slip case's points held in stick (the loop's states frozen): the stick branch outside it.
        Case{"coulomb slip held in stick", FrictionLaw::Coulomb, 0.1, 0, 1e-3, {0, 0, 0}, 0.05, {0, 0, 1}, 0.05, 1, 0,
             kHeldInStick}));

// psi = phi(s)/s and chi = psi'(s)/s against finite differences of phi(s)/s,
// across the series/closed-form switch, and finite at s = 0.
TEST(Friction, RegularisedLawsAreSmoothAndFiniteAtZeroSlip) {
  for (FrictionLaw law : {FrictionLaw::Tanh, FrictionLaw::Arctan}) {
    const double v = 0.3;
    auto phi = [&](double s) {
      return law == FrictionLaw::Tanh ? std::tanh(s / v) : 2 / M_PI * std::atan(s / v);
    };
    double psi0, chi0;
    regularisedLaw(law, 0.0, v, psi0, chi0);
    EXPECT_NEAR(psi0, (law == FrictionLaw::Tanh ? 1.0 : 2 / M_PI) / v, 1e-15);
    EXPECT_TRUE(std::isfinite(chi0));
    for (double z : {1e-6, 9.99e-3, 1.001e-2, 0.3, 2.0, 19.9, 20.1, 100.0}) {
      const double s = z * v;
      double psi, chi;
      regularisedLaw(law, s, v, psi, chi);
      EXPECT_NEAR(psi, phi(s) / s, 1e-12 * std::fabs(psi)) << "z = " << z;
      if (z < 1e-4) {  // finite differences drown in round-off: the limit -2/3 scale / v^3
        EXPECT_NEAR(chi, psi0 * v * (-2.0 / 3.0) / (v * v * v), 1e-9 * std::fabs(chi));
        continue;
      }
      const double h = 1e-5 * s;
      const double dpsi = (phi(s + h) / (s + h) - phi(s - h) / (s - h)) / (2 * h);
      EXPECT_NEAR(chi, dpsi / s, 1e-5 * std::fabs(chi) + 1e-9) << "law " << int(law) << " z = " << z;
    }
  }
}

// Full slip far beyond the regularisation: |t_f| = mu t_n, along the slip.
TEST(Friction, FullSlipMobilisesMuTimesNormal) {
  const Cylinder cyl = cylinder(kZ);
  FrictionParameters fp;
  fp.law = FrictionLaw::Tanh;
  fp.mu = 0.4;
  fp.v = 1e-6;
  fp.spin = 0.1;
  double X[4][3], x[4][3], lambda[kMaxFacePoints] = {}, h[3 * kMaxFacePoints] = {}, R[12];
  face(X, -0.1, 1);
  face(x, 0.07, 2);
  FrictionPoint pts[kMaxFacePoints];
  ASSERT_TRUE(frictionFaceResidualTangent(X, x, x, cyl, 1e-2, 1e-2, lambda, FaceRule::Gauss2, fp, h, R,
                                          nullptr, pts));
  for (int q = 0; q < 4; ++q) {
    const auto& t = pts[q].traction;
    const double mag = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    EXPECT_NEAR(mag, 0.4 * pts[q].normal, 1e-12 * mag);
    EXPECT_GT(t[0], 0) << "the capstan turning about +z drags the face below it towards +x";
    EXPECT_EQ(pts[q].state, 2);
  }
}

}  // namespace
