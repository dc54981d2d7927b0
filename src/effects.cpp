#include "effects.hpp"

#include <Kokkos_Timer.hpp>

#include <Teuchos_CommHelpers.hpp>

#include <cmath>

#include "../kernels/body_force.hpp"
#include "../kernels/brick.hpp"
#include "../kernels/contact.hpp"
#include "../kernels/foundation.hpp"
#include "mesh.hpp"

namespace capstan {

void Effect::evaluate(const NodalVectors& x, const NodalVectors& u, const TangentSink* sink) {
  Kokkos::Timer timer;
  launch(x, u, sink != nullptr, sink ? *sink : TangentSink{});
  Kokkos::fence();
  seconds_ += timer.seconds();
  ++launches_;
}

namespace {

// One brick's reference (X) and current (x) node positions, from the effect's
// per-brick reference coordinates and the overlapped nodes' positions.
template <class Nodes, class Reference>
KOKKOS_INLINE_FUNCTION void gatherBrick(int e, const Nodes& nodes, const Reference& X, const NodalVectors& x,
                                        double Xe[8][3], double xe[8][3]) {
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) {
      Xe[a][i] = X(e, a, i);
      xe[a][i] = x(nodes(e, a), i);
    }
}

// Dof ids of entities given by their node ids.
template <class NodeView>
IntMatrix dofsOf(const NodeView& nodes) {
  const int nn = int(nodes.extent(1));
  IntMatrix dofs("dofs", nodes.extent(0), 3 * nn);
  Kokkos::parallel_for(
      "dofs", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)), KOKKOS_LAMBDA(int e) {
        for (int a = 0; a < nn; ++a)
          for (int i = 0; i < 3; ++i) dofs(e, 3 * a + i) = 3 * nodes(e, a) + i;
      });
  return dofs;
}

// Node ids and reference coordinates of entities (bricks: 8 nodes, faces: 4)
// from a flat node list, into device views.
template <class NodeView, class CoordView>
void loadEntities(const Mesh& mesh, const std::vector<int>& nodeList, const std::string& label,
                  NodeView& nodes, CoordView& X) {
  const size_t nn = NodeView::static_extent(1), count = nodeList.size() / nn;
  nodes = NodeView(label + " nodes", count);
  X = CoordView(label + " X", count);
  auto hn = Kokkos::create_mirror_view(nodes);
  auto hX = Kokkos::create_mirror_view(X);
  for (size_t e = 0; e < count; ++e)
    for (size_t a = 0; a < nn; ++a) {
      const int n = nodeList[nn * e + a];
      hn(e, a) = n;
      for (int i = 0; i < 3; ++i) hX(e, a, i) = mesh.X[3 * n + i];
    }
  Kokkos::deep_copy(nodes, hn);
  Kokkos::deep_copy(X, hX);
}

}  // namespace

// ---------------------------------------------------------------- bricks

BrickEffect::BrickEffect(const Mesh& mesh, double c, double penalty, double volumeTolerance)
    : Effect("brick"), c_(c), penalty_(penalty), volumeTolerance_(volumeTolerance) {
  const size_t ne = mesh.numElements();
  loadEntities(mesh, mesh.connectivity, "brick", nodes_, X_);
  pressureAnchor = Kokkos::View<double*>("pbar", ne);
  pressure = Kokkos::View<double*>("p", ne);
  volume = Kokkos::View<double*>("v", ne);
  referenceVolume = Kokkos::View<double*>("V", ne);
  minJacobian = Kokkos::View<double*>("minJ", ne);
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("brick R", ne, 24);
  local_.stiff = true;
  auto X = X_;
  auto V = referenceVolume;
  Kokkos::parallel_for(
      "brick reference volume", Kokkos::RangePolicy<ExecSpace>(0, ne), KOKKOS_LAMBDA(int e) {
        double Xe[8][3];
        for (int a = 0; a < 8; ++a)
          for (int i = 0; i < 3; ++i) Xe[a][i] = X(e, a, i);
        double minJ;
        V(e) = kernels::brickVolume(Xe, Xe, minJ);
      });
}

