#include "friction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "../../kernels/friction.hpp"
#include "../mesh.hpp"
#include "entities.hpp"
#include "../step_record.hpp"

#include <Teuchos_CommHelpers.hpp>
#include <stdexcept>

namespace capstan {

using detail::dofsOf;
using detail::loadEntities;

static_assert(int(FrictionSettings::Law::Tanh) == int(kernels::FrictionLaw::Tanh) &&
                  int(FrictionSettings::Law::Arctan) == int(kernels::FrictionLaw::Arctan) &&
                  int(FrictionSettings::Law::Coulomb) == int(kernels::FrictionLaw::Coulomb),
              "FrictionSettings::Law names kernels::FrictionLaw's values");


FrictionEffect::FrictionEffect(const std::string& name, const Mesh& mesh,
                               const std::vector<int>& quads, const ContactEffect& contact,
                               const FrictionSettings& settings)
    : Effect(name), contact_(contact), settings_(settings) {
  const size_t nf = quads.size() / 4;
  loadEntities(mesh, quads, "friction", nodes_, X_);
  history_ = Kokkos::View<double*>("friction history", nf * kHistoryPerFace);
  tangentialMultipliers_ = Kokkos::View<double*>("friction lambda_T", nf * kernels::kMaxFacePoints * 3);
  points_ = decltype(points_)("friction points", nf, kernels::kMaxFacePoints);
  heldBranch_ = Kokkos::View<int*>("friction held branch", nf * kernels::kMaxFacePoints);
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
  {
    auto Xh = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), X_);
    for (size_t f = 0; f < nf; ++f)
      for (int a = 0; a < 4; ++a)
        positionScale_ = std::max(positionScale_, std::sqrt(Xh(f, a, 0) * Xh(f, a, 0) + Xh(f, a, 1) * Xh(f, a, 1) +
                                                            Xh(f, a, 2) * Xh(f, a, 2)));
  }
  parameters_.law = kernels::FrictionLaw(int(settings.law));
  parameters_.mu = settings.coefficient;
  parameters_.smoothing = settings.smoothing;
  parameters_.tangentPenalty =
      settings.tangentialPenalty > 0 ? settings.tangentialPenalty : contact.solvePenalty();
}

void FrictionEffect::setInterval(double tStart, double tEnd) {
  const double dt = tEnd - tStart;
  dt_ = dt;
  for (int i = 0; i < 3; ++i) parameters_.ds[i] = contact_.capstan().velocity[i] * dt;
  parameters_.spin = contact_.capstan().angularVelocity * dt * contact_.radius();
  // The slip-length scale eps3 dt; a zero-length interval (a re-evaluation of a
  // converged state) has no slip, any positive scale gives t_f = 0 there.
  parameters_.v = settings_.regularization * (dt > 0 ? dt : 1.0) * regularisationScale_;
}

void FrictionEffect::setRegularisationScale(double scale) {
  parameters_.v *= scale / regularisationScale_;
  regularisationScale_ = scale;
}

double FrictionEffect::travelOverSlipScale() const {
  if (settings_.law != FrictionSettings::Law::Tanh && settings_.law != FrictionSettings::Law::Arctan) return 0;
  return contact_.capstan().surfaceSpeed() / settings_.regularization;
}

