// Kernel checks: every tangent against central finite differences of its
// residual, and rigid motions give zero residual and zero stress.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "kernels/body_force.hpp"
#include "kernels/brick.hpp"
#include "kernels/foundation.hpp"

using namespace capstan::kernels;

namespace {

// A distorted reference brick: unit cube with perturbed corners.
void distortedBrick(double X[8][3], unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(-0.15, 0.15);
  for (int a = 0; a < 8; ++a) {
    X[a][0] = 0.5 * (1 + hexXiSign(a)) * 1.3 + d(gen);
    X[a][1] = 0.5 * (1 + hexEtaSign(a)) * 0.8 + d(gen);
    X[a][2] = 0.5 * (1 + hexZetaSign(a)) * 1.1 + d(gen);
  }
}

// A non-trivial deformation: shear, stretch and a quadratic bend plus noise.
void deform(const double X[8][3], double x[8][3], unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(-0.05, 0.05);
  for (int a = 0; a < 8; ++a) {
    x[a][0] = 1.2 * X[a][0] + 0.3 * X[a][1] + 0.1 * X[a][2] * X[a][2] + d(gen);
    x[a][1] = 0.9 * X[a][1] - 0.1 * X[a][0] * X[a][2] + d(gen);
    x[a][2] = 0.95 * X[a][2] + 0.2 * X[a][0] + d(gen);
  }
}

double relErr(const std::vector<double>& a, const std::vector<double>& b) {
  double num = 0, den = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    num = std::max(num, std::fabs(a[i] - b[i]));
    den = std::max(den, std::fabs(b[i]));
  }
  return num / den;
}

struct BrickCase {
  double c, eps, pbar;
  unsigned seed;
};

class BrickTangent : public ::testing::TestWithParam<BrickCase> {};

TEST_P(BrickTangent, MatchesCentralDifferences) {
  const auto pc = GetParam();
  double X[8][3], x[8][3];
  distortedBrick(X, pc.seed);
  deform(X, x, pc.seed + 7);
  double minJ;
  const double V = brickVolume(X, X, minJ);
  ASSERT_GT(minJ, 0);
  std::vector<double> R(24), K(576), fd(576);
  BrickState st;
  brickResidualTangent(X, x, V, pc.pbar, pc.c, pc.eps, R.data(), K.data(), st);
  ASSERT_GT(st.minJ, 0);
  // Step scaled to the element; central differences error ~h^2.
  const double h = 1e-6;
  for (int col = 0; col < 24; ++col) {
    double xp[8][3], xm[8][3];
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) xp[a][i] = xm[a][i] = x[a][i];
    xp[col / 3][col % 3] += h;
    xm[col / 3][col % 3] -= h;
    std::vector<double> Rp(24), Rm(24);
    BrickState s2;
    brickResidualTangent(X, xp, V, pc.pbar, pc.c, pc.eps, Rp.data(), nullptr, s2);
    brickResidualTangent(X, xm, V, pc.pbar, pc.c, pc.eps, Rm.data(), nullptr, s2);
    for (int row = 0; row < 24; ++row) fd[row * 24 + col] = (Rp[row] - Rm[row]) / (2 * h);
  }
  EXPECT_LT(relErr(K, fd), 1e-6) << "c=" << pc.c << " eps=" << pc.eps << " pbar=" << pc.pbar;
}

INSTANTIATE_TEST_SUITE_P(Cases, BrickTangent,
                         ::testing::Values(BrickCase{1.0, 1e-3, 0.0, 1}, BrickCase{1.0, 1e-1, 0.7, 2},
                                           BrickCase{2.5, 1e-2, -1.3, 3}, BrickCase{0.3, 1.0, 2.0, 4}));