void BrickEffect::launch(const NodalVectors& x, const NodalVectors&, bool tangent, const TangentSink& sink) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
  auto V = referenceVolume, pbar = pressureAnchor, p = pressure, v = volume, minJ = minJacobian;
  const double c = c_, eps = penalty_;
  Kokkos::parallel_for(
      "brick residual+tangent", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)),
      KOKKOS_LAMBDA(int e) {
        double Xe[8][3], xe[8][3];
        gatherBrick(e, nodes, X, x, Xe, xe);
        kernels::BrickState st;
        double K[24 * 24];
        kernels::brickResidualTangent(Xe, xe, V(e), pbar(e), c, eps, &R(e, 0), tangent ? K : nullptr, st);
        if (tangent) sink.take<24>(e, K);
        p(e) = st.pressure;
        v(e) = st.volume;
        minJ(e) = st.minJ;
      });
}

void BrickEffect::volumeGradients(const NodalVectors& x, Matrix& g) const {
  auto nodes = nodes_;
  auto X = X_;
  if (g.extent(0) != nodes.extent(0)) g = Matrix("brick dv/dx", nodes.extent(0), 24);
  auto out = g;
  Kokkos::parallel_for(
      "brick volume gradient", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)), KOKKOS_LAMBDA(int e) {
        double Xe[8][3], xe[8][3];
        gatherBrick(e, nodes, X, x, Xe, xe);
        kernels::brickVolumeGradient(Xe, xe, &out(e, 0));
      });
}

void BrickEffect::constraintRows(const NodalVectors& x, ConstraintRows& rows) const {
  volumeGradients(x, rows.gradient);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), volume);
  auto V = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), referenceVolume);
  rows.clear();
  for (size_t e = 0; e < V.extent(0); ++e) {
    rows.entity.push_back(int(e)), rows.multiplier.push_back(int(e));
    rows.force.push_back(-1.0), rows.diagonal.push_back(0.0), rows.value.push_back(v(e) - V(e));
    rows.schur.push_back(penalty_ * V(e)), rows.scale.push_back(V(e));
  }
}

void BrickEffect::multiplierMap(const Kokkos::View<double*>& next) const {
  Kokkos::deep_copy(next, pressure);
}

double BrickEffect::constraintViolation() const {
  double change = 0;
  auto v = volume, V = referenceVolume;
  Kokkos::parallel_reduce(
      "volume change", Kokkos::RangePolicy<ExecSpace>(0, v.extent(0)),
      KOKKOS_LAMBDA(int e, double& m) {
        const double d = kernels::fabs(v(e) / V(e) - 1);
        m = d > m ? d : m;
      },
      Kokkos::Max<double>(change));
  return change;
}

void BrickEffect::centroidStress(const NodalVectors& x, Matrix& stress,
                                 Kokkos::View<double*>& mises) const {
  auto nodes = nodes_;
  auto X = X_;
  auto p = pressure;
  const double c = c_;
  stress = Matrix("stress", nodes.extent(0), 6);
  mises = Kokkos::View<double*>("von Mises", nodes.extent(0));
  auto s = stress;
  auto m = mises;
  Kokkos::parallel_for(
      "brick centroid stress", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)),
      KOKKOS_LAMBDA(int e) {
        double Xe[8][3], xe[8][3], sig[6];
        gatherBrick(e, nodes, X, x, Xe, xe);
        kernels::brickCentroidStress(Xe, xe, p(e), c, sig);
        for (int k = 0; k < 6; ++k) s(e, k) = sig[k];
        m(e) = kernels::vonMises(sig);
      });
}

// ---------------------------------------------------------------- foundation

FoundationEffect::FoundationEffect(const std::string& name, const Mesh& mesh,
                                   const std::string& face, double k,
                                   std::array<bool, 3> components)
    : Effect(name), k_(k) {
  const auto& quads = mesh.faces.at(face);
  const size_t nf = quads.size() / 4;
  loadEntities(mesh, quads, "foundation", nodes_, X_);
  for (int i = 0; i < 3; ++i) mask_[i] = components[i] ? 1 : 0;
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("foundation R", nf, 12);
  local_.stiff = true;
}

