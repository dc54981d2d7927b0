#include "predictors.hpp"

#include <algorithm>

#include "rolling.hpp"
#include "seating.hpp"

namespace capstan {

namespace {

// The predictor's solve with the factorisation Newton kept from the last step (GMRES with the
// LU preconditioner) instead of a new one, to this tolerance in at most this many iterations,
// else with a new one: fewer factorisations (docs/performance.md, "Defaults and why").
struct PredictorOnKept {
  double tolerance;
  int maxIterations;
};
constexpr PredictorOnKept kPredictorOnKept{1e-3, 30};

}  // namespace

double Predictors::firstGuess(double t0, double t, StepRecord& rec) {
  auto& assembly = *m_.assembly;
  Vector f(m_.u->getMap());
  double bare = 0;
  {
    Vector plain(*m_.u, Teuchos::Copy);
    assembly.applyConstraints(plain, t);
    assembly.evaluate(plain, &f, nullptr);
    bare = f.norm2();
  }
  // A fresh run's first increment: a body that the capstan overlaps deeply moved clear first.
  if (t0 == 0 && !previous_) seat(t, bare);
  // In steady rolling every increment looks like the one before (the nip has
  // moved on by one increment of the roller's turn), which the linear response
  // from a state at rest cannot see: the shape shifted along the streamlines,
  // else the last increment extrapolated.
  const std::vector<double> turns = coreTurns(t0, t);
  bool continued = m_.rolling && previous_ && tPrevious_ < t0 &&
                   (shiftAlongStreamlines(t0, t, turns) || extrapolate(t0, t, bare, f));
  // From the bare state every point of a driven roller's nip slips and the
  // core's rotation has almost no stiffness: turn the body with the core first.
  bool rolled = !continued && rollWithCores(turns);
  // A free core's roll is the guess. A prescribed turn's roll leaves the
  // loads' linear response to the tangent predictor, the turn left out of it.
  const auto& cores = m_.assembly->rigidCores();
  bool freeRolled = false;
  for (size_t i = 0; i < cores.size(); ++i) freeRolled = freeRolled || (rolled && cores[i].free[3] && turns[i] != 0);
  // A step that barely changes anything (steady rolling) needs no predictor.
  if (!continued && !freeRolled && m_.scene.solver.predictor == SolverSettings::Predictor::Tangent &&
      bare > 1e-8 * m_.forceScale)
    tangent(t0, t, bare, rec, rolled);
  assembly.applyConstraints(*m_.u, t);
  return bare;
}

void Predictors::seat(double t, double bare) {
  const double moved = seatFreeCore(m_, log_, t, bare);
  if (moved > 0 && !seated_)
    log_.progress(format("  step 1: the capstan overlaps the body by more than its shortest contact face edge: the "
                         "body moved %.4g clear with its core as the first guess",
                         moved));
  seated_ = seated_ || moved > 0;
}

void Predictors::linearResponse(double t, StepRecord& rec) {
  auto& assembly = *m_.assembly;
  assembly.applyConstraints(*m_.u, t);
  Vector f(m_.u->getMap());
  assembly.evaluate(*m_.u, &f, nullptr);
  const double bare = f.norm2();
  if (m_.scene.solver.predictor == SolverSettings::Predictor::Tangent && bare > 1e-8 * m_.forceScale)
    tangent(t, t, bare, rec);
  assembly.applyConstraints(*m_.u, t);
}

void Predictors::remember(const Vector& before, double tBefore, std::vector<double> rotationsBefore) {
  previous_ = rcp(new Vector(before, Teuchos::Copy));
  tPrevious_ = tBefore;
  previousRotation_ = std::move(rotationsBefore);
}

Predictors::Memory Predictors::memory() const {
  Memory memory;
  if (previous_.is_null()) return memory;
  const auto data = previous_->getData();
  memory.u.assign(data.begin(), data.end());
  memory.t = tPrevious_;
  memory.rotations = previousRotation_;
  return memory;
}

void Predictors::recall(const Memory& memory) {
  if (memory.u.empty()) return;
  previous_ = rcp(new Vector(m_.u->getMap()));
  auto data = previous_->getDataNonConst();
  std::copy(memory.u.begin(), memory.u.end(), data.begin());
  tPrevious_ = memory.t;
  previousRotation_ = memory.rotations;
}

bool Predictors::extrapolate(double t0, double t, double bare, Vector& f) {
  Vector trial(*m_.u, Teuchos::Copy);
  trial.update(-(t - t0) / (t0 - tPrevious_), *previous_, 1.0 + (t - t0) / (t0 - tPrevious_));
  m_.assembly->applyConstraints(trial, t);
  const bool valid = m_.assembly->evaluate(trial, &f, nullptr);
  const double norm = f.norm2();  // collective: every rank
  if (log_.on("newton"))
    log_.event("newton", format("extrapolated: valid %d |R| %.3e bare %.3e", int(valid), norm, bare),
             json::Object().add("event", json::string("extrapolation")).add("valid", valid ? "true" : "false")
                 .add("residual", json::number(norm)).add("bare", json::number(bare)));
  if (!(valid && norm < bare)) return false;
  m_.u->update(1.0, trial, 0.0);
  return true;
}

std::vector<double> Predictors::coreTurns(double t0, double t) const {
  const auto& cores = m_.assembly->rigidCores();
  std::vector<double> dTheta;
  for (size_t i = 0; i < cores.size(); ++i) {
    // A prescribed rotation turns the body with the core too: from the bare
    // state only the core's face would turn (9 rad in one step of the Hertz
    // ring inverted every brick next to it, and no cut recovered).
    // (Constraints' velocity of theta: the prescribed omega, or 0 for a held core.)
    double omega = m_.assembly->constraints().velocity[cores[i].firstDof + 3];
    if (cores[i].free[3]) {
      if (previous_ && tPrevious_ < t0)
        omega = (cores[i].rotation - previousRotation_[i]) / (t0 - tPrevious_);
      else
        omega = noSlipAngularVelocity(m_.scene, cores[i]);
    }
    dTheta.push_back(omega * (t - t0));
  }
  return dTheta;
}

bool Predictors::shiftAlongStreamlines(double t0, double t, const std::vector<double>& dTheta) {
  if (m_.scene.solver.rollingPredictor != SolverSettings::RollingPredictor::StreamlineShift || tPrevious_ <= 0)
    return false;
  // One turning core: the shift keeps one body's shape about one axis.
  if (std::count_if(dTheta.begin(), dTheta.end(), [](double x) { return x != 0; }) != 1) return false;
  const size_t c = size_t(std::find_if(dTheta.begin(), dTheta.end(), [](double x) { return x != 0; }) - dTheta.begin());
  auto& assembly = *m_.assembly;
  // Only near rolling: the last increment's turn within 20% of rolling without
  // slip. A cut step's first sub-step can end with the core turned backwards
  // (the fast roller at 2 cells per step), and shifting the shape upstream
  // then fails every later sub-step.
  const double noSlip = noSlipAngularVelocity(m_.scene, assembly.rigidCores()[c]) * (t - t0);
  if (!(std::fabs(dTheta[c] / noSlip - 1) < 0.2)) return false;
  if (!shift_) shift_ = std::make_unique<StreamlineShift>(assembly.mesh(), assembly.dofMap());
  // The cores' records are the bare state's (firstGuess evaluated it): the
  // converged translation.
  shift_->apply(*m_.u, assembly.rigidCores()[c], c, dTheta[c], assembly.ownedCoreDof(c, 3));
  // The multipliers stand in space too: left behind, the first pass of the
  // fast rollers and the drive started a cell's turn away from them.
  for (const auto& e : assembly.effects()) shift_->shiftMultipliers(*e, assembly.rigidCores()[c], c, dTheta[c]);
  if (log_.on("newton"))
    log_.event("newton", format("shifted along the streamlines by %.4g", dTheta[c]),
               json::Object().add("event", json::string("streamline_shift")).add("angle", json::number(dTheta[c])));
  return true;
}

bool Predictors::rollWithCores(const std::vector<double>& dTheta) {
  if (std::none_of(dTheta.begin(), dTheta.end(), [](double x) { return x != 0; })) return false;
  m_.assembly->rollWithCores(*m_.u, dTheta);
  if (log_.on("newton"))
    log_.event("newton", format("rolled by %.4g", dTheta[0]),
             json::Object().add("event", json::string("rolled")).add("angle", json::number(dTheta[0])));
  return true;
}

// Starting Newton from the linear response (rather than with the increment
// alone on the boundary, where the boundary layer of elements is badly
// distorted) saves most line-search work.
void Predictors::tangent(double t0, double t1, double bare, StepRecord& rec, bool turned) {
  auto& assembly = *m_.assembly;
  const auto map = m_.u->getMap();
  Vector z(map), Kz(map), f(map), rhs(map), du(map);
  assembly.constraintIncrement(z, t0, t1, turned);
  // Into Newton's matrix (Newton reassembles it before it solves): a matrix of
  // the predictor's own would cost memory (docs/performance.md).
  const RCP<FEMatrix> W = m_.newton->matrix();
  // Effects linearise for the predictor: contact leaves out its geometric stiffness (t_n / d,
  // large where the bare state penetrates by the whole increment) and friction assumes stick, so
  // the body follows the capstan, which a slipping linearisation cannot see.
  for (const auto& e : assembly.effects()) e->setPredicting(true);
  const bool valid = assembly.evaluate(*m_.u, &f, W.get(), &z, &Kz);
  if (!valid) {
    for (const auto& e : assembly.effects()) e->setPredicting(false);
    return;
  }
  {
    auto r = rhs.getDataNonConst();
    auto fd = f.getData();
    auto kz = Kz.getData();
    for (LO d = 0; d < LO(r.size()); ++d) r[d] = assembly.ownedConstrained(d) ? 0.0 : -(fd[d] + kz[d]);
  }
  // A first guess: 1e-6 is plenty (Newton corrects it); a tighter tolerance
  // on a nearly steady step, where the right-hand side is at round-off, ran
  // GMRES to its limit. With the factorisation Newton kept from the last step
  // where there is one (kPredictorOnKept), else with a new one.
  int its = -1, spent = 0;
  if (m_.newton->keepsFactorisation()) {
    its = m_.newton->linearSolve(rhs, du, std::max(kPredictorOnKept.tolerance, m_.scene.solver.linearTolerance),
                                 NewtonSolver::Preconditioner::KeptAsBuilt, kPredictorOnKept.maxIterations);
    if (its < 0) spent = kPredictorOnKept.maxIterations, du.putScalar(0.0);
  }
  if (its < 0) its = m_.newton->linearSolve(rhs, du, std::max(1e-6, m_.scene.solver.linearTolerance));
  for (const auto& e : assembly.effects()) e->setPredicting(false);
  rec.linear += spent;
  if (its < 0) return;  // keep the plain guess
  rec.linear += its;
  // The linear response can overshoot where contact or large strain makes the
  // problem strongly nonlinear (an element inverts, or the residual grows):
  // then try shorter steps along du before keeping the plain guess.
  for (double alpha = 1; alpha > 0.1; alpha /= 2) {
    Vector trial(*m_.u, Teuchos::Copy);
    trial.update(alpha, du, 1.0, z, 1.0);
    assembly.applyConstraints(trial, t1);
    const bool valid = assembly.evaluate(trial, &f, nullptr);
    const double norm = f.norm2();  // collective: every rank
    if (log_.on("newton"))
      log_.event("newton", format("predictor alpha %g valid %d |R| %.3e bare %.3e", alpha, int(valid), norm, bare),
               json::Object().add("event", json::string("predictor")).add("alpha", json::number(alpha))
                   .add("valid", valid ? "true" : "false").add("residual", json::number(norm))
                   .add("bare", json::number(bare)));
    if (!valid) continue;  // inverts an element
    if (norm < bare) {
      m_.u->update(1.0, trial, 0.0);
      return;
    }
  }
}

}  // namespace capstan