void FrictionEffect::launch(const NodalVectors& x, const NodalVectors&, bool tangent, const TangentSink& sink) {
  auto nodes = nodes_;
  auto X = X_;
  auto R = local_.R;
  auto active = local_.active;
  auto lambda = contact_.normalMultipliers();
  auto h = history_;
  auto lambdaT = tangentialMultipliers_;
  auto held = heldBranch_;
  const bool useMultipliers = augmented();
  auto pts = points_;
  const kernels::Cylinder cyl = contact_.cylinder();
  const double eps = contact_.solvePenalty(), kappa = contact_.compliance();
  const auto rule = contact_.rule();
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
            &R(f, 0), tangent ? K : nullptr, p, nullptr, &held(f * kernels::kMaxFacePoints));
        if (tangent && active(f)) sink.take<12>(f, K);
        for (int q = 0; q < kernels::facePointCount(rule); ++q) {
          for (int i = 0; i < 3; ++i) pts(f, q, kTraction + i) = p[q].traction[i];
          pts(f, q, kNormal) = p[q].normal;
          pts(f, q, kSlip) = p[q].slip;
          pts(f, q, kState) = p[q].state;
          pts(f, q, kFWeight) = p[q].weight;
          for (int i = 0; i < 3; ++i) pts(f, q, kFE + i) = p[q].e[i];
          pts(f, q, kWork) = p[q].work;
        }
      });
}

void FrictionEffect::commit(const NodalVectors& x) {
  auto nodes = nodes_;
  auto h = history_;
  auto lambdaT = tangentialMultipliers_;
  auto pts = points_;
  const int nq = kernels::facePointCount(contact_.rule());
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
  const int nq = kernels::facePointCount(contact_.rule());
  Kokkos::deep_copy(next, 0.0);
  Kokkos::parallel_for(
      "friction multiplier map", Kokkos::RangePolicy<ExecSpace>(0, pts.extent(0)), KOKKOS_LAMBDA(int f) {
        for (int q = 0; q < nq; ++q)
          for (int i = 0; i < 3; ++i) next((f * kernels::kMaxFacePoints + q) * 3 + i) = pts(f, q, kTraction + i);
      });
}

bool FrictionEffect::notePass(bool mayHold, bool lastResort, bool freeze) {
  if (!stepsForItself()) return false;
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  const size_t nf = pts.extent(0);
  const int nq = kernels::facePointCount(contact_.rule());
  cycles_.resize(nf * kernels::kMaxFacePoints);
  std::vector<std::pair<size_t, int>> changed;  // (point, its new hold)
  for (size_t f = 0; f < nf; ++f)
    for (int q = 0; q < nq; ++q) {
      const size_t k = f * kernels::kMaxFacePoints + q;
      auto& c = cycles_[k];
      const int now = int(pts(f, q, kState));
      // A, B, A: one return; A, B, A, B, A: three, a cycle. Changes: between
      // stick and slip, while in contact.
      if (now != 0 && c.last > 0 && now != c.last) ++c.changes;
      if (now != 0 && now != c.last && now == c.beforeLast && ++c.returns >= 3 && mayHold && !c.hold)
        changed.emplace_back(k, kernels::kHeldInSlip);
      else if (lastResort && now != 0 && c.changes >= 4 && !c.hold)
        changed.emplace_back(k, kernels::kHeldInSlip);
      else if (freeze && now != 0 && !c.hold)
        changed.emplace_back(k, now == 1 ? kernels::kHeldInStick : kernels::kHeldInSlip);
      else if (c.hold == kernels::kHeldInStick) {
        // Frozen in stick: into slip (for good) once its traction leaves the cone.
        const double t = std::sqrt(pts(f, q, kTraction) * pts(f, q, kTraction) +
                                   pts(f, q, kTraction + 1) * pts(f, q, kTraction + 1) +
                                   pts(f, q, kTraction + 2) * pts(f, q, kTraction + 2));
        if (t > parameters_.mu * pts(f, q, kNormal) * (1 + 1e-9)) changed.emplace_back(k, kernels::kHeldInSlip);
      }
      c.beforeLast = c.last, c.last = now;
    }
  if (changed.empty()) return false;
  auto held = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), heldBranch_);
  for (const auto& [k, hold] : changed) {
    if (!cycles_[k].hold) ++heldPoints_;
    held(k) = cycles_[k].hold = hold;
  }
  Kokkos::deep_copy(heldBranch_, held);
  return true;
}