void FoundationEffect::launch(const NodalVectors&, const NodalVectors& u, bool tangent, const TangentSink& sink) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
  const double k = k_;
  const int m0 = mask_[0], m1 = mask_[1], m2 = mask_[2];
  Kokkos::parallel_for(
      "foundation", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)), KOKKOS_LAMBDA(int f) {
        double Xf[4][3], uf[4][3];
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) {
            Xf[a][i] = X(f, a, i);
            uf[a][i] = u(nodes(f, a), i);
          }
        const int mask[3] = {m0, m1, m2};
        double K[12 * 12];
        kernels::foundationResidualTangent(Xf, uf, k, mask, &R(f, 0), tangent ? K : nullptr);
        if (tangent) sink.take<12>(f, K);
      });
}

std::array<double, 3> FoundationEffect::localForceOnBody() const {
  auto R = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), local_.R);
  std::array<double, 3> F{0, 0, 0};
  for (size_t f = 0; f < R.extent(0); ++f)
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) F[i] -= R(f, 3 * a + i);  // R = internal - external
  return F;
}

// ---------------------------------------------------------------- body force

BodyForceEffect::BodyForceEffect(const Mesh& mesh, std::array<double, 3> b, double endTime)
    : Effect("body force"), endTime_(endTime) {
  Kokkos::View<int* [8], Kokkos::LayoutRight> nodes;
  Kokkos::View<double* [8][3], Kokkos::LayoutRight> X;
  loadEntities(mesh, mesh.connectivity, "body force", nodes, X);
  local_.dofs = dofsOf(nodes);
  local_.R = Matrix("body force R", nodes.extent(0), 24);
  fullLoad_ = Matrix("body force load", nodes.extent(0), 24);
  auto load = fullLoad_;
  const double b0 = b[0], b1 = b[1], b2 = b[2];
  Kokkos::parallel_for(
      "body force", Kokkos::RangePolicy<ExecSpace>(0, X.extent(0)), KOKKOS_LAMBDA(int e) {
        double Xe[8][3];
        for (int a = 0; a < 8; ++a)
          for (int i = 0; i < 3; ++i) Xe[a][i] = X(e, a, i);
        const double bb[3] = {b0, b1, b2};
        kernels::brickBodyForce(Xe, bb, &load(e, 0));
      });
}

// A dead load ramped with time: the loads integrated once, scaled.
void BodyForceEffect::launch(const NodalVectors&, const NodalVectors&, bool, const TangentSink&) {
  auto R = local_.R;
  auto load = fullLoad_;
  const double scale = scale_;
  Kokkos::parallel_for(
      "body force scale", Kokkos::RangePolicy<ExecSpace>(0, R.extent(0)), KOKKOS_LAMBDA(int e) {
        for (int k = 0; k < 24; ++k) R(e, k) = scale * load(e, k);
      });
}

// ---------------------------------------------------------------- contact

namespace {
enum PointField { kGap = 0, kPressure, kWeight, kArea, kE, kX = kE + 3 };
}