TEST(Brick, VolumeGradientIsG) {
  // d v / d x equals g = int J d_a dV: check through the pressure response.
  double X[8][3], x[8][3];
  distortedBrick(X, 11);
  deform(X, x, 12);
  double minJ;
  const double V = brickVolume(X, X, minJ);
  const double h = 1e-6;
  for (int col = 0; col < 24; col += 5) {
    double xp[8][3], xm[8][3];
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) xp[a][i] = xm[a][i] = x[a][i];
    xp[col / 3][col % 3] += h;
    xm[col / 3][col % 3] -= h;
    const double dv = (brickVolume(X, xp, minJ) - brickVolume(X, xm, minJ)) / (2 * h);
    // g_col from the residual's pressure part: R(p=1) - R(p=0) = -g (at eps -> inf).
    std::vector<double> R0(24), R1(24);
    BrickState st;
    brickResidualTangent(X, x, V, 0.0, 1.0, 1e300, R0.data(), nullptr, st);
    brickResidualTangent(X, x, V, 1.0, 1.0, 1e300, R1.data(), nullptr, st);
    EXPECT_NEAR(R0[col] - R1[col], dv, 1e-8 * std::fabs(dv) + 1e-12);
    // and brickVolumeGradient gives the same g.
    double g[24];
    brickVolumeGradient(X, x, g);
    EXPECT_NEAR(g[col], dv, 1e-8 * std::fabs(dv) + 1e-12);
  }
}

TEST(Brick, RigidMotionGivesZeroResidualAndStress) {
  double X[8][3], x[8][3];
  distortedBrick(X, 21);
  // Rotation about an oblique axis by 0.9 rad plus a translation.
  const double n[3] = {1 / std::sqrt(3.0), 1 / std::sqrt(3.0), 1 / std::sqrt(3.0)};
  const double th = 0.9, c = std::cos(th), s = std::sin(th);
  double Q[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Q[i][j] = c * (i == j) + (1 - c) * n[i] * n[j];
  Q[0][1] -= s * n[2], Q[0][2] += s * n[1], Q[1][0] += s * n[2];
  Q[1][2] -= s * n[0], Q[2][0] -= s * n[1], Q[2][1] += s * n[0];
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i)
      x[a][i] = Q[i][0] * X[a][0] + Q[i][1] * X[a][1] + Q[i][2] * X[a][2] + 0.3 * (i + 1);
  double minJ;
  const double V = brickVolume(X, X, minJ);
  std::vector<double> R(24);
  BrickState st;
  brickResidualTangent(X, x, V, 0.0, 1.0, 1e-3, R.data(), nullptr, st);
  for (double r : R) EXPECT_NEAR(r, 0.0, 1e-12);
  EXPECT_NEAR(st.volume, V, 1e-13);
  double sigma[6];
  brickCentroidStress(X, x, st.pressure, 1.0, sigma);
  for (double v : sigma) EXPECT_NEAR(v, 0.0, 1e-12);
}

TEST(Brick, HomogeneousStretchStress) {
  // Isochoric stretch: sigma_xx - sigma_yy = 2c (lambda^2 - 1/lambda).
  double X[8][3], x[8][3];
  for (int a = 0; a < 8; ++a) {
    X[a][0] = 0.5 * (1 + hexXiSign(a));
    X[a][1] = 0.5 * (1 + hexEtaSign(a));
    X[a][2] = 0.5 * (1 + hexZetaSign(a));
  }
  const double lam = 1.5, c = 0.7;
  for (int a = 0; a < 8; ++a) {
    x[a][0] = lam * X[a][0];
    x[a][1] = X[a][1] / std::sqrt(lam);
    x[a][2] = X[a][2] / std::sqrt(lam);
  }
  double sigma[6];
  brickCentroidStress(X, x, 0.0, c, sigma);
  EXPECT_NEAR(sigma[0] - sigma[1], 2 * c * (lam * lam - 1 / lam), 1e-12);
  EXPECT_NEAR(sigma[3], 0, 1e-14);
}