void FrictionEffect::releaseHeldSlips() {
  cycles_.clear();
  if (heldPoints_ == 0) return;
  Kokkos::deep_copy(heldBranch_, 0);
  heldPoints_ = 0;
}

void FrictionEffect::stickRows(ConstraintRows& rows, int width, const StickRowFill& fill, std::vector<double>& grad,
                               std::vector<double>& column) const {
  // On the host: the points of the nip only.
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  auto lambdaT = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), tangentialMultipliers_);
  const auto rule = contact_.rule();
  const int nq = kernels::facePointCount(rule);
  const auto b = contact_.axisDirection();
  const double epsT = parameters_.tangentPenalty;
  grad.clear(), column.clear();
  for (size_t f = 0; f < pts.extent(0); ++f)
    for (int q = 0; q < nq; ++q) {
      if (int(pts(f, q, kState)) != 1) continue;
      const int m = (int(f) * kernels::kMaxFacePoints + q) * 3;
      double xi, eta, w, N[4], dN[4][2];
      kernels::facePoint(rule, q, xi, eta, w);
      kernels::quadShape(xi, eta, N, dN);
      const double* e = &pts(f, q, kFE);
      const double tangents[2][3] = {{b[1] * e[2] - b[2] * e[1], b[2] * e[0] - b[0] * e[2], b[0] * e[1] - b[1] * e[0]},
                                     {b[0], b[1], b[2]}};
      for (int k = 0; k < 2; ++k) {
        const double* tau = tangents[k];
        // The slip along tau, from the stick traction t = P_t lambda_T + du_t / eps_t.
        double slip = 0;
        for (int i = 0; i < 3; ++i) slip += epsT * tau[i] * (pts(f, q, kTraction + i) - lambdaT(m + i));
        const size_t at = grad.size();
        grad.resize(at + width, 0.0), column.resize(at + width, 0.0);
        fill(f, N, e, tau, k == 0, &grad[at]);
        for (int a = 0; a < 4; ++a)  // dR/dmu = -w N_a tau on the face's nodes
          for (int i = 0; i < 3; ++i) column[at + 3 * a + i] = -pts(f, q, kFWeight) * N[a] * tau[i];
        rows.entity.push_back(int(f)), rows.multiplier.push_back(m);
        rows.force.push_back(pts(f, q, kFWeight)), rows.diagonal.push_back(0.0);
        rows.value.push_back(slip), rows.schur.push_back(-epsT), rows.scale.push_back(0.0);
        rows.direction.insert(rows.direction.end(), tau, tau + 3);
      }
    }
}

Matrix FrictionEffect::rowMatrix(const char* label, size_t rows, int width, const std::vector<double>& values) {
  Matrix m(std::string(label), rows, size_t(width));
  auto h = Kokkos::create_mirror_view(m);
  for (size_t k = 0; k < values.size(); ++k) h.data()[k] = values[k];
  Kokkos::deep_copy(m, h);
  return m;
}

void FrictionEffect::constraintRows(const NodalVectors&, ConstraintRows& rows) const {
  rows.clear();
  rows.gradient = Matrix();
  if (!stepsForItself()) return;
  std::vector<double> grad, column;
  stickRows(
      rows, 12,
      [](size_t, const double N[4], const double*, const double tau[3], bool, double* g) {
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) g[3 * a + i] = -N[a] * tau[i];  // d(tau . du_t) / dx_a
      },
      grad, column);
  rows.gradient = rowMatrix("stick dc/dx", rows.size(), 12, grad);  // the columns are force x gradient
}