ContactEffect::ContactEffect(const std::string& name, const Mesh& mesh,
                             const std::vector<int>& quads, const Settings& settings)
    : Effect(name), settings_(settings) {
  const size_t nf = quads.size() / 4;
  loadEntities(mesh, quads, "contact", nodes_, X_);
  const double nb = std::sqrt(settings.axisDirection[0] * settings.axisDirection[0] +
                              settings.axisDirection[1] * settings.axisDirection[1] +
                              settings.axisDirection[2] * settings.axisDirection[2]);
  for (int i = 0; i < 3; ++i) beta_[i] = settings.axisDirection[i] / nb;
  lambda_ = Kokkos::View<double*>("contact lambda", nf * kernels::kMaxFacePoints);
  points_ = decltype(points_)("contact points", nf, kernels::kMaxFacePoints);
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("contact R", nf, 12);
  local_.stiff = true;
  local_.active = Kokkos::View<int*>("contact active", nf);
  // The smallest candidate face edge over all ranks sets the defaults.
  double h = 1e300;
  for (size_t f = 0; f < nf; ++f)
    for (int a = 0; a < 4; ++a) {
      const int n0 = quads[4 * f + a], n1 = quads[4 * f + (a + 1) % 4];
      double l2 = 0;
      for (int i = 0; i < 3; ++i) l2 += std::pow(mesh.X[3 * n1 + i] - mesh.X[3 * n0 + i], 2);
      h = std::min(h, std::sqrt(l2));
    }
  double hMin = h;
  Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_MIN, h, Teuchos::outArg(hMin));
  if (settings_.tolerance <= 0) settings_.tolerance = 1e-4 * hMin;
  // Automatic floor for the nodal rule only: with Gauss points the penalty
  // answer approaches an over-constrained one as eps2 -> 0 (flat faces cannot
  // touch a curved capstan at every Gauss point), and the multiplier loop
  // crawls (measured on G1: eps2 = 1e-4 needed 100+ passes per step).
  const bool nodal = kernels::FaceRule(settings_.rule) == kernels::FaceRule::Nodal;
  const double floor = settings_.minimumSolvePenalty >= 0 ? settings_.minimumSolvePenalty
                       : nodal                            ? 1e-2 * hMin / settings_.c
                                                          : 0.0;
  solvePenalty_ = std::max(settings_.penalty, floor);
  compliance_ = settings_.exact ? 0.0 : settings_.penalty;
}

void ContactEffect::setInterval(double, double tEnd) { time_ = tEnd; }

kernels::Cylinder ContactEffect::cylinder() const {
  kernels::Cylinder cyl;
  for (int i = 0; i < 3; ++i) {
    cyl.a[i] = settings_.axisPoint[i] + settings_.velocity[i] * time_;
    cyl.b[i] = beta_[i];
  }
  cyl.R = settings_.radius;
  cyl.smoothing = settings_.smoothing;
  return cyl;
}

void ContactEffect::launch(const NodalVectors& x, const NodalVectors&, bool tangent, const TangentSink& sink) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
  auto active = local_.active;
  auto lambda = lambda_;
  auto pts = points_;
  const kernels::Cylinder cyl = cylinder();
  const double eps = solvePenalty_, kappa = compliance_;
  const auto rule = kernels::FaceRule(settings_.rule);
  const bool geometric = !predicting_;
  Kokkos::parallel_for(
      "contact residual+tangent", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)),
      KOKKOS_LAMBDA(int f) {
        double Xf[4][3], xf[4][3];
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) {
            Xf[a][i] = X(f, a, i);
            xf[a][i] = x(nodes(f, a), i);
          }
        kernels::ContactPoint p[kernels::kMaxFacePoints];
        double K[12 * 12];
        active(f) = kernels::contactFaceResidualTangent(
            Xf, xf, cyl, eps, kappa, &lambda(f * kernels::kMaxFacePoints), rule, &R(f, 0),
            tangent ? K : nullptr, p, geometric);
        if (tangent && active(f)) sink.take<12>(f, K);
        for (int q = 0; q < kernels::facePointCount(rule); ++q) {
          pts(f, q, kGap) = p[q].gap;
          pts(f, q, kPressure) = p[q].pressure;
          pts(f, q, kWeight) = p[q].weight;
          pts(f, q, kArea) = p[q].area;
          for (int i = 0; i < 3; ++i) {
            pts(f, q, kE + i) = p[q].e[i];
            pts(f, q, kX + i) = p[q].x[i];
          }
        }
      });
}

