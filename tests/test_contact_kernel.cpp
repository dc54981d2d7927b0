// Contact face kernel (kernels/contact.hpp): tangent against central finite
// differences for axes along a coordinate direction and skewed, faces partly
// and wholly in contact, penalty and augmented multipliers, every quadrature
// rule; the force the face receives; and the cheap exit for faces away from
// the capstan.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "kernels/contact.hpp"

using namespace capstan::kernels;

namespace {

Cylinder makeCylinder(const double a[3], const double dir[3], double R) {
  Cylinder c;
  const double n = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  for (int i = 0; i < 3; ++i) c.a[i] = a[i], c.b[i] = dir[i] / n;
  c.R = R;
  return c;
}

// A warped quad below the cylinder's lowest line, shifted by (sx, sy, sz).
void face(double x[4][3], double sx, double sy, double sz, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(-0.05, 0.05);
  const double base[4][3] = {{0, 0, 0}, {0.5, 0, 0}, {0.5, 0, 0.6}, {0, 0, 0.6}};
  for (int a = 0; a < 4; ++a) {
    x[a][0] = base[a][0] + sx + d(gen);
    x[a][1] = base[a][1] + sy + d(gen) + 0.1 * base[a][0] * base[a][2];
    x[a][2] = base[a][2] + sz + d(gen);
  }
}

struct Case {
  const char* name;
  double axisDir[3];
  double eps, kappa, lambda;
  FaceRule rule;
};

class ContactTangent : public ::testing::TestWithParam<Case> {};

// Residual of face x (12 values; zero if the face is not touching).
std::vector<double> residual(const double X[4][3], const double x[4][3], const Cylinder& c,
                             const Case& k, const double* lambda) {
  std::vector<double> R(12, 0.0);
  ContactPoint pts[kMaxFacePoints];
  if (!contactFaceResidualTangent(X, x, c, k.eps, k.kappa, lambda, k.rule, R.data(), nullptr, pts))
    std::fill(R.begin(), R.end(), 0.0);
  return R;
}

TEST_P(ContactTangent, MatchesCentralDifferences) {
  const Case k = GetParam();
  const double a[3] = {0.25, 2.0, 0.3};
  const Cylinder cyl = makeCylinder(a, k.axisDir, 2.0);
  double lambda[kMaxFacePoints];
  for (int q = 0; q < kMaxFacePoints; ++q) lambda[q] = k.lambda * (1 + 0.1 * q);
  int checked = 0, partly = 0;
  // Several positions: the face slides under the capstan and rises into it,
  // from barely touching (one or two points) to wholly in contact.
  for (int pos = 0; pos < 12; ++pos) {
    double X[4][3], x[4][3];
    face(X, -0.5 + 0.15 * pos, -0.1, -0.2, 11 + pos);
    face(x, -0.6 + 0.1 * pos, -0.02 + 0.004 * pos, -0.25 + 0.02 * pos, 101 + pos);
    std::vector<double> R(12), K(144);
    ContactPoint pts[kMaxFacePoints];
    if (!contactFaceResidualTangent(X, x, cyl, k.eps, k.kappa, lambda, k.rule, R.data(), K.data(), pts))
      continue;
    // Central differences must not straddle a point's switch t_n = 0.
    const int nq = facePointCount(k.rule);
    bool nearKink = false;
    int touching = 0;
    for (int q = 0; q < nq; ++q) {
      const double raw = lambda[q] + (pts[q].gap - k.kappa * lambda[q]) / k.eps;
      nearKink = nearKink || std::fabs(raw) * k.eps < 1e-4;
      touching += raw > 0;
    }
    if (nearKink) continue;
    partly += touching < nq;
    const double h = 1e-6;
    double maxErr = 0, scale = 0;
    for (int col = 0; col < 12; ++col) {
      x[col / 3][col % 3] += h;
      const auto Rp = residual(X, x, cyl, k, lambda);
      x[col / 3][col % 3] -= 2 * h;
      const auto Rm = residual(X, x, cyl, k, lambda);
      x[col / 3][col % 3] += h;
      for (int row = 0; row < 12; ++row) {
        const double fd = (Rp[row] - Rm[row]) / (2 * h);
        maxErr = std::max(maxErr, std::fabs(K[row * 12 + col] - fd));
        scale = std::max(scale, std::fabs(fd));
      }
    }
    EXPECT_LT(maxErr / scale, 1e-6) << k.name << " position " << pos;
    // The tangent is symmetric (a potential's Hessian).
    for (int r = 0; r < 12; ++r)
      for (int c = 0; c < r; ++c)
        EXPECT_NEAR(K[r * 12 + c], K[c * 12 + r], 1e-12 * scale) << k.name;
    ++checked;
  }
  EXPECT_GE(checked, 4) << k.name << ": too few positions in contact";
  EXPECT_GE(partly, 1) << k.name << ": no position with the face partly in contact";
}

INSTANTIATE_TEST_SUITE_P(
    Contact, ContactTangent,
    ::testing::Values(Case{"penalty, axis z, Gauss 2x2", {0, 0, 1}, 1e-2, 1e-2, 0, FaceRule::Gauss2},
                      Case{"penalty, skewed axis, Gauss 2x2", {0.2, -0.3, 1}, 1e-2, 1e-2, 0, FaceRule::Gauss2},
                      Case{"penalty, axis x, Gauss 3x3", {1, 0, 0.05}, 1e-2, 1e-2, 0, FaceRule::Gauss3},
                      Case{"augmented, axis z, nodal", {0, 0, 1}, 1e-2, 0, 0.5, FaceRule::Nodal},
                      Case{"augmented, skewed axis, nodal", {0.3, 0.1, 1}, 1e-2, 0, 0.5, FaceRule::Nodal},
                      Case{"solve penalty above the scene's, skewed", {0.2, 0, 1}, 1e-2, 1e-3, 0.3, FaceRule::Gauss2}));

// Far from the capstan: no contribution, and the caller may skip the face.
TEST(Contact, FaceAwayFromCapstanIsInactive) {
  const double a[3] = {0, 5, 0}, dir[3] = {0, 0, 1};
  const Cylinder cyl = makeCylinder(a, dir, 2.0);
  double X[4][3];
  face(X, 0, 0, 0, 3);
  double R[12], K[144], lambda[kMaxFacePoints] = {};
  ContactPoint pts[kMaxFacePoints];
  EXPECT_FALSE(contactFaceResidualTangent(X, X, cyl, 1e-3, 1e-3, lambda, FaceRule::Gauss2, R, K, pts));
  for (int q = 0; q < 4; ++q) {
    EXPECT_LT(pts[q].gap, -2.5);
    EXPECT_EQ(pts[q].pressure, 0.0);
  }
}

// A flat face pressed by a capstan whose axis is parallel to it: with the nodal
// rule each node gets the traction (g / eps) e of its own penetration, weighted
// by a quarter of the face's area; the total force on the face is their sum.
TEST(Contact, NodalForceOfAFlatFace) {
  const double a[3] = {0.3, 2.0 - 0.05, 0}, dir[3] = {0, 0, 1};
  const Cylinder cyl = makeCylinder(a, dir, 2.0);
  const double X[4][3] = {{0, 0, 0}, {0.6, 0, 0}, {0.6, 0, 1}, {0, 0, 1}};
  double R[12], lambda[kMaxFacePoints] = {};
  ContactPoint pts[kMaxFacePoints];
  const double eps = 1e-3;
  ASSERT_TRUE(contactFaceResidualTangent(X, X, cyl, eps, eps, lambda, FaceRule::Nodal, R, nullptr, pts));
  double F[3] = {0, 0, 0}, expect[3] = {0, 0, 0};
  for (int a2 = 0; a2 < 4; ++a2)
    for (int i = 0; i < 3; ++i) F[i] -= R[3 * a2 + i];  // force on the body
  for (int n = 0; n < 4; ++n) {
    const double dx = X[n][0] - a[0], dy = X[n][1] - a[1];
    const double d = std::sqrt(dx * dx + dy * dy), g = 2.0 - d;
    if (g <= 0) continue;
    expect[0] += 0.15 * g / eps * dx / d;  // area 0.6 / 4
    expect[1] += 0.15 * g / eps * dy / d;
  }
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(F[i], expect[i], 1e-12);
  EXPECT_LT(F[1], 0.0);  // pushed away from the axis, which lies above
}

TEST(Contact, PointOnTheAxisIsFinite) {
  const double a[3] = {0, 0, 0}, dir[3] = {0, 0, 1}, x[3] = {0, 0, 0.4};
  const Cylinder cyl = makeCylinder(a, dir, 1.0);
  double e[3], d;
  const double g = cylinderGap(cyl, x, e, d);
  EXPECT_EQ(g, 1.0);
  EXPECT_NEAR(e[0] * e[0] + e[1] * e[1] + e[2] * e[2], 1.0, 1e-15);
  EXPECT_NEAR(e[2], 0.0, 1e-15);
}

}  // namespace

