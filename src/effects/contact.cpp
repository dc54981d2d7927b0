#include "contact.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <algorithm>
#include <cmath>

#include "../../kernels/contact.hpp"
#include "../mesh.hpp"
#include "entities.hpp"
#include "../log.hpp"
#include "../step_record.hpp"
#include "../vec3.hpp"

namespace capstan {

using detail::dofsOf;
using detail::loadEntities;

static_assert(int(ContactSettings::Quadrature::Gauss2x2) == int(kernels::FaceRule::Gauss2) &&
                  int(ContactSettings::Quadrature::Gauss3x3) == int(kernels::FaceRule::Gauss3) &&
                  int(ContactSettings::Quadrature::Nodal) == int(kernels::FaceRule::Nodal),
              "ContactSettings::Quadrature names kernels::FaceRule's values");

ContactEffect::ContactEffect(const std::string& name, const Mesh& mesh, const std::vector<int>& quads,
                             const CapstanSpec& capstan, double c, bool exactStick)
    : Effect(name), capstan_(capstan) {
  const ContactSettings& settings = capstan.contact;
  const size_t nf = quads.size() / 4;
  loadEntities(mesh, quads, "contact", nodes_, X_);
  beta_ = unit(capstan.axisDirection);
  lambda_ = Kokkos::View<double*>("contact lambda", nf * kernels::kMaxFacePoints);
  points_ = decltype(points_)("contact points", nf, kernels::kMaxFacePoints);
  local_.dofs = dofsOf(nodes_);
  local_.R = Matrix("contact R", nf, 12);
  local_.stiff = true;
  local_.active = Kokkos::View<int*>("contact active", nf);
  // The shortest candidate face edge over all ranks sets the defaults. The longest edge of
  // the faces near the capstan at the start (a node within 3R of its axis) is warned of where
  // it exceeds the capstan's diameter: contact holds the points only, and the capstan can sit
  // between them.
  double h = 1e300, hNear = 0;
  for (size_t f = 0; f < nf; ++f) {
    bool near = false;
    double longest = 0;
    for (int a = 0; a < 4; ++a) {
      const int n0 = quads[4 * f + a], n1 = quads[4 * f + (a + 1) % 4];
      Vec3 edge{}, r{};
      for (int i = 0; i < 3; ++i) {
        edge[i] = mesh.X[3 * n1 + i] - mesh.X[3 * n0 + i];
        r[i] = mesh.X[3 * n0 + i] - capstan.axisPoint[i];
      }
      h = std::min(h, norm(edge));
      longest = std::max(longest, norm(edge));
      near = near || norm(sub(r, scale(beta_, dot(r, beta_)))) < 3 * capstan.radius;
    }
    if (near) hNear = std::max(hNear, longest);
  }
  double hMin = h, hNearAll = 0;
  Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_MIN, h, Teuchos::outArg(hMin));
  Teuchos::reduceAll(*mesh.comm, Teuchos::REDUCE_MAX, hNear, Teuchos::outArg(hNearAll));
  shortestEdge_ = hMin;
  if (hNearAll > 2 * capstan.radius)
    coarseFacesWarning_ = format("contact faces near the capstan are up to %.3g long, more than its diameter %.3g: "
                                 "contact holds the faces' points only, and the capstan can sit between them (a "
                                 "finer Mesh/Cells there)",
                                 hNearAll, 2 * capstan.radius);
  tolerance_ = settings.penetrationTolerance > 0 ? settings.penetrationTolerance : 1e-4 * hMin;
  capstan_.contact.quadrature = settings.resolvedQuadrature(hMin, c, exactStick);
  // A Gauss rule the scene names where Auto would take the nodal one.
  using Q = ContactSettings::Quadrature;
  if (settings.quadrature == Q::Gauss2x2 || settings.quadrature == Q::Gauss3x3) {
    const char* gauss = settings.quadrature == Q::Gauss2x2 ? "2x2" : "3x3";
    ContactSettings asAuto = settings;
    asAuto.quadrature = Q::Auto;
    if (asAuto.resolvedQuadrature(hMin, c) == Q::Nodal)  // the stiff penalty
      quadratureWarning_ = format("Gauss %s with Penalty %g, below %g h / c = %g (h = %g, the shortest contact face "
                                  "edge): Gauss points of flat faces lock against the curved capstan and the loops "
                                  "stall (docs/contact.md, \"Stiff penalties\"); Auto gives this penalty Nodal",
                                  gauss, settings.resolvedPenalty(hMin, c), ContactSettings::kGaussPenaltyLimit,
                                  ContactSettings::kGaussPenaltyLimit * hMin / c, hMin);
    else if (exactStick)
      quadratureWarning_ = format("Gauss %s under Coulomb in steady rolling: its exact stick has rows in the "
                                  "saddle-point step only at the nodal rule's points, and without them the "
                                  "multiplier loop crawls (docs/contact.md); Auto gives it Nodal",
                                  gauss);
  }
  const double penalty = settings.resolvedPenalty(hMin, c);
  solvePenalty_ = settings.solvePenalty(hMin, c, rule() == kernels::FaceRule::Nodal);
  compliance_ = settings.exact() ? 0.0 : penalty;
  if (!settings.exact() && penalty > ContactSettings::kSoftestPenalty * hMin / c)
    softPenaltyWarning_ = format("%g lies above %g h / c = %.3g (h = %.3g, the shortest contact face edge; c = %g): "
                                 "the body sinks into the capstan by about eps2 x the contact pressure, %.3g h at a "
                                 "pressure of c (0, the default, scales with h / c in any units)",
                                 penalty, ContactSettings::kSoftestPenalty, ContactSettings::kSoftestPenalty * hMin / c,
                                 hMin, c, penalty * c / hMin);
}