// Uzawa: lambda <- t_n (= max(0, lambda + (g - kappa lambda) / eps)).
void ContactEffect::multiplierMap(const Kokkos::View<double*>& next) const {
  if (!augmented()) return;
  auto pts = points_;
  const int nq = kernels::facePointCount(kernels::FaceRule(settings_.rule));
  Kokkos::deep_copy(next, 0.0);
  Kokkos::parallel_for(
      "contact multiplier map", Kokkos::RangePolicy<ExecSpace>(0, pts.extent(0)),
      KOKKOS_LAMBDA(int f) {
        for (int q = 0; q < nq; ++q) next(f * kernels::kMaxFacePoints + q) = pts(f, q, kPressure);
      });
}

void ContactEffect::projectMultipliers() {
  if (!augmented()) return;
  auto lambda = lambda_;
  Kokkos::parallel_for(
      "contact multiplier projection", Kokkos::RangePolicy<ExecSpace>(0, lambda.extent(0)),
      KOKKOS_LAMBDA(int i) { lambda(i) = lambda(i) > 0 ? lambda(i) : 0.0; });
}

void ContactEffect::constraintRows(const NodalVectors&, ConstraintRows& rows) const {
  rows.clear();
  if (!augmented() || settings_.smoothing > 0) {
    rows.gradient = Matrix();
    return;
  }
  // On the host: a few thousand candidate faces at most, most not in contact.
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  auto lambda = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), lambda_);
  const auto rule = kernels::FaceRule(settings_.rule);
  const int nq = kernels::facePointCount(rule);
  const double eps = solvePenalty_, kappa = compliance_;
  std::vector<double> grad;
  for (size_t f = 0; f < pts.extent(0); ++f)
    for (int q = 0; q < nq; ++q) {
      if (!(pts(f, q, kPressure) > 0)) continue;
      const int m = int(f) * kernels::kMaxFacePoints + q;
      double xi, eta, w, N[4], dN[4][2];
      kernels::facePoint(rule, q, xi, eta, w);
      kernels::quadShape(xi, eta, N, dN);
      for (int a = 0; a < 4; ++a)
        for (int i = 0; i < 3; ++i) grad.push_back(-N[a] * pts(f, q, kE + i));  // d g / d x_a
      rows.entity.push_back(int(f)), rows.multiplier.push_back(m);
      rows.force.push_back(pts(f, q, kWeight) * (1 - kappa / eps)), rows.diagonal.push_back(-kappa);
      rows.value.push_back(pts(f, q, kGap) - kappa * lambda(m));
      rows.schur.push_back(-eps), rows.scale.push_back(0.0);
    }
  rows.gradient = Matrix("contact dg/dx", rows.size(), 12);
  auto h = Kokkos::create_mirror_view(rows.gradient);
  for (size_t k = 0; k < grad.size(); ++k) h.data()[k] = grad[k];
  Kokkos::deep_copy(rows.gradient, h);
}

// eps |t_n - lambda|: the penetration |g| at points in contact (exact contact),
// the distance a released point is still held at otherwise.
double ContactEffect::constraintViolation() const {
  if (!augmented()) return 0;
  auto pts = points_;
  auto lambda = lambda_;
  const int nq = kernels::facePointCount(kernels::FaceRule(settings_.rule));
  const double eps = solvePenalty_;
  double v = 0;
  Kokkos::parallel_reduce(
      "contact violation", Kokkos::RangePolicy<ExecSpace>(0, pts.extent(0)),
      KOKKOS_LAMBDA(int f, double& m) {
        for (int q = 0; q < nq; ++q) {
          const double d = eps * kernels::fabs(pts(f, q, kPressure) - lambda(f * kernels::kMaxFacePoints + q));
          m = d > m ? d : m;
        }
      },
      Kokkos::Max<double>(v));
  return v;
}

