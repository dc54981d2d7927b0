#include "steady_friction.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "../mesh.hpp"
#include "../rigid_cores.hpp"
#include "../rolling.hpp"
#include "../scene.hpp"
#include "entities.hpp"

namespace capstan {

namespace {
// Weights of an upwind difference at node 0 from nodes 1 (h1 behind) and 2
// (h1 + h2 behind): f' = sum_k w_k f_k. Second order: the parabola through
// the three; first order: (f_0 - f_1) / h1.
void upwindWeights(int order, double h1, double h2, double w[3]) {
  if (order == 1) {
    w[0] = 1 / h1, w[1] = -1 / h1, w[2] = 0;
    return;
  }
  w[0] = (2 * h1 + h2) / (h1 * (h1 + h2));
  w[1] = -(h1 + h2) / (h1 * h2);
  w[2] = h1 / (h2 * (h1 + h2));
}
}  // namespace

SteadyFrictionEffect::SteadyFrictionEffect(const std::string& name, const Mesh& mesh, const std::vector<int>& quads,
                                           const ContactEffect& contact, const FrictionSettings& settings,
                                           const Scene& scene)
    : FrictionEffect(name, mesh, quads, contact, settings) {
  sceneTangentPenalty_ = parameters_.tangentPenalty;
  for (const auto& s : scene.supports)
    if (s.isCore() && s.face == "inner") coreName_ = s.name, axisSign_ = s.axisDirection[2] > 0 ? 1.0 : -1.0;
  // The no-slip flow about +z: the roller's surface at the capstan's surface speed.
  const auto& c = contact.capstan();
  omegaRef_ = -c.angularVelocity * c.radius * (c.axisDirection[2] > 0 ? 1.0 : -1.0) / scene.mesh.outerRadius;
  sigma_ = omegaRef_ >= 0 ? 1.0 : -1.0;
  const int order = scene.analysis.upwindOrder;
  const size_t nf = quads.size() / 4;
  entityNodes_ = decltype(entityNodes_)("steady friction nodes", nf);
  weights_ = decltype(weights_)("steady friction weights", nf);
  crossing_ = Kokkos::View<double*>("steady friction crossing time", nf);
  auto hn = Kokkos::create_mirror_view(entityNodes_);
  auto hw = Kokkos::create_mirror_view(weights_);
  auto hc = Kokkos::create_mirror_view(crossing_);
  const auto& ctr = scene.mesh.center;
  auto angle = [&](int n) { return std::atan2(mesh.X[3 * n + 1] - ctr[1], mesh.X[3 * n] - ctr[0]); };
  auto behind = [&](int from, int to) {  // the ring angle from `to` forward to `from` along the flow
    const double d = std::remainder(sigma_ * (angle(from) - angle(to)), 2 * M_PI);
    if (!(d > 0)) throw std::logic_error(name + ": a ring cell of non-positive angle");
    return d;
  };
  const int back1 = sigma_ > 0 ? 1 : 2, back2 = sigma_ > 0 ? 0 : 3;  // Mesh::kRingSteps -1, -2 (or +1, +2)
  for (size_t f = 0; f < nf; ++f) {
    std::vector<int> nodes(quads.begin() + 4 * f, quads.begin() + 4 * f + 4);
    auto slot = [&](int n) {
      const auto it = std::find(nodes.begin(), nodes.end(), n);
      if (it != nodes.end()) return int(it - nodes.begin());
      nodes.push_back(n);
      return int(nodes.size()) - 1;
    };
    double mean = 0, W[4][kNodes] = {};
    for (int a = 0; a < 4; ++a) {
      const int n = quads[4 * f + a];
      const int u1 = mesh.ringNeighbours[n][back1], u2 = mesh.ringNeighbours[n][back2];
      if (u1 < 0 || u2 < 0) throw std::logic_error(name + ": a contact node without its ring neighbours");
      const double h1 = behind(n, u1), h2 = behind(u1, u2);
      double w[3];
      upwindWeights(order, h1, h2, w);
      W[a][a] += w[0], W[a][slot(u1)] += w[1];
      if (order == 2) W[a][slot(u2)] += w[2];
      mean += h1 / 4;
    }
    if (nodes.size() > size_t(kNodes)) throw std::logic_error(name + ": more upstream nodes than an entity holds");
    while (nodes.size() < size_t(kNodes)) nodes.push_back(nodes[0]);  // repeats carry zero weight
    hc(f) = mean / std::fabs(omegaRef_);
    for (int k = 0; k < kNodes; ++k) hn(f, k) = nodes[k];
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < kNodes; ++k) hw(f, a, k) = W[a][k] * hc(f);
  }
  Kokkos::deep_copy(entityNodes_, hn);
  Kokkos::deep_copy(weights_, hw);
  Kokkos::deep_copy(crossing_, hc);
  // Entities: the face's 4 nodes (rows) and the upstream ones (columns), and
  // omega's block (bindCores); the work and slip the kernel reports are per
  // unit time.
  dt_ = 1;
  local_.rowDofs = 12;
  auto dofs = IntMatrix("steady friction dofs", nf, 3 * kNodes);
  auto hd = Kokkos::create_mirror_view(dofs);
  for (size_t f = 0; f < nf; ++f)
    for (int k = 0; k < kNodes; ++k)
      for (int i = 0; i < 3; ++i) hd(f, 3 * k + i) = 3 * hn(f, k) + i;
  Kokkos::deep_copy(dofs, hd);
  local_.dofs = dofs;
  local_.R = Matrix("steady friction R", nf, 3 * kNodes);
}