// faceCut: a flat face whose corners touch the cylinder (axis along z, R = 1, above
// the face y = 0) is cut by the sagitta R - sqrt(R^2 - (h/2)^2) at its middle; a capstan
// sunk through the face (axis on it) by R.
TEST(Contact, FaceCutIsTheSagittaOrTheSunkDepth) {
  const double h = 0.6;
  const double a[3] = {0, std::sqrt(1 - h * h / 4), 0}, dir[3] = {0, 0, 1};  // the corners on the surface
  const Cylinder c = makeCylinder(a, dir, 1.0);
  double x[4][3] = {{-h / 2, 0, 0}, {h / 2, 0, 0}, {h / 2, 0, 0.2}, {-h / 2, 0, 0.2}};
  double at[3], edge;
  const double sagitta = 1 - std::sqrt(1 - h * h / 4);
  EXPECT_NEAR(faceCut(x, c, at, edge), sagitta, 1e-14);
  EXPECT_NEAR(at[0], 0, 1e-14);
  EXPECT_NEAR(edge, h, 1e-14);
  for (auto& p : x) p[1] += a[1];  // the face through the axis
  EXPECT_NEAR(faceCut(x, c, at, edge), 1.0, 1e-14);
  for (auto& p : x) p[1] -= 3;  // well clear: a negative cut, the face's distance from the surface
  EXPECT_NEAR(faceCut(x, c, at, edge), -2.0, 1e-14);
}