ContactEffect::Figures ContactEffect::figures(const std::array<double, 3>& ref) const {
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  const int nq = kernels::facePointCount(kernels::FaceRule(settings_.rule));
  const auto& b = beta_;
  // tau_ref = b x ref completes the frame for the angle about the axis.
  const std::array<double, 3> side{b[1] * ref[2] - b[2] * ref[1], b[2] * ref[0] - b[0] * ref[2],
                                   b[0] * ref[1] - b[1] * ref[0]};
  Figures fig;
  fig.angleMin = 1e300, fig.angleMax = -1e300;
  for (size_t f = 0; f < pts.extent(0); ++f)
    for (int q = 0; q < nq; ++q) {
      const double g = pts(f, q, kGap), tn = pts(f, q, kPressure);
      fig.maxPenetration = std::max(fig.maxPenetration, g);
      if (!(tn > 0)) continue;
      const double* e = &pts(f, q, kE);
      // Force on the capstan at this point: -t w dA; its moment arm R e.
      double F[3];
      for (int i = 0; i < 3; ++i) F[i] = -tn * e[i] * pts(f, q, kWeight);
      for (int i = 0; i < 3; ++i) fig.force[i] += F[i];
      const double tau[3] = {b[1] * e[2] - b[2] * e[1], b[2] * e[0] - b[0] * e[2],
                             b[0] * e[1] - b[1] * e[0]};
      fig.torque += settings_.radius * (F[0] * tau[0] + F[1] * tau[1] + F[2] * tau[2]);
      // With a smoothed contact law, points just outside the nip keep a tiny
      // pressure: they count as in contact (area, width) only where the exact
      // law would press (tn > smoothing / 2).
      if (!(tn > 0.5 * settings_.smoothing)) continue;
      ++fig.points;
      fig.peakPressure = std::max(fig.peakPressure, tn);
      fig.area += pts(f, q, kArea);
      const double c = e[0] * ref[0] + e[1] * ref[1] + e[2] * ref[2];
      const double s = e[0] * side[0] + e[1] * side[1] + e[2] * side[2];
      const double angle = std::atan2(s, c);
      fig.angleMin = std::min(fig.angleMin, angle);
      fig.angleMax = std::max(fig.angleMax, angle);
    }
  return fig;
}

void ContactEffect::faceFields(std::vector<double>& pressure, std::vector<double>& gap,
                               std::vector<double>& traction) const {
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  const int nq = kernels::facePointCount(kernels::FaceRule(settings_.rule));
  const size_t nf = pts.extent(0);
  pressure.assign(nf, 0.0);
  gap.assign(nf, -1e300);
  traction.assign(3 * nf, 0.0);
  for (size_t f = 0; f < nf; ++f) {
    double area = 0;
    for (int q = 0; q < nq; ++q) {
      const double w = pts(f, q, kWeight), tn = pts(f, q, kPressure);
      area += w;
      pressure[f] += w * tn;
      for (int i = 0; i < 3; ++i) traction[3 * f + i] += w * tn * pts(f, q, kE + i);
      gap[f] = std::max(gap[f], pts(f, q, kGap));
    }
    pressure[f] /= area;
    for (int i = 0; i < 3; ++i) traction[3 * f + i] /= area;
  }
}

// ---------------------------------------------------------------- friction

namespace {
constexpr int kHistoryPerFace = 12 + 3 * kernels::kMaxFacePoints;
enum FrictionField { kTraction = 0, kNormal = 3, kSlip, kState, kFWeight, kFE };
}  // namespace

FrictionEffect::FrictionEffect(const std::string& name, const Mesh& mesh,
                               const std::vector<int>& quads, const ContactEffect& contact,
                               const Settings& settings)
    : Effect(name), contact_(contact), settings_(settings) {
  const size_t nf = quads.size() / 4;
  loadEntities(mesh, quads, "friction", nodes_, X_);
  history_ = Kokkos::View<double*>("friction history", nf * kHistoryPerFace);
  tangentialMultipliers_ = Kokkos::View<double*>("friction lambda_T", nf * kernels::kMaxFacePoints * 3);
  points_ = decltype(points_)("friction points", nf, kernels::kMaxFacePoints);
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("friction R", nf, 12);
  local_.stiff = true;
  local_.active = Kokkos::View<int*>("friction active", nf);
  // The body starts at its reference positions, with no friction traction.
  auto X = X_;
  auto h = history_;
  Kokkos::parallel_for(
      "friction history start", Kokkos::RangePolicy<ExecSpace>(0, nf), KOKKOS_LAMBDA(int f) {
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) h(f * kHistoryPerFace + 3 * a + i) = X(f, a, i);
      });
  parameters_.law = settings.law;
  parameters_.mu = settings.mu;
  parameters_.smoothing = settings.smoothing;
  parameters_.tangentPenalty =
      settings.tangentPenalty > 0 ? settings.tangentPenalty : contact.solvePenalty();
}