double SteadyFrictionEffect::surfaceSpeed() const {
  return std::abs(contact_.capstan().angularVelocity * contact_.radius());
}

double SteadyFrictionEffect::sceneSlipFraction() const {
  const auto law = startLaw_ ? sceneLaw_ : settings_.law;
  if (law == FrictionSettings::Law::Coulomb || law == FrictionSettings::Law::None) return 0;
  return (startLaw_ ? sceneRegularization_ : settings_.regularization) / surfaceSpeed();
}

void SteadyFrictionEffect::useStartLaw(double speedFraction) {
  if (!startLaw_) {
    sceneLaw_ = settings_.law;
    sceneRegularization_ = settings_.regularization;
    startLaw_ = true;
  }
  if (sceneLaw_ == FrictionSettings::Law::Coulomb) {
    settings_.law = FrictionSettings::Law::Tanh;
    parameters_.law = kernels::FrictionLaw::Tanh;
  }
  settings_.regularization = speedFraction * surfaceSpeed();
}

void SteadyFrictionEffect::useSceneLaw(bool seed) {
  if (!startLaw_) return;
  startLaw_ = false;
  settings_.regularization = sceneRegularization_;
  if (sceneLaw_ != FrictionSettings::Law::Coulomb) return;
  settings_.law = FrictionSettings::Law::Coulomb;
  parameters_.law = kernels::FrictionLaw::Coulomb;
  // lambda_T = t. Seeding lambda_T = t - du_t / eps_t instead (Tanh's traction as Coulomb's
  // trial traction) cost the 126k-dof drive's GMRES solves dearly (docs/steady-rolling.md,
  // "Start from rest").
  if (seed) multiplierMap(tangentialMultipliers_);
}

void SteadyFrictionEffect::bindCores(const RigidCores& cores) {
  cores_ = &cores;
  core_ = coreName_.empty() ? -1 : cores.find(coreName_);
  if (core_ < 0) return;
  // omega's block of 3 (omega and the core's two unused slots, held), so the
  // entity's dofs stay in blocks of 3 (TangentSink).
  const int first = cores.records()[core_].firstDof + 3;
  const size_t nf = local_.dofs.extent(0);
  auto old = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), local_.dofs);
  constexpr int n = 3 * kNodes;
  auto dofs = IntMatrix("steady friction dofs", nf, n + 3);
  auto hd = Kokkos::create_mirror_view(dofs);
  for (size_t f = 0; f < nf; ++f) {
    for (int k = 0; k < n; ++k) hd(f, k) = old(f, k);
    for (int k = 0; k < 3; ++k) hd(f, n + k) = first + k;
  }
  Kokkos::deep_copy(dofs, hd);
  local_.dofs = dofs;
  local_.R = Matrix("steady friction R", nf, n + 3);
}