double FrictionEffect::constraintViolation() const {
  if (!augmented()) return 0;
  auto pts = points_;
  auto lambdaT = tangentialMultipliers_;
  const int nq = kernels::facePointCount(contact_.rule());
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

double FrictionEffect::residualRoundOff(const Teuchos::Comm<int>& comm) const {
  double sum = 0;
  if ((settings_.law == FrictionSettings::Law::Tanh || settings_.law == FrictionSettings::Law::Arctan) &&
      parameters_.v > 0) {
    auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
    const int nq = kernels::facePointCount(contact_.rule());
    // Positions reach the faces' farthest node or the capstan's surface now
    // (a capstan with a Velocity moves away from where it started).
    const auto cyl = contact_.cylinder();
    const double capstanReach = cyl.R + std::sqrt(cyl.a[0] * cyl.a[0] + cyl.a[1] * cyl.a[1] + cyl.a[2] * cyl.a[2]);
    const double ds = std::numeric_limits<double>::epsilon() * std::max(positionScale_, capstanReach);
    for (size_t f = 0; f < pts.extent(0); ++f)
      for (int q = 0; q < nq; ++q)
        if (int(pts(f, q, kState)) != 0) {
          const double r = pts(f, q, kFWeight) * settings_.coefficient * pts(f, q, kNormal) * ds / parameters_.v;
          sum += r * r;
        }
  }
  double total = 0;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, sum, Teuchos::outArg(total));
  return std::sqrt(total);
}

FrictionEffect::Figures FrictionEffect::figures() const {
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  const int nq = kernels::facePointCount(contact_.rule());
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
      fig.work += w * pts(f, q, kWork);
      fig.normalIntegral += w * tn;
      if (settings_.coefficient > 0) fig.maxRatio = std::max(fig.maxRatio, mag / (settings_.coefficient * tn));
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
                                std::vector<double>& slip, std::vector<double>& slipRate) const {
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_);
  const int nq = kernels::facePointCount(contact_.rule());
  const size_t nf = pts.extent(0);
  traction.assign(3 * nf, 0.0);
  stick.assign(nf, 0.0);
  slip.assign(nf, 0.0);
  slipRate.assign(nf, 0.0);
  for (size_t f = 0; f < nf; ++f) {
    double area = 0;
    for (int q = 0; q < nq; ++q) {
      const double w = pts(f, q, kFWeight);
      area += w;
      for (int i = 0; i < 3; ++i) traction[3 * f + i] += w * pts(f, q, kTraction + i);
      slipRate[f] += w * pts(f, q, kSlip) * slipRateScale();
      const int state = int(pts(f, q, kState));
      if (state == 1) stick[f] += 1;
      if (state == 2) slip[f] += 1;
    }
    if (area > 0) {
      for (int i = 0; i < 3; ++i) traction[3 * f + i] /= area;
      slipRate[f] /= area;
    }
  }
}

void FrictionEffect::report(const Teuchos::Comm<int>& comm, StepRecord& rec) const {
  const auto ff = figures();
  double sums[8] = {ff.force[0], ff.force[1], ff.force[2], ff.torque, ff.frictionIntegral,
                    ff.normalIntegral, double(ff.stick), double(ff.slip)}, gs[8];
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, 8, sums, gs);
  double ratio = 0;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, ff.maxRatio, Teuchos::outArg(ratio));
  auto r = std::find_if(rec.capstans.begin(), rec.capstans.end(),
                        [&](const CapstanRecord& c) { return c.name == contact_.capstan().name; });
  if (r == rec.capstans.end()) throw std::logic_error(name() + ": its contact has not reported");
  r->friction = true;
  for (int i = 0; i < 3; ++i) r->force[i] += gs[i];
  r->torque += gs[3];
  r->frictionIntegral = gs[4];
  r->normalIntegral = gs[5];
  r->stick = long(gs[6]);
  r->slip = long(gs[7]);
  r->maxFrictionRatio = ratio;
  // The increment's dissipated work over its length; a re-evaluation of a
  // converged state (a zero-length interval) has no slip.
  double work = 0;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, ff.work, Teuchos::outArg(work));
  r->slipPower = dt_ > 0 ? work / dt_ : 0.0;
}

}  // namespace capstan