void FrictionEffect::setInterval(double tStart, double tEnd) {
  const double dt = tEnd - tStart;
  for (int i = 0; i < 3; ++i) parameters_.ds[i] = contact_.settings().velocity[i] * dt;
  parameters_.spin = settings_.angularVelocity * dt * contact_.radius();
  // The slip-length scale eps3 dt; a zero-length interval (a re-evaluation of a
  // converged state) has no slip, any positive scale gives t_f = 0 there.
  parameters_.v = settings_.regularization * (dt > 0 ? dt : 1.0);
}

void FrictionEffect::launch(const NodalVectors& x, const NodalVectors&, bool tangent, const TangentSink& sink) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
  auto active = local_.active;
  auto lambda = contact_.normalMultipliers();
  auto h = history_;
  auto lambdaT = tangentialMultipliers_;
  const bool useMultipliers = augmented();
  auto pts = points_;
  const kernels::Cylinder cyl = contact_.cylinder();
  const double eps = contact_.solvePenalty(), kappa = contact_.compliance();
  const auto rule = kernels::FaceRule(contact_.rule());
  const kernels::FrictionParameters fp = parameters_;
  Kokkos::parallel_for(
      "friction residual+tangent", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)),
      KOKKOS_LAMBDA(int f) {
        double Xf[4][3], xf[4][3], xn[4][3];
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) {
            Xf[a][i] = X(f, a, i);
            xf[a][i] = x(nodes(f, a), i);
            xn[a][i] = h(f * kHistoryPerFace + 3 * a + i);
          }
        kernels::FrictionPoint p[kernels::kMaxFacePoints];
        double K[12 * 12];
        active(f) = kernels::frictionFaceResidualTangent(
            Xf, xf, xn, cyl, eps, kappa, &lambda(f * kernels::kMaxFacePoints), rule, fp,
            useMultipliers ? &lambdaT(f * kernels::kMaxFacePoints * 3) : &h(f * kHistoryPerFace + 12),
            &R(f, 0), tangent ? K : nullptr, p);
        if (tangent && active(f)) sink.take<12>(f, K);
        for (int q = 0; q < kernels::facePointCount(rule); ++q) {
          for (int i = 0; i < 3; ++i) pts(f, q, kTraction + i) = p[q].traction[i];
          pts(f, q, kNormal) = p[q].normal;
          pts(f, q, kSlip) = p[q].slip;
          pts(f, q, kState) = p[q].state;
          pts(f, q, kFWeight) = p[q].weight;
          for (int i = 0; i < 3; ++i) pts(f, q, kFE + i) = p[q].e[i];
        }
      });
}

void FrictionEffect::commit(const NodalVectors& x) {
  auto nodes = nodes_;
  auto h = history_;
  auto lambdaT = tangentialMultipliers_;
  auto pts = points_;
  const int nq = kernels::facePointCount(kernels::FaceRule(contact_.rule()));
  Kokkos::parallel_for(
      "friction commit", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)), KOKKOS_LAMBDA(int f) {
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) h(f * kHistoryPerFace + 3 * a + i) = x(nodes(f, a), i);
        for (int q = 0; q < nq; ++q)
          for (int i = 0; i < 3; ++i) {
            h(f * kHistoryPerFace + 12 + 3 * q + i) = pts(f, q, kTraction + i);
            lambdaT((f * kernels::kMaxFacePoints + q) * 3 + i) = pts(f, q, kTraction + i);
          }
      });
}