TEST(Foundation, TangentMatchesCentralDifferences) {
  const double X[4][3] = {{0, 0, 0}, {1.2, 0.1, 0}, {1.1, 0.9, 0.2}, {-0.1, 1.0, 0.1}};
  double u[4][3] = {{0.1, -0.2, 0.05}, {0.3, 0.1, 0}, {-0.1, 0.2, 0.1}, {0.05, 0.05, -0.2}};
  const int mask[3] = {1, 0, 1};
  std::vector<double> R(12), K(144), fd(144), Rp(12), Rm(12), R0(12);
  foundationResidualTangent(X, u, 2.5, mask, R.data(), K.data());
  // Without K (residual-only evaluations) the residual is the same, bit for bit.
  foundationResidualTangent(X, u, 2.5, mask, R0.data(), nullptr);
  EXPECT_EQ(R, R0);
  const double h = 1e-6;
  for (int col = 0; col < 12; ++col) {
    u[col / 3][col % 3] += h;
    foundationResidualTangent(X, u, 2.5, mask, Rp.data(), nullptr);
    u[col / 3][col % 3] -= 2 * h;
    foundationResidualTangent(X, u, 2.5, mask, Rm.data(), nullptr);
    u[col / 3][col % 3] += h;
    for (int row = 0; row < 12; ++row) fd[row * 12 + col] = (Rp[row] - Rm[row]) / (2 * h);
  }
  EXPECT_LT(relErr(K, fd), 1e-6);
  // A uniform displacement d on the face: total force -k d_i A on masked components.
  double uu[4][3];
  for (int a = 0; a < 4; ++a) uu[a][0] = 0.2, uu[a][1] = 0.3, uu[a][2] = -0.1;
  foundationResidualTangent(X, uu, 2.5, mask, R.data(), K.data());
  double area = 0, N[4];
  for (int q = 0; q < 4; ++q) area += quadAreaElement(X, gauss2(q & 1), gauss2(q >> 1), N);
  double F[3] = {0, 0, 0};
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) F[i] += R[3 * a + i];
  EXPECT_NEAR(F[0], 2.5 * 0.2 * area, 1e-12);
  EXPECT_NEAR(F[1], 0.0, 1e-15);
  EXPECT_NEAR(F[2], 2.5 * -0.1 * area, 1e-12);
}

// Body force: a dead load, so there is no tangent (the residual does not depend on
// the motion: nothing to difference). Its nodal loads add up to b V, and on a
// parallelepiped each node carries V / 8 (int N_a dV exact with 2x2x2 Gauss).
TEST(BodyForce, LoadsAddUpToBTimesVolume) {
  double X[8][3];
  distortedBrick(X, 7);
  const double b[3] = {0.3, -1.7, 0.25};
  double R[24];
  brickBodyForce(X, b, R);
  double V = 0;
  for (int q = 0; q < 8; ++q) {
    double D[8][3];
    V += hexReferenceGradients(X, gauss2(q & 1), gauss2((q >> 1) & 1), gauss2(q >> 2), D);
  }
  for (int i = 0; i < 3; ++i) {
    double F = 0;
    for (int a = 0; a < 8; ++a) F += R[3 * a + i];
    EXPECT_NEAR(F, -b[i] * V, 1e-13 * V);
  }
  double P[8][3];  // a sheared box: every node carries V / 8
  for (int a = 0; a < 8; ++a) {
    const double s0 = 0.5 * (1 + hexXiSign(a)), s1 = 0.5 * (1 + hexEtaSign(a)), s2 = 0.5 * (1 + hexZetaSign(a));
    P[a][0] = 2 * s0 + 0.4 * s1;
    P[a][1] = 1.5 * s1 + 0.2 * s2;
    P[a][2] = 0.5 * s2;
  }
  brickBodyForce(P, b, R);
  const double Vp = 2 * 1.5 * 0.5;
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(R[3 * a + i], -b[i] * Vp / 8, 1e-14);
}

}  // namespace