void ContactEffect::setInterval(double, double tEnd) { time_ = tEnd; }

kernels::Cylinder ContactEffect::cylinder() const {
  kernels::Cylinder cyl;
  for (int i = 0; i < 3; ++i) {
    cyl.a[i] = capstan_.axisPoint[i] + capstan_.velocity[i] * time_;
    cyl.b[i] = beta_[i];
  }
  cyl.R = capstan_.radius;
  cyl.smoothing = settings().smoothing;
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
  const auto rule = this->rule();
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

namespace {

// The worst entity's details, from the lowest rank that holds it (collective).
template <size_t N, class Details>
std::array<double, N> fromLowestHolder(const Teuchos::Comm<int>& comm, bool holds, Details details) {
  const int holder = holds ? comm.getRank() : comm.getSize();
  int first = holder;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, holder, Teuchos::outArg(first));
  std::array<double, N> mine{}, all{};
  if (first == comm.getRank()) mine = details();
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, int(N), mine.data(), all.data());
  return all;
}

// The largest value(i) over i < n and where (a Kokkos loop: value is a device function).
template <class Value>
Kokkos::MaxLoc<double, int>::value_type largestOf(const char* label, size_t n, Value value) {
  using MaxLoc = Kokkos::MaxLoc<double, int>;
  typename MaxLoc::value_type best;
  Kokkos::parallel_reduce(
      label, Kokkos::RangePolicy<ExecSpace>(0, n),
      KOKKOS_LAMBDA(int i, typename MaxLoc::value_type& m) {
        const double v = value(i);
        if (v > m.val) m.val = v, m.loc = i;
      },
      MaxLoc(best));
  return best;
}

}  // namespace

ContactEffect::Cut ContactEffect::deepestCut(const NodalVectors& x, const Teuchos::Comm<int>& comm) const {
  auto nodes = nodes_;
  const kernels::Cylinder cyl = cylinder();
  const auto local = largestOf("contact deepest cut", nodes.extent(0), KOKKOS_LAMBDA(int f) {
    double xf[4][3], at[3], edge;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) xf[a][i] = x(nodes(f, a), i);
    const double depth = kernels::faceCut(xf, cyl, at, edge);
    return depth > 0 && edge > 0 ? depth / edge : 0.0;
  });
  const double mine = nodes.extent(0) > 0 && local.val > 0 ? local.val : 0.0;
  double worst = 0;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, mine, Teuchos::outArg(worst));
  Cut cut;
  if (!(worst > 0)) return cut;
  const auto d = fromLowestHolder<5>(comm, mine == worst, [&] {
    auto xh = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
    auto nh = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), nodes);
    double xf[4][3], at[3], edge;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) xf[a][i] = xh(nh(local.loc, a), i);
    const double depth = kernels::faceCut(xf, cyl, at, edge);
    return std::array<double, 5>{depth, edge, at[0], at[1], at[2]};
  });
  cut.depth = d[0], cut.edge = d[1], cut.at = {d[2], d[3], d[4]};
  return cut;
}