void FrictionEffect::multiplierMap(const Kokkos::View<double*>& next) const {
  if (!augmented()) return;
  auto pts = points_;
  const int nq = kernels::facePointCount(kernels::FaceRule(contact_.rule()));
  Kokkos::deep_copy(next, 0.0);
  Kokkos::parallel_for(
      "friction multiplier map", Kokkos::RangePolicy<ExecSpace>(0, pts.extent(0)), KOKKOS_LAMBDA(int f) {
        for (int q = 0; q < nq; ++q)
          for (int i = 0; i < 3; ++i) next((f * kernels::kMaxFacePoints + q) * 3 + i) = pts(f, q, kTraction + i);
      });
}

double FrictionEffect::constraintViolation() const {
  if (!augmented()) return 0;
  auto pts = points_;
  auto lambdaT = tangentialMultipliers_;
  const int nq = kernels::facePointCount(kernels::FaceRule(contact_.rule()));
  const double epsT = parameters_.tangentPenalty;
  double v = 0;
  Kokkos::parallel_reduce(
      "friction violation", Kokkos::RangePolicy<ExecSpace>(0, pts.extent(0)),
      KOKKOS_LAMBDA(int f, double& m) {
        for (int q = 0; q < nq; ++q) {
          double d2 = 0;
          for (int i = 0; i < 3; ++i) {
            const double d = pts(f, q, kTraction + i) - lambdaT((f * kernels::kMaxFacePoints + q) * 3 + i);
            d2 += d * d;
          }
          const double d = epsT * kernels::sqrt(d2);
          m = d > m ? d : m;
        }
      },
      Kokkos::Max<double>(v));
  return v;
}

FrictionEffect::Figures FrictionEffect::figures() const {
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  const int nq = kernels::facePointCount(kernels::FaceRule(contact_.rule()));
  const auto b = contact_.axisDirection();
  Figures fig;
  for (size_t f = 0; f < pts.extent(0); ++f)
    for (int q = 0; q < nq; ++q) {
      const int state = int(pts(f, q, kState));
      if (state == 0) continue;
      const double w = pts(f, q, kFWeight), tn = pts(f, q, kNormal);
      // With a smoothed contact law, points just outside the nip keep a tiny
      // pressure: counted as in contact only where the exact law would be.
      if (tn > 0.5 * contact_.settings().smoothing) (state == 1 ? fig.stick : fig.slip) += 1;
      const double* t = &pts(f, q, kTraction);
      const double mag = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
      fig.frictionIntegral += w * mag;
      fig.normalIntegral += w * tn;
      if (settings_.mu > 0) fig.maxRatio = std::max(fig.maxRatio, mag / (settings_.mu * tn));
      // Force on the capstan -w t at radius R e: axial moment R (e x F) . b = R F . (b x e).
      const double* e = &pts(f, q, kFE);
      const double tau[3] = {b[1] * e[2] - b[2] * e[1], b[2] * e[0] - b[0] * e[2],
                             b[0] * e[1] - b[1] * e[0]};
      for (int i = 0; i < 3; ++i) {
        fig.force[i] -= w * t[i];
        fig.torque -= contact_.radius() * w * t[i] * tau[i];
      }
    }
  return fig;
}

void FrictionEffect::faceFields(std::vector<double>& traction, std::vector<double>& stick,
                                std::vector<double>& slip) const {
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  const int nq = kernels::facePointCount(kernels::FaceRule(contact_.rule()));
  const size_t nf = pts.extent(0);
  traction.assign(3 * nf, 0.0);
  stick.assign(nf, 0.0);
  slip.assign(nf, 0.0);
  for (size_t f = 0; f < nf; ++f) {
    double area = 0;
    for (int q = 0; q < nq; ++q) {
      const double w = pts(f, q, kFWeight);
      area += w;
      for (int i = 0; i < 3; ++i) traction[3 * f + i] += w * pts(f, q, kTraction + i);
      const int state = int(pts(f, q, kState));
      if (state == 1) stick[f] += 1;
      if (state == 2) slip[f] += 1;
    }
    if (area > 0)
      for (int i = 0; i < 3; ++i) traction[3 * f + i] /= area;
  }
}

}  // namespace capstan