void SteadyFrictionEffect::launch(const NodalVectors& x, const NodalVectors&, bool tangent, const TangentSink& sink) {
  auto nodes = entityNodes_;
  auto W = weights_;
  auto crossing = crossing_;
  auto X = X_;
  auto R = local_.R;
  auto active = local_.active;
  auto lambda = contact_.normalMultipliers();
  auto lambdaT = tangentialMultipliers_;
  auto held = heldBranch_;
  auto h = history_;
  const bool useMultipliers = augmented();
  auto pts = points_;
  const kernels::Cylinder cyl = contact_.cylinder();
  const double eps = contact_.solvePenalty(), kappa = contact_.compliance();
  const auto rule = contact_.rule();
  const int nq = kernels::facePointCount(rule);
  kernels::FrictionParameters fp = parameters_;
  fp.ds[0] = fp.ds[1] = fp.ds[2] = 0;
  const double surfaceSpeed = contact_.capstan().angularVelocity * contact_.radius();
  const double eps3 = settings_.regularization * regularisationScale_;
  // The flow's angular velocity about +z, times its sign sigma (> 0 when
  // omega is near its no-slip value), and its derivative by omega.
  const double omega = core_ >= 0 ? cores_->records()[core_].angularVelocity : 0.0;
  const double flow = sigma_ * axisSign_ * omega, dFlow = sigma_ * axisSign_;
  const bool withOmega = core_ >= 0, enabled = enabled_;
  constexpr int kN = kNodes, nNode = 3 * kNodes;
  Kokkos::parallel_for(
      "steady friction residual+tangent", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)),
      KOKKOS_LAMBDA(int f) {
        const int n = withOmega ? nNode + 3 : nNode;
        for (int k = 0; k < n; ++k) R(f, k) = 0;
        kernels::FrictionPoint p[kernels::kMaxFacePoints];
        for (int q = 0; q < nq; ++q) p[q] = kernels::FrictionPoint();
        double Xf[4][3], xf[4][3], xn[4][3], dxn[4][3];  // dxn: d xn / d omega
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) {
            double travel = 0;  // tau_f (dx/dtheta)_a
            for (int k = 0; k < kN; ++k) travel += W(f, a, k) * x(nodes(f, k), i);
            Xf[a][i] = X(f, a, i);
            xf[a][i] = x(nodes(f, a), i);
            xn[a][i] = xf[a][i] - flow * travel;
            dxn[a][i] = -dFlow * travel;
          }
        kernels::FrictionParameters fq = fp;
        fq.spin = surfaceSpeed * crossing(f);  // omega_c R tau_f
        fq.v = eps3 * crossing(f);
        double K[144], Kn[144];
        active(f) = enabled && kernels::frictionFaceResidualTangent(
                                   Xf, xf, xn, cyl, eps, kappa, &lambda(f * kernels::kMaxFacePoints), rule, fq,
                                   useMultipliers ? &lambdaT(f * kernels::kMaxFacePoints * 3)
                                                  : &h(f * kHistoryPerFace + 12),
                                   &R(f, 0), tangent ? K : nullptr, p, tangent ? Kn : nullptr,
                                   &held(f * kernels::kMaxFacePoints));
        if (!active(f)) {
          for (int k = 0; k < 12; ++k) R(f, k) = 0;
        } else if (tangent) {
          // Column block k (entity node k): [k < 4] K + sum_a Kn_a (delta_ak - flow W_ak);
          // omega's column: sum_a Kn_a dxn_a/domega. Rows beyond the face's 12: none.
          double Ke[(nNode + 3) * (nNode + 3)];
          for (int k = 0; k < n * n; ++k) Ke[k] = 0;
          for (int r = 0; r < 12; ++r) {
            double dOmega = 0;
            for (int a = 0; a < 4; ++a)
              for (int j = 0; j < 3; ++j) {
                const double kn = Kn[r * 12 + 3 * a + j];
                Ke[r * n + 3 * a + j] += K[r * 12 + 3 * a + j] + kn;
                for (int k = 0; k < kN; ++k) Ke[r * n + 3 * k + j] -= kn * flow * W(f, a, k);
                dOmega += kn * dxn[a][j];
              }
            if (withOmega) Ke[r * n + nNode] = dOmega;
          }
          if (withOmega) sink.take<nNode + 3>(f, Ke);
          else sink.take<nNode>(f, Ke);
        }
        // Per unit time: the slip over the crossing time, the work likewise.
        for (int q = 0; q < nq; ++q) {
          for (int i = 0; i < 3; ++i) pts(f, q, kTraction + i) = p[q].traction[i];
          pts(f, q, kNormal) = p[q].normal;
          pts(f, q, kSlip) = p[q].slip / crossing(f);
          pts(f, q, kState) = p[q].state;
          pts(f, q, kFWeight) = p[q].weight;
          for (int i = 0; i < 3; ++i) pts(f, q, kFE + i) = p[q].e[i];
          pts(f, q, kWork) = p[q].work / crossing(f);
        }
      });
}