ContactEffect::Cut ContactEffect::deepestNode(const NodalVectors& x, const Teuchos::Comm<int>& comm) const {
  const kernels::Cylinder cyl = cylinder();
  const auto local = largestOf("contact deepest node", x.extent(0), KOKKOS_LAMBDA(int n) {
    const double p[3] = {x(n, 0), x(n, 1), x(n, 2)};
    double e[3], d;
    return kernels::cylinderGap(cyl, p, e, d);
  });
  const double mine = x.extent(0) > 0 ? local.val : -1e300;
  Cut cut;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, mine, Teuchos::outArg(cut.depth));
  cut.at = fromLowestHolder<3>(comm, x.extent(0) > 0 && mine == cut.depth, [&] {
    auto xh = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
    return std::array<double, 3>{xh(local.loc, 0), xh(local.loc, 1), xh(local.loc, 2)};
  });
  return cut;
}

// Uzawa: lambda <- t_n (= max(0, lambda + (g - kappa lambda) / eps)).
void ContactEffect::multiplierMap(const Kokkos::View<double*>& next) const {
  if (!augmented()) return;
  auto pts = points_;
  const int nq = kernels::facePointCount(rule());
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

int ContactEffect::multiplierSites(std::vector<int>& nodes) const {
  if (!augmented() || rule() != kernels::FaceRule::Nodal) return 0;
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), nodes_);
  nodes.assign(h.extent(0) * kernels::kMaxFacePoints, -1);
  const int nq = kernels::facePointCount(rule());
  for (size_t f = 0; f < h.extent(0); ++f)
    for (int q = 0; q < nq; ++q) nodes[f * kernels::kMaxFacePoints + q] = h(f, q);  // the nodal rule's point q: corner q
  return 1;
}

void ContactEffect::constraintRows(const NodalVectors&, ConstraintRows& rows) const {
  rows.clear();
  if (!augmented() || settings().smoothing > 0) {
    rows.gradient = Matrix();
    return;
  }
  // On the host: a few thousand candidate faces at most, most not in contact.
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  auto lambda = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), lambda_);
  const auto rule = this->rule();
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
  const int nq = kernels::facePointCount(rule());
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
  const int nq = kernels::facePointCount(rule());
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
      fig.torque += capstan_.radius * (F[0] * tau[0] + F[1] * tau[1] + F[2] * tau[2]);
      // With a smoothed contact law, points just outside the nip keep a tiny
      // pressure: they count as in contact (area, width) only where the exact
      // law would press (tn > smoothing / 2).
      if (!(tn > 0.5 * settings().smoothing)) continue;
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
  const int nq = kernels::facePointCount(rule());
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

void ContactEffect::report(const Teuchos::Comm<int>& comm, StepRecord& rec) const {
  CapstanRecord r;
  r.name = capstan_.name;
  // Pass 1: sums and maxima. Pass 2: contact angles about the axis, measured
  // from the direction of the contact's resultant (so the contact arc never
  // straddles the +-pi cut), for the contact width.
  auto fig = figures({0, 0, 0});
  double sums[5] = {fig.force[0], fig.force[1], fig.force[2], fig.torque, fig.area}, gs[5];
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, 5, sums, gs);
  double maxima[2] = {fig.maxPenetration, fig.peakPressure}, gm[2];
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, 2, maxima, gm);
  long points = 0;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, fig.points, Teuchos::outArg(points));
  r.force = {gs[0], gs[1], gs[2]};
  r.torque = gs[3];
  r.area = gs[4];
  r.maxPenetration = gm[0];
  r.peakPressure = gm[1];
  r.points = points;
  // The body pushes the capstan away from itself: the contact lies along -force.
  const auto& b = beta_;
  Vec3 ref{-gs[0], -gs[1], -gs[2]};
  const double along = dot(ref, b);
  for (int i = 0; i < 3; ++i) ref[i] -= along * b[i];
  const double n = norm(ref);
  if (points > 0 && n > 0) {
    for (double& x : ref) x /= n;
    const auto angles = figures(ref);
    double lo[2] = {angles.angleMin, -angles.angleMax}, glo[2];
    Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, 2, lo, glo);
    r.width = radius() * (-glo[1] - glo[0]);
  }
  rec.capstans.push_back(r);
}

}  // namespace capstan