void SteadyFrictionEffect::constraintRows(const NodalVectors& x, ConstraintRows& rows) const {
  rows.clear();
  rows.gradient = Matrix();
  if (!stepsForItself() || !enabled_) return;
  auto W = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), weights_);
  auto nodes = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), entityNodes_);
  auto xh = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
  const double omega = core_ >= 0 ? cores_->records()[core_].angularVelocity : 0.0;
  const double flow = sigma_ * axisSign_ * omega, dFlow = sigma_ * axisSign_;
  constexpr int nNode = 3 * kNodes;
  const int n = core_ >= 0 ? nNode + 3 : nNode;
  const double radius = contact_.radius();
  std::vector<double> grad, column;
  stickRows(
      rows, n,
      [&](size_t f, const double N[4], const double* e, const double tau[3], bool circumferential, double* g) {
        double travel[3] = {0, 0, 0};  // sum_a N_a tau_f (dx/dtheta)_a
        for (int k = 0; k < kNodes; ++k) {
          double NW = 0;
          for (int a = 0; a < 4; ++a) NW += N[a] * W(f, a, k);
          for (int i = 0; i < 3; ++i) {
            g[3 * k + i] -= flow * NW * tau[i];
            travel[i] += NW * xh(nodes(f, k), i);
          }
        }
        if (core_ >= 0) g[nNode] = -dFlow * (tau[0] * travel[0] + tau[1] * travel[1] + tau[2] * travel[2]);
        // tau = b x e turns with the point (de/dx = (I - b b^T - e e^T) / d):
        // du^T dtau/dx = -(e . du) tau^T / d, with e . du = -flow e . travel
        // (the capstan's travel is tangent). The capstan's own travel, spin
        // (b x e), turns likewise but has no component along tau's change.
        if (circumferential) {
          const double normalSlip = -flow * (e[0] * travel[0] + e[1] * travel[1] + e[2] * travel[2]);
          for (int a = 0; a < 4; ++a)
            for (int i = 0; i < 3; ++i) g[3 * a + i] -= N[a] * normalSlip * tau[i] / radius;
        }
      },
      grad, column);
  rows.gradient = rowMatrix("steady stick dc/dx", rows.size(), n, grad);
  rows.column = rowMatrix("steady stick dR/dmu", rows.size(), n, column);
}

}  // namespace capstan
