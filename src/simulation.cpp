#include "simulation.hpp"

#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <sys/resource.h>

#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "anderson.hpp"
#include "assembly.hpp"
#include "checkpoint.hpp"
#include "errors.hpp"
#include "field_writer.hpp"
#include "json.hpp"
#include "newton.hpp"
#include "pressure_step.hpp"

namespace capstan {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The saddle-point pressure step's GMRES tolerance (relative): the volume
// error then falls about 1000x per pass in the linear regime.
constexpr double kPressureStepTolerance = 1e-3;
// ... and the volume error it aims to leave, as a fraction of the volume
// tolerance: the pass it ends is then the last.
constexpr double kPressureStepVolumeMargin = 0.3;

MPI_Comm rawComm(const RCP<const Comm>& comm) {
  auto mpi = Teuchos::rcp_dynamic_cast<const Teuchos::MpiComm<int>>(comm);
  return mpi.is_null() ? MPI_COMM_SELF : (*mpi->getRawMpiComm())();
}

// One capstan's figures at a converged step (global).
struct CapstanRecord {
  std::string name;
  std::array<double, 3> force{};  // body on capstan
  double torque = 0, maxPenetration = 0, peakPressure = 0, area = 0, width = 0;
  long points = 0;
  bool friction = false;
  long stick = 0, slip = 0;
  double frictionIntegral = 0, normalIntegral = 0, maxFrictionRatio = 0;
};

// A support's figures at a converged step (global). Rigid cores add their
// motion and torque.
struct SupportRecord {
  std::string name;
  std::array<double, 3> force{};  // support (core) on body
  bool core = false;
  double torque = 0, rotation = 0, angularVelocity = 0;
  bool hasSpeedRatio = false;
  double speedRatio = 0;  // roller surface speed / capstan surface speed
  std::array<double, 3> translation{};
};

struct StepRecord {
  int step = 0;
  double time = 0;
  int newton = 0, linear = 0, cutbacks = 0, augmentations = 0;
  int pressureStep = 0;  // Krylov iterations of the saddle-point pressure steps (part of linear)
  double residual = 0, wall = 0, volumeChange = 0;
  std::vector<SupportRecord> supports;
  std::vector<CapstanRecord> capstans;
  double maxPenetration() const {
    double m = 0;
    for (const auto& c : capstans) m = std::max(m, c.maxPenetration);
    return m;
  }
};

// Figures of the current state, reduced over all ranks.
struct StateFigures {
  double vmMin = 0, vmMax = 0, pMin = 0, pMax = 0, volumeChange = 0;
  double sMin[6] = {}, sMax[6] = {};
  std::array<double, 3> maxDisplacement{};
  std::vector<std::pair<std::string, std::array<double, 3>>> faceMeans;
};

void writeAtomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

// The lowest rank with a non-empty `error`, or -1 when no rank has one;
// `error` then holds that rank's message on every rank.
int firstError(const Comm& comm, std::string& error) {
  const int size = comm.getSize();
  int mine = error.empty() ? size : comm.getRank(), first = size;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, mine, Teuchos::outArg(first));
  if (first == size) return -1;
  int length = int(error.size());
  Teuchos::broadcast(comm, first, &length);
  error.resize(size_t(length));
  if (length > 0) Teuchos::broadcast(comm, first, length, &error[0]);
  return first;
}

// Collective error checks: every rank throws together, so none is left
// waiting in a collective call.
void agreeInput(const Comm& comm, std::string error) {
  if (firstError(comm, error) >= 0) throw InputError(error);
}
void agreeRuntime(const Comm& comm, std::string error) {
  if (firstError(comm, error) >= 0) throw std::runtime_error(error);
}

// Step records in a checkpoint (rank 0's file): what summary.json and
// history.csv list for the steps before the restart.
void putRecord(checkpoint::Writer& w, const StepRecord& r) {
  w.put(r.step), w.put(r.time), w.put(r.newton), w.put(r.linear), w.put(r.cutbacks);
  w.put(r.augmentations), w.put(r.residual), w.put(r.wall), w.put(r.volumeChange), w.put(r.pressureStep);
  w.put<int>(int(r.supports.size()));
  for (const auto& s : r.supports) {
    w.put(s.name), w.put(s.force), w.put(s.core), w.put(s.torque), w.put(s.rotation), w.put(s.angularVelocity);
    w.put(s.translation), w.put(s.hasSpeedRatio), w.put(s.speedRatio);
  }
  w.put<int>(int(r.capstans.size()));
  for (const auto& c : r.capstans) {
    w.put(c.name), w.put(c.force), w.put(c.torque), w.put(c.maxPenetration), w.put(c.peakPressure);
    w.put(c.area), w.put(c.width), w.put(c.points), w.put(c.friction), w.put(c.stick), w.put(c.slip);
    w.put(c.frictionIntegral), w.put(c.normalIntegral), w.put(c.maxFrictionRatio);
  }
}

StepRecord getRecord(checkpoint::Reader& in) {
  StepRecord r;
  r.step = in.get<int>(), r.time = in.get<double>(), r.newton = in.get<int>();
  r.linear = in.get<int>(), r.cutbacks = in.get<int>(), r.augmentations = in.get<int>();
  r.residual = in.get<double>(), r.wall = in.get<double>(), r.volumeChange = in.get<double>();
  r.pressureStep = in.get<int>();
  const int ns = in.get<int>();
  for (int i = 0; i < ns; ++i) {
    auto name = in.getString();
    SupportRecord s;
    s.name = name, s.force = in.get<std::array<double, 3>>(), s.core = in.get<bool>();
    s.torque = in.get<double>(), s.rotation = in.get<double>(), s.angularVelocity = in.get<double>();
    s.translation = in.get<std::array<double, 3>>();
    s.hasSpeedRatio = in.get<bool>(), s.speedRatio = in.get<double>();
    r.supports.push_back(s);
  }
  const int nc = in.get<int>();
  for (int i = 0; i < nc; ++i) {
    CapstanRecord c;
    c.name = in.getString(), c.force = in.get<std::array<double, 3>>(), c.torque = in.get<double>();
    c.maxPenetration = in.get<double>(), c.peakPressure = in.get<double>(), c.area = in.get<double>();
    c.width = in.get<double>(), c.points = in.get<long>(), c.friction = in.get<bool>();
    c.stick = in.get<long>(), c.slip = in.get<long>(), c.frictionIntegral = in.get<double>();
    c.normalIntegral = in.get<double>(), c.maxFrictionRatio = in.get<double>();
    r.capstans.push_back(c);
  }
  return r;
}

class Run {
 public:
  Run(const Scene& scene, const RCP<const Comm>& comm, const RunOptions& opt)
      : scene_(scene), comm_(comm), opt_(opt), rank0_(comm->getRank() == 0), t0_(Clock::now()) {}

  int execute();

 private:
  void predict(double t0, double t1, double bareResidual, StepRecord& rec);
  // Debugging aid (CAPSTAN_CHECK_TANGENT=1): the assembled tangent against a
  // central difference of the residual along a random direction, printed.
  void checkTangent();
  bool solveAt(double t0, double t1, StepRecord& rec, std::string& failure);
  // The pressure loop's saddle-point step at the converged state (src/
  // pressure_step.hpp): moves u and the pressure anchors together. False if
  // the block solve made no progress (nothing is changed then).
  bool saddlePointPressureStep(double t, Vector& f, StepRecord& rec);
  // Newton's linear solves and the pressure steps' block solves.
  double linearSolveSeconds() const {
    return newton_->linearSolveSeconds() + (pressureStep_ ? pressureStep_->seconds() : 0.0);
  }
  void recordStep(StepRecord& rec);
  CapstanRecord capstanFigures(const ContactEffect& contact, const FrictionEffect* friction) const;
  // Every effect's augmentation multipliers (pressure anchors, contact
  // multipliers) as one vector of this rank's values.
  // multiplier values of this rank, of the effects that are (or are not)
  // Anderson-accelerated.
  std::vector<double> multipliers(bool accelerated) const;
  std::vector<double> multiplierMap(bool accelerated) const;
  // keep: effects whose multipliers stay as they are.
  void setMultipliers(const std::vector<double>& values, bool accelerated,
                      const std::vector<const Effect*>& keep = {});
  // What a failed increment must undo: the multipliers and the effects'
  // history (committed by the converged sub-steps of a step that fails later).
  struct SolverState {
    std::vector<double> accelerated, plain, history;
  };
  SolverState saveState() const;
  void restoreState(const SolverState& m);
  StateFigures figures();
  // Why a step may have no equilibrium at all: a core's applied torque beyond
  // what friction in the nip can carry. Empty when no such core.
  std::string brakeDiagnosis() const;
  // The core's angular velocity when its outer (undeformed) surface rolls
  // without slip on the first spinning capstan (external contact: it turns
  // against the capstan); 0 when there is none. The speed ratio is the core's
  // angular velocity over this.
  double noSlipAngularVelocity(const RigidCore& core) const;
  // Element stress (6 per element), von Mises and pressure on the host, at the
  // last evaluated state.
  struct ElementFields {
    Matrix::HostMirror stress;
    Kokkos::View<double*>::HostMirror mises, pressure;
  };
  ElementFields elementFields() const;
  void writeFields(int step, double time);
  void writeSummary(bool converged, const std::string& failure);
  void writeHistory();
  void checkOutputDirectory();
  // fields.h5 rows of this rank (collective).
  FieldLayout fieldLayout() const;

  // Checkpoint/restart. The state a continuation needs: u, every effect's
  // multipliers (pressure anchors, contact and tangential multipliers) and
  // history (friction's positions, tractions and stick states), the step and
  // its time, and the step records for summary.json and history.csv. The step
  // size needs no saving: every step starts at the full Time/Step Size (cuts
  // last only within a step), and nothing else carries over between steps
  // (each Newton solve, Anderson mixing and preconditioner is built afresh).
  struct Restart {
    fs::path dir;  // the checkpoint read (OUTDIR/checkpoint/step-N)
    fs::path file; // this rank's file in it
    int step = 0;
    double time = 0;
    std::unique_ptr<checkpoint::Reader> in;  // positioned after the header
  };
  std::string checkpointBytes(int step, double time) const;
  void writeCheckpoint(int step, double time);
  // Finds and checks the checkpoint against the scene before anything is built.
  void openRestart(Restart& r);
  // Loads the state into the built run; throws InputError where it does not fit.
  void restore(Restart& r);
  // Node ids of each entity of effect e (nodes per entity in `perEntity`).
  std::vector<long long> entityKeys(const Effect& e, int& perEntity) const;

  const Scene& scene_;
  RCP<const Comm> comm_;
  RunOptions opt_;
  bool rank0_;
  Clock::time_point t0_;
  std::unique_ptr<MeshGenerator> generator_;
  Mesh mesh_;
  std::unique_ptr<Assembly> assembly_;
  std::unique_ptr<NewtonSolver> newton_;
  std::unique_ptr<PressureStep> pressureStep_;  // null with Solver/Pressure Update = Anderson
  std::vector<Kokkos::View<double*>> pressureStepDmu_;  // per effect: its multipliers' change in the step
  RCP<Vector> u_;
  std::unique_ptr<FieldWriter> writer_;
  std::vector<StepRecord> steps_;
  fs::path dir_;
  double outputSeconds_ = 0;
  // A restarted run's summary adds the earlier run's time and kernel counts.
  double timingOffset_[5] = {0, 0, 0, 0, 0};  // total, assembly, linear solve, output, preconditioner set-up
  std::map<std::string, std::pair<long, double>> effectOffset_;
  long numContactFaces_ = 0;  // global, each candidate face once
  double absTolerance_ = 0;
  // A rigid core turns freely: the rolling measures (extrapolation, rolling
  // first guess, settled multipliers) are on. Not checkpointed: a restarted
  // rolling run starts them afresh and may differ from an uninterrupted one.
  bool rolling_ = false;
  RCP<Vector> previous_;    // the state before the last converged increment (extrapolation)
  double tPrevious_ = 0;
  std::vector<double> previousRotation_;  // the cores' rotations in that state
  double forceScale_ = 1;  // c L^2, L the body's largest extent
};

// Tangent predictor: from the converged state u_n, the prescribed increment z
// and the linear response of the free dofs, K_ff du = -(R + K z)_f. Starting
// Newton there (rather than with the increment alone on the boundary, where the
// boundary layer of elements is badly distorted) saves most line-search work.
void Run::predict(double t0, double t1, double bareResidual, StepRecord& rec) {
  const auto map = u_->getMap();
  Vector z(map), Kz(map), f(map), rhs(map), du(map);
  assembly_->constraintIncrement(z, t0, t1);
  // Newton's matrix (Newton reassembles it before it solves): a matrix of the
  // predictor's own cost G1 8x 330 MiB of its 5.7 GiB peak on one rank.
  const RCP<FEMatrix> W = newton_->matrix();
  // Effects linearise for the predictor: the bare state penetrates the
  // capstans by the whole increment (contact leaves out its geometric
  // stiffness, t_n / d, large there) and slides over them by the capstan's
  // whole travel (friction assumes stick: the body follows the capstan, which
  // a slipping linearisation, with no stiffness along the slip, cannot see).
  for (const auto& e : assembly_->effects()) e->setPredicting(true);
  const bool valid = assembly_->evaluate(*u_, &f, W.get(), &z, &Kz);
  if (!valid) {
    for (const auto& e : assembly_->effects()) e->setPredicting(false);
    return;
  }
  {
    auto r = rhs.getDataNonConst();
    auto fd = f.getData();
    auto kz = Kz.getData();
    for (LO d = 0; d < LO(r.size()); ++d) r[d] = assembly_->ownedConstrained(d) ? 0.0 : -(fd[d] + kz[d]);
  }
  // A first guess: 1e-6 is plenty (Newton corrects it), and a tighter
  // tolerance on a nearly steady step, where the right-hand side is at
  // round-off, ran GMRES to its limit (H1 8x: 92 s per steady step).
  const int its = newton_->linearSolve(rhs, du, std::max(1e-6, scene_.solver.get<double>("Linear Tolerance")));
  for (const auto& e : assembly_->effects()) e->setPredicting(false);
  if (its < 0) return;  // keep the plain guess
  rec.linear += its;
  // The linear response can overshoot where contact or large strain makes the
  // problem strongly nonlinear (an element inverts, or the residual grows):
  // then try shorter steps along du before keeping the plain guess.
  for (double alpha = 1; alpha > 0.1; alpha /= 2) {
    Vector trial(*u_, Teuchos::Copy);
    trial.update(alpha, du, 1.0, z, 1.0);
    assembly_->applyConstraints(trial, t1);
    const bool valid = assembly_->evaluate(trial, &f, nullptr);
    const double norm = f.norm2();  // collective: every rank
    if (std::getenv("CAPSTAN_NEWTON_LOG") && rank0_ && !opt_.quiet)
      std::printf("    predictor alpha %g valid %d |R| %.3e bare %.3e\n", alpha, int(valid), norm, bareResidual);
    if (!valid) continue;  // inverts an element
    if (norm < bareResidual) {
      u_->update(1.0, trial, 0.0);
      return;
    }
  }
}

void Run::checkTangent() {
  const auto map = u_->getMap();
  Vector v(map), Wv(map), fp(map), fm(map), trial(map);
  v.randomize();
  {
    auto d = v.getDataNonConst();
    for (LO i = 0; i < LO(d.size()); ++i)
      if (assembly_->ownedConstrained(i)) d[i] = 0;
  }
  auto W = assembly_->createMatrix();
  assembly_->evaluate(*u_, nullptr, W.get());
  W->apply(v, Wv);
  const double h = 1e-7;
  trial.update(1.0, *u_, h, v, 0.0);
  assembly_->evaluate(trial, &fp, nullptr);
  trial.update(1.0, *u_, -h, v, 0.0);
  assembly_->evaluate(trial, &fm, nullptr);
  Vector diff(map);
  diff.update(1.0 / (2 * h), fp, -1.0 / (2 * h), fm, 0.0);
  diff.update(-1.0, Wv, 1.0);
  const double error = diff.norm2(), scale = Wv.norm2();  // collective: every rank
  if (rank0_) std::printf("    tangent check: |W v - FD| / |W v| = %.3e (|W v| = %.3e)\n", error / scale, scale);
  assembly_->evaluate(*u_, nullptr, nullptr);
}

bool Run::solveAt(double t0, double t, StepRecord& rec, std::string& failure) {
  const auto& sol = scene_.solver;
  assembly_->setInterval(t0, t);
  // Residual of the bare load increment: the predictor must beat it, and the
  // Newton tolerance is relative to it.
  Vector f(u_->getMap());
  double bare = 0;
  {
    Vector plain(*u_, Teuchos::Copy);
    assembly_->applyConstraints(plain, t);
    assembly_->evaluate(plain, &f, nullptr);
    bare = f.norm2();
  }
  // Rolling only (a rigid core turning freely): extrapolation along the last
  // converged increment. In steady rolling every
  // increment looks like the one before (the nip has moved on by one increment
  // of the roller's turn), which the linear response from a state at rest
  // cannot see. Kept when it beats the bare increment.
  bool extrapolated = false;
  if (rolling_ && previous_ && tPrevious_ < t0) {
    Vector trial(*u_, Teuchos::Copy);
    trial.update(-(t - t0) / (t0 - tPrevious_), *previous_, 1.0 + (t - t0) / (t0 - tPrevious_));
    assembly_->applyConstraints(trial, t);
    const bool valid = assembly_->evaluate(trial, &f, nullptr);
    const double norm = f.norm2();  // collective: every rank
    if (std::getenv("CAPSTAN_NEWTON_LOG") && rank0_ && !opt_.quiet)
      std::printf("    extrapolated: valid %d |R| %.3e bare %.3e\n", int(valid), norm, bare);
    if (valid && norm < bare) {
      u_->update(1.0, trial, 0.0);
      extrapolated = true;
    }
  }
  // A free core driven by a spinning capstan: turn the whole body with it, at
  // its last angular velocity (at first: rolling without slip), so that the nip
  // starts near stick; from the bare state every point slips and the core's
  // rotation has almost no stiffness.
  bool rolled = false;
  if (!extrapolated) {
    std::vector<double> dTheta;
    for (const auto& core : assembly_->rigidCores()) {
      double omega = 0;
      if (core.free[3]) {
        if (previous_ && tPrevious_ < t0) {
          omega = (core.rotation - previousRotation_[&core - assembly_->rigidCores().data()]) / (t0 - tPrevious_);
        } else {
          omega = noSlipAngularVelocity(core);
        }
      }
      dTheta.push_back(omega * (t - t0));
    }
    if (std::any_of(dTheta.begin(), dTheta.end(), [](double x) { return x != 0; })) {
      assembly_->rollWithCores(*u_, dTheta);
      rolled = true;
      if (std::getenv("CAPSTAN_NEWTON_LOG")) {
        Vector trial(*u_, Teuchos::Copy);
        assembly_->applyConstraints(trial, t);
        assembly_->evaluate(trial, &f, nullptr);
        const double n = f.norm2();
        if (rank0_ && !opt_.quiet) std::printf("    rolled by %.4g: |R| %.3e bare %.3e\n", dTheta[0], n, bare);
      }
    }
  }
  // A step that barely changes anything (steady rolling) needs no predictor.
  if (!extrapolated && !rolled && sol.get<std::string>("Predictor") == "Tangent" && bare > 1e-8 * forceScale_)
    predict(t0, t, bare, rec);
  assembly_->applyConstraints(*u_, t);
  if (std::getenv("CAPSTAN_CHECK_TANGENT")) checkTangent();
  // r0 is capped by the body's force scale c L^2: with a small penalty the bare
  // increment's residual is huge (volume error / eps), and a tolerance relative
  // to it would accept a poorly converged state.
  const double r0 = std::min(bare, forceScale_);
  const double tol = std::max(sol.get<double>("Newton Relative Tolerance") * r0, absTolerance_);
  // The augmentation loop: Newton at fixed multipliers, then each effect's
  // constraint is checked and the multipliers move to their fixed-point map
  // (Anderson-accelerated, formulation.md §1 and §2).
  int maxOuter = sol.get<int>("Max Pressure Iterations");
  for (const auto* c : assembly_->contacts()) maxOuter = std::max(maxOuter, c->maxAugmentations());
  AndersonMixing mixing(sol.get<int>("Pressure Acceleration Depth"), comm_);
  for (int it = 1; it <= maxOuter; ++it) {
    // After a multiplier update the residual may already be below the step's
    // tolerance; x must still respond to the new multipliers, or the loop
    // drifts without moving v. So later solves reduce the residual by 1e-4
    // (down to round-off, 1e-3 x the absolute tolerance): one Newton
    // iteration, usually. 1e-6 took two and gave the same passes and answer
    // (G1 2x: 124 Newton iterations instead of 171, forces equal to 2e-13);
    // 1e-2 is too loose, and the pressure loop stalls (280).
    double tolIt = tol;
    if (it > 1) {
      assembly_->evaluate(*u_, &f, nullptr);
      tolIt = std::max(std::min(tol, 1e-4 * f.norm2()), 1e-3 * absTolerance_);
    }
    const auto solveStart = Clock::now();
    const NewtonResult r = newton_->solve(*u_, tolIt);
    const double solveSeconds = since(solveStart);
    rec.newton += r.iterations;
    rec.linear += r.linearIterations;
    rec.residual = r.residualNorm;
    rec.augmentations = it;
    if (!opt_.quiet && rank0_ && std::getenv("CAPSTAN_NEWTON_LOG")) {
      std::printf("    newton |R|:");
      for (double n : r.residualHistory) std::printf(" %.3e", n);
      std::printf("  (%d linear; preconditioners built: %d; %.3f s)\n", r.linearIterations,
                  newton_->preconditionerBuilds(), solveSeconds);
    }
    // A later pass may start below what round-off lets Newton reach; a state
    // within the absolute tolerance is as converged as it gets.
    if (!r.converged && !(it > 1 && r.residualNorm <= absTolerance_)) {
      if (std::getenv("CAPSTAN_CHECK_TANGENT")) checkTangent();
      failure = r.failure;
      return false;
    }
    // Refresh p(x), v, contact pressures at the converged state.
    assembly_->evaluate(*u_, &f, nullptr);
    bool met = true, volumeMet = true;
    std::vector<const Effect*> settled;  // plain-updated effects already within tolerance
    for (const auto& e : assembly_->effects()) {
      double v = 0;
      Teuchos::reduceAll(*comm_, Teuchos::REDUCE_MAX, e->constraintViolation(), Teuchos::outArg(v));
      if (e.get() == &assembly_->bricks()) {
        rec.volumeChange = v, volumeMet = v <= e->constraintTolerance();
        if (pressureStep_) pressureStep_->measuredAfterNewton(v);
      }
      if (!opt_.quiet && rank0_ && std::getenv("CAPSTAN_NEWTON_LOG"))
        std::printf("    %s: %.3e (tolerance %.1e)\n", e->constraintName().c_str(), v, e->constraintTolerance());
      if (v <= e->constraintTolerance()) {
        if (rolling_) settled.push_back(e.get());
        continue;
      }
      met = false;
      const auto* contact = dynamic_cast<const ContactEffect*>(e.get());
      if (contact && it >= contact->maxAugmentations()) {
        failure = e->constraintName() + " " + Teuchos::toString(v) + " above its tolerance " +
                  Teuchos::toString(e->constraintTolerance()) + " after " + std::to_string(it) +
                  " augmentations";
        return false;
      }
    }
    if (met) return true;
    if (pressureStep_) {
      // The other multipliers first: the pressure step then re-balances the
      // body under their new values too, so their change does not spoil the
      // volumes it makes exact.
      const std::vector<double> pressureNext = multiplierMap(true);  // at the converged state
      setMultipliers(multiplierMap(false), false, settled);
      if (!volumeMet && !saddlePointPressureStep(t, f, rec))  // no progress: a plain pass instead
        setMultipliers(pressureNext, true);
      continue;
    }
    setMultipliers(mixing.next(multipliers(true), multiplierMap(true)), true);
    // Rolling: contact and friction multipliers within their tolerance stay
    // put. Moving them anyway (points flicker at the tolerance level as they
    // pass through the nip) keeps changing the map the pressure loop's mixing
    // works on, and it stalls. Elsewhere every multiplier moves each pass (a
    // symmetric problem then stays symmetric to round-off).
    setMultipliers(multiplierMap(false), false, settled);
  }
  failure = "augmentation loop did not meet the volume and contact tolerances in " +
            std::to_string(maxOuter) + " iterations";
  return false;
}

bool Run::saddlePointPressureStep(double t, Vector& f, StepRecord& rec) {
  BrickEffect& bricks = assembly_->bricks();
  auto W = newton_->matrix();
  assembly_->evaluate(*u_, &f, W.get());  // the tangent at the converged state
  Vector dx(assembly_->dofMap());
  // Solved until the volume error predicted after the next Newton solve is a
  // third of the volume tolerance (less by the ratio that the last such
  // prediction missed by), or to kPressureStepTolerance and the volume error
  // it leaves is a third of the tolerance, or still far off (PressureStep::solve).
  const double tolerance = kPressureStepTolerance, volumeTarget = kPressureStepVolumeMargin * bricks.constraintTolerance();
  PressureStep::Result step;
  const auto stepStart = Clock::now();
  try {
    step = pressureStep_->solve(*W, newton_->approximateInverse(), f, tolerance, volumeTarget,
                                scene_.solver.get<int>("Max Linear Iterations"), dx, pressureStepDmu_);
  } catch (const std::exception&) {  // e.g. a preconditioner that cannot be built: a plain pass
    return false;
  }
  rec.linear += step.iterations;
  rec.pressureStep += step.iterations;
  if (!opt_.quiet && rank0_ && std::getenv("CAPSTAN_NEWTON_LOG"))
    std::printf("    pressure step: %d GMRES iterations, residual reduced %.2e, volume error left %.2e "
                "(stopped on the prediction after Newton %.2e, target %.2e, %d checks), %d contact rows; %.3f s\n",
                step.iterations, step.reduction, step.volumeResidual, step.volumePredicted, step.predictionTarget,
                step.predictions, step.contactRows, since(stepStart));
  if (!(step.reduction < 1)) return false;
  u_->update(1.0, dx, 1.0);
  assembly_->applyConstraints(*u_, t);
  // Each effect's multipliers move by their part of dmu (contact's back into
  // lambda >= 0: a point the step pulls free is released).
  for (size_t i = 0; i < assembly_->effects().size(); ++i) {
    Effect& e = *assembly_->effects()[i];
    auto mu = e.multipliers();
    auto d = pressureStepDmu_[i];
    if (mu.extent(0) == 0 || d.extent(0) != mu.extent(0)) continue;
    Kokkos::parallel_for(
        "pressure step multipliers", Kokkos::RangePolicy<ExecSpace>(0, mu.extent(0)),
        KOKKOS_LAMBDA(int k) { mu(k) += d(k); });
    e.projectMultipliers();
  }
  return true;
}

std::vector<double> Run::multipliers(bool accelerated) const {
  std::vector<double> out;
  for (const auto& e : assembly_->effects()) {
    if (e->accelerated() != accelerated) continue;
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e->multipliers());
    out.insert(out.end(), h.data(), h.data() + h.size());
  }
  return out;
}

std::vector<double> Run::multiplierMap(bool accelerated) const {
  std::vector<double> out;
  for (const auto& e : assembly_->effects()) {
    if (e->accelerated() != accelerated) continue;
    Kokkos::View<double*> next("next multipliers", e->multipliers().extent(0));
    e->multiplierMap(next);
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), next);
    out.insert(out.end(), h.data(), h.data() + h.size());
  }
  return out;
}

void Run::setMultipliers(const std::vector<double>& values, bool accelerated,
                         const std::vector<const Effect*>& keep) {
  size_t offset = 0;
  for (const auto& e : assembly_->effects()) {
    if (e->accelerated() != accelerated) continue;
    if (std::find(keep.begin(), keep.end(), e.get()) != keep.end()) {
      offset += e->multipliers().extent(0);
      continue;
    }
    auto view = e->multipliers();
    auto h = Kokkos::create_mirror_view(view);
    for (size_t i = 0; i < h.size(); ++i) h(i) = values[offset + i];
    offset += h.size();
    Kokkos::deep_copy(view, h);
    e->projectMultipliers();
  }
}

Run::SolverState Run::saveState() const {
  SolverState m{multipliers(true), multipliers(false), {}};
  for (const auto& e : assembly_->effects()) {
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e->history());
    m.history.insert(m.history.end(), h.data(), h.data() + h.size());
  }
  return m;
}

void Run::restoreState(const SolverState& m) {
  setMultipliers(m.accelerated, true);
  setMultipliers(m.plain, false);
  size_t offset = 0;
  for (const auto& e : assembly_->effects()) {
    auto view = e->history();
    auto h = Kokkos::create_mirror_view(view);
    for (size_t i = 0; i < h.size(); ++i) h(i) = m.history[offset + i];
    offset += h.size();
    Kokkos::deep_copy(view, h);
  }
}

Run::ElementFields Run::elementFields() const {
  auto& bricks = assembly_->bricks();
  Matrix stress;
  Kokkos::View<double*> mises;
  bricks.centroidStress(assembly_->positions(), stress, mises);
  return {Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), stress),
          Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mises),
          Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.pressure)};
}

StateFigures Run::figures() {
  StateFigures s;
  auto& bricks = assembly_->bricks();
  const auto [hs, hm, hp] = elementFields();
  auto hv = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.volume);
  auto hV = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.referenceVolume);
  // Local extrema as (min, -max) pairs so one REDUCE_MIN does all of them.
  std::vector<double> lo(18, 1e300);
  for (size_t e = 0; e < hs.extent(0); ++e) {
    auto upd = [&](int k, double x) {
      lo[2 * k] = std::min(lo[2 * k], x);
      lo[2 * k + 1] = std::min(lo[2 * k + 1], -x);
    };
    for (int k = 0; k < 6; ++k) upd(k, hs(e, k));
    upd(6, hm(e));
    upd(7, hp(e));
    lo[16] = std::min(lo[16], -std::fabs(hv(e) / hV(e) - 1));
  }
  std::vector<double> gl(18);
  Teuchos::reduceAll(*comm_, Teuchos::REDUCE_MIN, 18, lo.data(), gl.data());
  for (int k = 0; k < 6; ++k) s.sMin[k] = gl[2 * k], s.sMax[k] = -gl[2 * k + 1];
  s.vmMin = gl[12], s.vmMax = -gl[13], s.pMin = gl[14], s.pMax = -gl[15];
  s.volumeChange = -gl[16];

  auto ud = u_->getData();
  double md[3] = {0, 0, 0}, gmd[3];
  for (size_t n = 0; n < mesh_.numOwnedNodes; ++n)
    for (int i = 0; i < 3; ++i) md[i] = std::max(md[i], std::fabs(ud[3 * n + i]));
  Teuchos::reduceAll(*comm_, Teuchos::REDUCE_MAX, 3, md, gmd);
  s.maxDisplacement = {gmd[0], gmd[1], gmd[2]};

  for (const auto& face : mesh_.faceNames) {
    double sum[4] = {0, 0, 0, 0}, gsum[4];
    for (int n : mesh_.faceNodes(face)) {
      if (n >= int(mesh_.numOwnedNodes)) continue;
      for (int i = 0; i < 3; ++i) sum[i] += ud[3 * n + i];
      sum[3] += 1;
    }
    Teuchos::reduceAll(*comm_, Teuchos::REDUCE_SUM, 4, sum, gsum);
    s.faceMeans.push_back({face, {gsum[0] / gsum[3], gsum[1] / gsum[3], gsum[2] / gsum[3]}});
  }
  return s;
}

double Run::noSlipAngularVelocity(const RigidCore& core) const {
  if (scene_.mesh.type != "Annulus") return 0;
  for (const auto& c : scene_.capstans) {
    if (c.angularVelocity == 0) continue;
    const auto& b = c.axisDirection;
    const double nb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    const auto& d = core.axisDirection;
    const double along = (d[0] * b[0] + d[1] * b[1] + d[2] * b[2]) / nb;
    return -c.angularVelocity * c.radius * along / scene_.mesh.outerRadius;
  }
  return 0;
}

std::string Run::brakeDiagnosis() const {
  auto brief = [](double x) {
    std::ostringstream o;
    o << x;
    return o.str();
  };
  std::string out;
  if (scene_.mesh.type != "Annulus") return out;
  for (const auto& s : scene_.supports) {
    if (s.type != "Rigid Core" || s.rotation != "Free" || s.torque == 0) continue;
    // Friction at most mu |t_n| everywhere, at most the outer radius from the
    // axis: the nip carries at most sum mu |F| R_outer about the core's axis.
    const double F = std::sqrt(s.force[0] * s.force[0] + s.force[1] * s.force[1] + s.force[2] * s.force[2]);
    double mu = 0;
    for (const auto& c : scene_.capstans) mu += c.frictionLaw == "None" ? 0.0 : c.frictionCoefficient;
    const double capacity = mu * F * scene_.mesh.outerRadius;
    if (std::fabs(s.torque) > capacity)
      out += "; support '" + s.name + "': its Torque " + brief(s.torque) +
             " exceeds what friction in the nip can carry (mu |Force| R = " + brief(mu) + " x " + brief(F) +
             " x " + brief(scene_.mesh.outerRadius) + " = " + brief(capacity) +
             "): there is no quasi-static equilibrium, the roller would stop and the capstan slip";
  }
  return out;
}

void Run::recordStep(StepRecord& rec) {
  const auto reactions = assembly_->constraintReactions();
  std::map<std::string, std::array<double, 3>> byName;
  for (size_t s = 0; s < reactions.size(); ++s)
    byName[assembly_->constraints().supportNames[s]] = reactions[s];
  for (auto* f : assembly_->foundations()) {
    const auto local = f->localForceOnBody();
    double g[3];
    Teuchos::reduceAll(*comm_, Teuchos::REDUCE_SUM, 3, local.data(), g);
    byName[f->name().substr(std::string("foundation:").size())] = {g[0], g[1], g[2]};
  }
  for (const auto& s : scene_.supports) {
    SupportRecord sr;
    sr.name = s.name, sr.force = byName[s.name];
    rec.supports.push_back(sr);
  }
  // Rigid cores: the reactions at the face nodes are the force of the core on
  // the body; angular velocity over the step (formulation: increment / dt).
  for (const auto& core : assembly_->rigidCores()) {
    auto& sr = *std::find_if(rec.supports.begin(), rec.supports.end(),
                             [&](const SupportRecord& x) { return x.name == core.name; });
    sr.core = true;
    sr.force = core.forceOnBody;
    sr.torque = core.torqueOnBody;
    sr.translation = core.translation;
    sr.rotation = core.rotation;
    double before = 0, tBefore = 0;
    if (!steps_.empty()) {
      tBefore = steps_.back().time;
      for (const auto& p : steps_.back().supports)
        if (p.name == core.name) before = p.rotation;
    }
    sr.angularVelocity = (core.rotation - before) / (rec.time - tBefore);
    const double rolling = noSlipAngularVelocity(core);
    sr.hasSpeedRatio = rolling != 0;
    if (sr.hasSpeedRatio) sr.speedRatio = sr.angularVelocity / rolling;
  }
  for (size_t i = 0; i < assembly_->contacts().size(); ++i)
    rec.capstans.push_back(capstanFigures(*assembly_->contacts()[i], assembly_->frictions()[i]));
}

CapstanRecord Run::capstanFigures(const ContactEffect& contact, const FrictionEffect* friction) const {
  CapstanRecord r;
  r.name = contact.name().substr(std::string("contact:").size());
  if (friction) {
    const auto ff = friction->figures();
    double sums[8] = {ff.force[0], ff.force[1], ff.force[2], ff.torque, ff.frictionIntegral,
                      ff.normalIntegral, double(ff.stick), double(ff.slip)}, gs[8];
    Teuchos::reduceAll(*comm_, Teuchos::REDUCE_SUM, 8, sums, gs);
    double ratio = 0;
    Teuchos::reduceAll(*comm_, Teuchos::REDUCE_MAX, ff.maxRatio, Teuchos::outArg(ratio));
    r.friction = true;
    r.force = {gs[0], gs[1], gs[2]};  // the normal contact's share is added below
    r.torque = gs[3];
    r.frictionIntegral = gs[4];
    r.normalIntegral = gs[5];
    r.stick = long(gs[6]);
    r.slip = long(gs[7]);
    r.maxFrictionRatio = ratio;
  }
  // Pass 1: sums and maxima. Pass 2: contact angles about the axis, measured
  // from the direction of the contact's resultant (so the contact arc never
  // straddles the +-pi cut), for the contact width.
  auto fig = contact.figures({0, 0, 0});
  double sums[5] = {fig.force[0], fig.force[1], fig.force[2], fig.torque, fig.area}, gs[5];
  Teuchos::reduceAll(*comm_, Teuchos::REDUCE_SUM, 5, sums, gs);
  double maxima[2] = {fig.maxPenetration, fig.peakPressure}, gm[2];
  Teuchos::reduceAll(*comm_, Teuchos::REDUCE_MAX, 2, maxima, gm);
  long points = 0;
  Teuchos::reduceAll(*comm_, Teuchos::REDUCE_SUM, fig.points, Teuchos::outArg(points));
  for (int i = 0; i < 3; ++i) r.force[i] += gs[i];
  r.torque += gs[3];
  r.area = gs[4];
  r.maxPenetration = gm[0];
  r.peakPressure = gm[1];
  r.points = points;
  // The body pushes the capstan away from itself: the contact lies along -force.
  const auto& b = contact.axisDirection();
  std::array<double, 3> ref{-gs[0], -gs[1], -gs[2]};
  const double along = ref[0] * b[0] + ref[1] * b[1] + ref[2] * b[2];
  for (int i = 0; i < 3; ++i) ref[i] -= along * b[i];
  const double n = std::sqrt(ref[0] * ref[0] + ref[1] * ref[1] + ref[2] * ref[2]);
  if (points > 0 && n > 0) {
    for (double& x : ref) x /= n;
    const auto angles = contact.figures(ref);
    double lo[2] = {angles.angleMin, -angles.angleMax}, glo[2];
    Teuchos::reduceAll(*comm_, Teuchos::REDUCE_MIN, 2, lo, glo);
    r.width = contact.radius() * (-glo[1] - glo[0]);
  }
  return r;
}

void Run::writeFields(int step, double time) {
  if (!writer_) return;
  const auto t = Clock::now();
  const size_t nn = mesh_.numOwnedNodes, ne = mesh_.numElements();
  auto ud = u_->getData();
  std::vector<double> coords(3 * nn);
  Field disp{"displacement", 3, std::vector<double>(3 * nn)};
  for (size_t n = 0; n < nn; ++n)
    for (int i = 0; i < 3; ++i) {
      disp.values[3 * n + i] = ud[3 * n + i];
      coords[3 * n + i] = mesh_.X[3 * n + i] + ud[3 * n + i];
    }
  const auto [hs, hm, hp] = elementFields();
  Field p{"pressure", 1, std::vector<double>(ne)}, vm{"von_mises", 1, std::vector<double>(ne)};
  Field sig{"stress", 6, std::vector<double>(6 * ne)};
  for (size_t e = 0; e < ne; ++e) {
    p.values[e] = hp(e);
    vm.values[e] = hm(e);
    for (int k = 0; k < 6; ++k) sig.values[6 * e + k] = hs(e, k);
  }
  // Contact faces: pressure and traction summed over the capstans, the largest gap.
  const size_t nf = assembly_->contactFaceNodes().size() / 4;
  Field cp{"contact_pressure", 1, std::vector<double>(nf, 0.0)};
  Field gap{"gap", 1, std::vector<double>(nf, -1e300)};
  Field ct{"contact_traction", 3, std::vector<double>(3 * nf, 0.0)};
  const auto& contacts = assembly_->contacts();
  for (size_t c = 0; c < contacts.size(); ++c) {
    std::vector<double> pc, gc, tc;
    contacts[c]->faceFields(pc, gc, tc);
    const auto& index = assembly_->contactFacesOf(c);
    for (size_t f = 0; f < index.size(); ++f) {
      cp.values[index[f]] += pc[f];
      gap.values[index[f]] = std::max(gap.values[index[f]], gc[f]);
      for (int i = 0; i < 3; ++i) ct.values[3 * index[f] + i] += tc[3 * f + i];
    }
  }
  // Friction: traction summed over the capstans, stick and slip point counts.
  Field ft{"friction_traction", 3, std::vector<double>(3 * nf, 0.0)};
  Field stick{"stick_points", 1, std::vector<double>(nf, 0.0)};
  Field slip{"slip_points", 1, std::vector<double>(nf, 0.0)};
  bool anyFriction = false;
  for (size_t c = 0; c < contacts.size(); ++c) {
    const auto* friction = assembly_->frictions()[c];
    if (!friction) continue;
    anyFriction = true;
    std::vector<double> tc, sc, lc;
    friction->faceFields(tc, sc, lc);
    const auto& index = assembly_->contactFacesOf(c);
    for (size_t f = 0; f < index.size(); ++f) {
      for (int i = 0; i < 3; ++i) ft.values[3 * index[f] + i] += tc[3 * f + i];
      stick.values[index[f]] += sc[f];
      slip.values[index[f]] += lc[f];
    }
  }
  std::vector<Field> faceFields;
  if (numContactFaces_ > 0) faceFields = {cp, gap, ct};
  if (anyFriction) faceFields.insert(faceFields.end(), {ft, stick, slip});
  writer_->writeStep(step, time, coords, {disp}, {p, vm, sig}, faceFields);
  outputSeconds_ += since(t);
}

void Run::writeHistory() {
  if (!rank0_) return;
  std::ostringstream out;
  out << "step,time,newton_iterations,linear_iterations,cutbacks,augmentations,residual_norm,"
         "max_abs_volume_change,wall_seconds";
  for (const auto& s : scene_.supports) out << "," << s.name << "_fx," << s.name << "_fy," << s.name << "_fz";
  for (const auto& c : scene_.capstans)
    for (const char* k : {"_fx", "_fy", "_fz", "_max_penetration", "_contact_points"}) out << "," << c.name << k;
  out << "\n";
  for (const auto& r : steps_) {
    out << r.step << "," << json::number(r.time) << "," << r.newton << "," << r.linear << ","
        << r.cutbacks << "," << r.augmentations << "," << json::number(r.residual) << ","
        << json::number(r.volumeChange) << "," << json::number(r.wall);
    for (const auto& s : r.supports)
      for (double x : s.force) out << "," << json::number(x);
    for (const auto& c : r.capstans) {
      for (double x : c.force) out << "," << json::number(x);
      out << "," << json::number(c.maxPenetration) << "," << c.points;
    }
    out << "\n";
  }
  writeAtomically(dir_ / "history.csv", out.str());
}

void Run::writeSummary(bool converged, const std::string& failure) {
  const StateFigures s = figures();
  // Per rank: peak resident memory (Linux reports ru_maxrss in KiB), memory in
  // transparent huge pages now, and page faults so far (src/heap_tunables.hpp).
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  double mine[3] = {double(usage.ru_maxrss) / 1024.0, 0, double(usage.ru_minflt)};
  {
    std::ifstream smaps("/proc/self/smaps_rollup");
    std::string key;
    double kib;
    while (smaps >> key)
      if (key == "AnonHugePages:" && smaps >> kib) mine[1] = kib / 1024.0;
  }
  const int ranks = comm_->getSize();
  std::vector<double> all(3 * ranks);
  Teuchos::gatherAll(*comm_, 3, mine, 3 * ranks, all.data());
  auto perRank = [&](int figure) {
    std::vector<double> v(ranks);
    for (int r = 0; r < ranks; ++r) v[r] = all[3 * r + figure];
    return v;
  };
  const auto peakMiB = perRank(0), hugeMiB = perRank(1), faults = perRank(2);
  if (!rank0_) return;
  using json::Object;
  auto vec = [](const std::array<double, 3>& v) { return json::array({v[0], v[1], v[2]}); };
  auto mm = [](double a, double b) {
    return Object().add("min", json::number(a)).add("max", json::number(b)).str();
  };
  std::string stepList = "[";
  for (size_t i = 0; i < steps_.size(); ++i) {
    const auto& r = steps_[i];
    Object sup;
    for (const auto& sp : r.supports) {
      Object o;
      o.add("force", vec(sp.force));
      if (sp.core)
        o.add("torque", json::number(sp.torque)).add("translation", vec(sp.translation))
            .add("rotation", json::number(sp.rotation)).add("angular_velocity", json::number(sp.angularVelocity));
      if (sp.hasSpeedRatio) o.add("speed_ratio", json::number(sp.speedRatio));
      sup.add(sp.name, o.str());
    }
    Object caps;
    for (const auto& c : r.capstans)
      caps.add(c.name, Object().add("force", vec(c.force))
                           .add("max_penetration", json::number(c.maxPenetration))
                           .add("contact_points", json::number(c.points))
                           .add("stick_points", json::number(c.stick))
                           .add("slip_points", json::number(c.slip))
                           .add("torque", json::number(c.torque))
                           .add("contact_area", json::number(c.area))
                           .add("peak_pressure", json::number(c.peakPressure))
                           .add("contact_width", json::number(c.width))
                           .add("friction", c.friction ? Object()
                                   .add("traction_integral", json::number(c.frictionIntegral))
                                   .add("normal_traction_integral", json::number(c.normalIntegral))
                                   .add("max_traction_ratio", json::number(c.maxFrictionRatio)).str()
                                : "null").str());
    Object o;
    o.add("step", json::number(r.step)).add("time", json::number(r.time))
        .add("newton_iterations", json::number(r.newton))
        .add("linear_iterations", json::number(r.linear))
        .add("pressure_step_iterations", json::number(r.pressureStep))
        .add("cutbacks", json::number(r.cutbacks))
        .add("augmentations", json::number(r.augmentations))
        .add("residual_norm", json::number(r.residual))
        .add("max_abs_volume_change", json::number(r.volumeChange))
        .add("capstans", caps.str())
        .add("supports", sup.str())
        .add("wall_seconds", json::number(r.wall));
    stepList += (i ? ",\n    " : "\n    ") + o.str();
  }
  stepList += "\n  ]";
  const char* comp[6] = {"xx", "yy", "zz", "xy", "yz", "xz"};
  Object stress, faces;
  for (int k = 0; k < 6; ++k) stress.add(comp[k], mm(s.sMin[k], s.sMax[k]));
  for (const auto& f : s.faceMeans) faces.add(f.first, vec(f.second));
  Object fin;
  fin.add("von_mises", mm(s.vmMin, s.vmMax)).add("stress", stress.str())
      .add("pressure", mm(s.pMin, s.pMax))
      .add("max_abs_volume_change", json::number(s.volumeChange))
      .add("max_displacement", vec(s.maxDisplacement))
      .add("node_displacement_mean", faces.str());
  Object effects;
  for (const auto& e : assembly_->effects()) {
    const auto offset = effectOffset_[e->name()];
    effects.add(e->name(), Object().add("launches", json::number(e->launches() + offset.first))
                               .add("seconds", json::number(e->seconds() + offset.second)).str());
  }
  const double total = since(t0_) + timingOffset_[0];
  Object timing;
  timing.add("total", json::number(total))
      .add("assembly", json::number(assembly_->assemblySeconds() + timingOffset_[1]))
      .add("linear_solve", json::number(linearSolveSeconds() + timingOffset_[2]))
      .add("output", json::number(outputSeconds_ + timingOffset_[3]))
      .add("preconditioner_setup", json::number(newton_->preconditionerSeconds() + timingOffset_[4]));
  Object memory;
  memory.add("peak_rss_mib", json::array(peakMiB))
      .add("peak_rss_mib_max", json::number(*std::max_element(peakMiB.begin(), peakMiB.end())))
      .add("huge_pages_mib", json::array(hugeMiB))
      .add("page_faults", json::array(faults));
  Object mesh;
  mesh.add("nodes", json::number(long(mesh_.numGlobalNodes)))
      .add("elements", json::number(long(mesh_.numGlobalElements)))
      .add("dofs", json::number(long(3 * mesh_.numGlobalNodes)))
      .add("contact_faces", json::number(numContactFaces_))
      .add("partition", json::string(partitionName(mesh_.partition)))
      .add("cut_faces", json::number(long(mesh_.numCutFaces)));
  Object top;
  top.add("title", json::string(scene_.title)).add("scene", json::string(scene_.file))
      .add("version", json::string(CAPSTAN_VERSION))
      .add("ranks", json::number(comm_->getSize()))
      .add("converged", converged ? "true" : "false")
      .add("failure", converged ? "null" : json::string(failure))
      .add("mesh", mesh.str()).add("steps", stepList).add("final", fin.str())
      .add("timing", timing.str()).add("memory", memory.str()).add("effects", effects.str());
  writeAtomically(dir_ / "summary.json", top.str() + "\n");
}

void Run::checkOutputDirectory() {
  dir_ = scene_.outputDirectory;
  int dirOk = 1;
  std::string dirError;
  if (rank0_) {
    std::error_code ec;
    fs::create_directories(dir_, ec);
    const fs::path probe = dir_ / ".capstan-write-test";
    std::ofstream test(probe);
    if (ec || !test) {
      dirOk = 0;
      dirError = ec ? ec.message() : "not writable";
    } else {
      test.close();
      fs::remove(probe);
    }
  }
  Teuchos::broadcast(*comm_, 0, &dirOk);
  if (!dirOk)
    throw InputError(scene_.file + ": parameter 'Output/Directory': cannot write to '" +
                     dir_.string() + "'" + (dirError.empty() ? "" : ": " + dirError));
}

FieldLayout Run::fieldLayout() const {
  FieldLayout layout;
  layout.comm = rawComm(comm_);
  long long nodes = (long long)mesh_.numOwnedNodes, elems = (long long)mesh_.numElements();
  MPI_Exscan(&nodes, &layout.nodeOffset, 1, MPI_LONG_LONG, MPI_SUM, layout.comm);
  MPI_Exscan(&elems, &layout.elemOffset, 1, MPI_LONG_LONG, MPI_SUM, layout.comm);
  if (comm_->getRank() == 0) layout.nodeOffset = layout.elemOffset = 0;
  layout.nodesOwned = nodes;
  layout.elemsOwned = elems;
  layout.nodesGlobal = mesh_.numGlobalNodes;
  layout.elemsGlobal = mesh_.numGlobalElements;
  // File index of every overlapped node: owners tell the ranks that share it.
  Tpetra::Vector<> fileId(mesh_.ownedNodeMap), fileIdOverlap(mesh_.overlapNodeMap);
  {
    auto d = fileId.getDataNonConst();
    for (size_t n = 0; n < mesh_.numOwnedNodes; ++n) d[n] = double(layout.nodeOffset + (long long)n);
  }
  fileIdOverlap.doImport(fileId, Tpetra::Import<>(mesh_.ownedNodeMap, mesh_.overlapNodeMap), Tpetra::INSERT);
  auto ids = fileIdOverlap.getData();
  for (int n : mesh_.connectivity) layout.hexConnectivity.push_back((long long)ids[n]);
  // Contact-face grid: the union of the capstans' candidate faces.
  long long faces = (long long)(assembly_->contactFaceNodes().size() / 4);
  MPI_Exscan(&faces, &layout.faceOffset, 1, MPI_LONG_LONG, MPI_SUM, layout.comm);
  if (comm_->getRank() == 0) layout.faceOffset = 0;
  layout.facesOwned = faces;
  layout.facesGlobal = numContactFaces_;
  for (int n : assembly_->contactFaceNodes()) layout.quadConnectivity.push_back((long long)ids[n]);
  return layout;
}

std::vector<long long> Run::entityKeys(const Effect& e, int& perEntity) const {
  auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e.local().dofs);
  perEntity = int(dofs.extent(1) / 3);
  std::vector<long long> keys(dofs.extent(0) * perEntity);
  for (size_t i = 0; i < dofs.extent(0); ++i)
    for (int a = 0; a < perEntity; ++a) keys[i * perEntity + a] = mesh_.nodeGids[dofs(i, 3 * a) / 3];
  return keys;
}

namespace {
std::vector<double> hostValues(const Kokkos::View<double*>& v) {
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  return std::vector<double>(h.data(), h.data() + h.size());
}
}  // namespace

std::string Run::checkpointBytes(int step, double time) const {
  checkpoint::Writer w;
  w.put(std::string(checkpoint::kMagic));
  w.put<int>(comm_->getSize()), w.put<int>(comm_->getRank());
  w.put<int>(step), w.put<double>(time), w.put<double>(scene_.stepSize);
  w.put(scene_.mesh.min), w.put(scene_.mesh.max), w.put(scene_.mesh.cells);
  // Displacement of the owned nodes, by node id.
  std::vector<long long> gids(mesh_.nodeGids.begin(), mesh_.nodeGids.begin() + mesh_.numOwnedNodes);
  auto ud = u_->getData();
  w.put(gids);
  w.put(std::vector<double>(ud.begin(), ud.begin() + 3 * mesh_.numOwnedNodes));
  w.put(std::vector<double>(ud.begin() + 3 * mesh_.numOwnedNodes, ud.end()));  // rigid cores (rank 0)
  // Every effect's multipliers and history, by its entities' node ids.
  const auto& effects = assembly_->effects();
  w.put<int>(int(effects.size()));
  for (const auto& e : effects) {
    int perEntity = 0;
    const auto keys = entityKeys(*e, perEntity);
    w.put(e->name()), w.put<int>(perEntity), w.put(keys);
    w.put(hostValues(e->multipliers()));
    w.put(hostValues(e->history()));
  }
  // Rank 0: the step records, and what the summary adds up over the runs.
  if (rank0_) {
    w.put<int>(int(steps_.size()));
    for (const auto& r : steps_) putRecord(w, r);
    w.put<double>(since(t0_) + timingOffset_[0]);
    w.put<double>(assembly_->assemblySeconds() + timingOffset_[1]);
    w.put<double>(linearSolveSeconds() + timingOffset_[2]);
    w.put<double>(outputSeconds_ + timingOffset_[3]);
    w.put<double>(newton_->preconditionerSeconds() + timingOffset_[4]);
    for (const auto& e : effects) {
      const auto offset = effectOffset_.count(e->name()) ? effectOffset_.at(e->name()) : std::pair<long, double>{};
      w.put<long>(e->launches() + offset.first), w.put<double>(e->seconds() + offset.second);
    }
  }
  return w.bytes();
}

void Run::writeCheckpoint(int step, double time) {
  const auto t = Clock::now();
  const fs::path root = dir_ / "checkpoint";
  const std::string name = checkpoint::stepName(step);
  const fs::path done = root / name, tmp = root / (name + ".tmp");
  std::string error;
  if (rank0_) {
    try {
      fs::remove_all(tmp);
      fs::create_directories(tmp);
    } catch (const std::exception& e) {
      error = std::string("checkpoint: ") + e.what();
    }
  }
  agreeRuntime(*comm_, error);
  try {
    writeAtomically(tmp / checkpoint::rankFile(comm_->getRank()), checkpointBytes(step, time));
  } catch (const std::exception& e) {
    error = std::string("checkpoint: ") + e.what();
  }
  agreeRuntime(*comm_, error);
  // Every rank's file is there: the rename publishes the checkpoint at once,
  // then the older ones go (a restart takes the newest complete one).
  if (rank0_) {
    try {
      fs::remove_all(done);
      fs::rename(tmp, done);
      for (const auto& entry : fs::directory_iterator(root))
        if (entry.path() != done) fs::remove_all(entry.path());
    } catch (const std::exception& e) {
      error = std::string("checkpoint: ") + e.what();
    }
  }
  agreeRuntime(*comm_, error);
  outputSeconds_ += since(t);
}

void Run::openRestart(Restart& r) {
  const std::string where = scene_.file + ": --restart " + opt_.restart + ": ";
  // Rank 0 picks the checkpoint, so every rank reads the same one.
  std::string dir, error;
  int files = 0;
  if (rank0_) {
    const fs::path found = checkpoint::latest(fs::path(opt_.restart) / "checkpoint");
    if (found.empty()) {
      error = where + "no checkpoint in '" + (fs::path(opt_.restart) / "checkpoint").string() +
              "' (an earlier run of the scene with Output/Checkpoint Every > 0 writes them)";
    } else {
      dir = found.string();
      while (fs::exists(found / checkpoint::rankFile(files))) ++files;
    }
  }
  agreeInput(*comm_, error);
  int length = int(dir.size());
  Teuchos::broadcast(*comm_, 0, &length);
  dir.resize(size_t(length));
  Teuchos::broadcast(*comm_, 0, length, &dir[0]);
  Teuchos::broadcast(*comm_, 0, &files);
  if (files != comm_->getSize())
    throw InputError(where + "the checkpoint '" + dir + "' was written on " + std::to_string(files) +
                     " rank(s); restart it on as many (mpiexec -n " + std::to_string(files) + ")");
  r.dir = dir;
  r.file = r.dir / checkpoint::rankFile(comm_->getRank());
  try {
    std::ifstream in(r.file, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read it");
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    r.in = std::make_unique<checkpoint::Reader>(std::move(bytes));
    auto& rd = *r.in;
    if (rd.getString() != checkpoint::kMagic) throw std::runtime_error("not a capstan checkpoint");
    const int ranks = rd.get<int>(), rank = rd.get<int>();
    if (ranks != comm_->getSize() || rank != comm_->getRank())
      throw std::runtime_error("written by rank " + std::to_string(rank) + " of " + std::to_string(ranks));
    r.step = rd.get<int>();
    r.time = rd.get<double>();
    const double dt = rd.get<double>();
    const auto min = rd.get<std::array<double, 3>>(), max = rd.get<std::array<double, 3>>();
    const auto cells = rd.get<std::array<int, 3>>();
    auto shortest = [](double x) {  // 0.01, not 1.00000000000000002e-02
      char buf[32];
      return std::string(buf, std::to_chars(buf, buf + sizeof buf, x).ptr);
    };
    auto text = [&](const auto& a) {
      return "{" + shortest(a[0]) + ", " + shortest(a[1]) + ", " + shortest(a[2]) + "}";
    };
    if (cells != scene_.mesh.cells)
      error = "parameter 'Mesh/Cells': the scene has " + text(scene_.mesh.cells) + ", the checkpoint's mesh " +
              text(cells) + " (a different mesh size)";
    else if (min != scene_.mesh.min || max != scene_.mesh.max)
      error = "parameter 'Mesh/Min', 'Mesh/Max': the scene has " + text(scene_.mesh.min) + " to " +
              text(scene_.mesh.max) + ", the checkpoint " + text(min) + " to " + text(max);
    else if (dt != scene_.stepSize)
      error = "parameter 'Time/Step Size': the scene has " + shortest(scene_.stepSize) +
              ", the checkpoint " + shortest(dt);
    else if (r.step > scene_.steps)
      error = "parameter 'Time/Steps': the scene has " + std::to_string(scene_.steps) +
              " steps, the checkpoint is of step " + std::to_string(r.step);
  } catch (const std::exception& e) {
    error = r.file.string() + ": " + e.what();
  }
  agreeInput(*comm_, error.empty() ? "" : where + error);
}

void Run::restore(Restart& r) {
  std::string error;
  try {
    auto& in = *r.in;
    // Displacement: every owned node's value, found by node id.
    const auto gids = in.getVector<long long>();
    const auto u = in.getVector<double>();
    const auto cores = in.getVector<double>();
    if (gids.size() != mesh_.numOwnedNodes || u.size() != 3 * gids.size())
      throw std::runtime_error("holds " + std::to_string(gids.size()) + " nodes, this rank owns " +
                               std::to_string(mesh_.numOwnedNodes) + " (another mesh, or another Mesh/Partition)");
    std::map<long long, size_t> owned;
    for (size_t n = 0; n < mesh_.numOwnedNodes; ++n) owned[mesh_.nodeGids[n]] = n;
    auto ud = u_->getDataNonConst();
    for (size_t i = 0; i < gids.size(); ++i) {
      const auto it = owned.find(gids[i]);
      if (it == owned.end()) throw std::runtime_error("node " + std::to_string(gids[i]) + " is not owned here");
      for (int c = 0; c < 3; ++c) ud[3 * it->second + c] = u[3 * i + c];
    }
    if (cores.size() != ud.size() - 3 * mesh_.numOwnedNodes)
      throw std::runtime_error("holds " + std::to_string(cores.size()) + " rigid-core values, the scene has " +
                               std::to_string(ud.size() - 3 * mesh_.numOwnedNodes) + " here");
    for (size_t j = 0; j < cores.size(); ++j) ud[3 * mesh_.numOwnedNodes + j] = cores[j];
    // Effects: the same ones, each value put back on its entity by node ids.
    const auto& effects = assembly_->effects();
    std::string have, want;
    for (const auto& e : effects) want += (want.empty() ? "" : ", ") + e->name();
    const int count = in.get<int>();
    std::vector<std::string> names;
    struct Saved {
      int perEntity;
      std::vector<long long> keys;
      std::vector<double> multipliers, history;
    };
    std::vector<Saved> saved;
    for (int i = 0; i < count; ++i) {
      names.push_back(in.getString());
      have += (have.empty() ? "" : ", ") + names.back();
      Saved sv;
      sv.perEntity = in.get<int>();
      sv.keys = in.getVector<long long>();
      sv.multipliers = in.getVector<double>();
      sv.history = in.getVector<double>();
      saved.push_back(std::move(sv));
    }
    if (have != want)
      throw std::runtime_error("holds the effects [" + have + "], the scene runs [" + want +
                               "] (a different set of supports, capstans or friction laws)");
    for (size_t i = 0; i < effects.size(); ++i) {
      auto& e = *effects[i];
      const auto& sv = saved[i];
      int perEntity = 0;
      const auto keys = entityKeys(e, perEntity);
      const size_t entities = perEntity ? keys.size() / perEntity : 0;
      if (perEntity != sv.perEntity || keys.size() != sv.keys.size())
        throw std::runtime_error(e.name() + ": " + std::to_string(sv.keys.size() / std::max(sv.perEntity, 1)) +
                                 " entities, the scene has " + std::to_string(entities));
      std::map<std::vector<long long>, size_t> index;
      for (size_t k = 0; k < entities; ++k)
        index[std::vector<long long>(keys.begin() + k * perEntity, keys.begin() + (k + 1) * perEntity)] = k;
      auto put = [&](Kokkos::View<double*> view, const std::vector<double>& values, const char* what) {
        if (values.size() != view.size())
          throw std::runtime_error(e.name() + ": " + std::to_string(values.size()) + " " + what + ", the scene has " +
                                   std::to_string(view.size()));
        if (view.size() == 0) return;
        const size_t per = view.size() / entities;
        auto h = Kokkos::create_mirror_view(view);
        for (size_t k = 0; k < entities; ++k) {
          const auto it = index.find(
              std::vector<long long>(sv.keys.begin() + k * perEntity, sv.keys.begin() + (k + 1) * perEntity));
          if (it == index.end()) throw std::runtime_error(e.name() + ": an entity the scene does not have");
          for (size_t j = 0; j < per; ++j) h(it->second * per + j) = values[k * per + j];
        }
        Kokkos::deep_copy(view, h);
      };
      put(e.multipliers(), sv.multipliers, "multipliers");
      put(e.history(), sv.history, "history values");
    }
    if (rank0_) {
      const int n = in.get<int>();
      for (int i = 0; i < n; ++i) steps_.push_back(getRecord(in));
      for (double& t : timingOffset_) t = in.get<double>();
      for (const auto& e : effects) {
        const long launches = in.get<long>();
        effectOffset_[e->name()] = {launches, in.get<double>()};
      }
    }
    if (!in.atEnd()) throw std::runtime_error("damaged (data after the end)");
  } catch (const std::exception& e) {
    error = scene_.file + ": --restart " + opt_.restart + ": " + r.file.string() + ": " + e.what();
  }
  agreeInput(*comm_, error);
}

int Run::execute() {
  // Everything that can be wrong with the input is found before anything is
  // written: the ranks, the checkpoint of a restart, then the output directory.
  const auto& m = scene_.mesh;
  const double elements = double(m.cells[0]) * m.cells[1] * m.cells[2];
  if (elements < comm_->getSize())
    throw InputError(scene_.file + ": parameter 'Mesh/Cells': " + Teuchos::toString(elements) +
                     " element(s) for " + std::to_string(comm_->getSize()) +
                     " MPI ranks; every rank needs at least one");
  Restart restart;
  if (!opt_.restart.empty()) openRestart(restart);

  if (m.type == "Annulus")
    generator_ = std::make_unique<AnnulusGenerator>(m.center, m.innerRadius, m.outerRadius, m.length, m.cells,
                                                    m.outerCellRatio, m.fineSector);
  else
    generator_ = std::make_unique<BoxGenerator>(m.min, m.max, m.cells);
  mesh_ = distributeMesh(*generator_, comm_, partitionFor(m.partition, m.cells[2], comm_->getSize()));
  assembly_ = std::make_unique<Assembly>(mesh_, scene_);
  try {
    newton_ = std::make_unique<NewtonSolver>(*assembly_, scene_.solver);
  } catch (const InputError& e) {  // the Solver/NOX or Solver/Stratimikos sublist
    throw InputError(scene_.file + ": " + e.what());
  }
  if (scene_.solver.get<std::string>("Pressure Update") == "Saddle Point") {
    const std::string schur = scene_.solver.get<std::string>("Pressure Step Schur");
    const bool laplacian = schur == "Laplacian" || (schur == "Auto" && newton_->iterative());
    pressureStep_ = std::make_unique<PressureStep>(
        *assembly_, laplacian ? PressureStep::Schur::Laplacian : PressureStep::Schur::Diagonal);
  }
  u_ = rcp(new Vector(assembly_->dofMap()));
  for (const auto& core : assembly_->rigidCores()) rolling_ = rolling_ || core.free[3];
  double size2 = 0;
  for (int d = 0; d < 3; ++d) size2 = std::max(size2, std::pow(m.max[d] - m.min[d], 2));
  forceScale_ = scene_.c * size2;
  absTolerance_ = scene_.solver.get<double>("Newton Absolute Tolerance");
  if (absTolerance_ == 0) absTolerance_ = 1e-13 * forceScale_;
  long localFaces = long(assembly_->contactFaceNodes().size() / 4);
  Teuchos::reduceAll(*comm_, Teuchos::REDUCE_SUM, localFaces, Teuchos::outArg(numContactFaces_));

  if (restart.in) {
    restore(restart);
    // fields.h5 is continued: the earlier run's must be there to append to.
    int found = 1;
    if (rank0_ && scene_.writeFields) found = fs::exists(fs::path(opt_.restart) / "fields.h5") ? 1 : 0;
    Teuchos::broadcast(*comm_, 0, &found);
    if (!found)
      throw InputError(scene_.file + ": --restart " + opt_.restart + ": no fields.h5 there to continue "
                       "(the earlier run had Output/Write Fields = false?)");
  }

  checkOutputDirectory();
  // Checkpoints of an earlier run into this directory do not belong to this
  // one (a restart keeps the one it started from until it writes its own).
  if (rank0_) {
    std::error_code ec;
    for (fs::directory_iterator it(dir_ / "checkpoint", ec), end; !ec && it != end; it.increment(ec))
      if (!restart.in || !fs::equivalent(it->path(), restart.dir, ec)) fs::remove_all(it->path(), ec);
  }

  const int N = scene_.steps;
  const double dt = scene_.stepSize;
  int firstStep = 1;
  double tDone = 0;
  if (restart.in) {
    firstStep = restart.step + 1;
    tDone = restart.time;
    if (scene_.writeFields) {
      // Continue the earlier run's fields.h5 (a copy, when this run writes elsewhere).
      std::string error;
      if (rank0_) {
        std::error_code ec;
        const fs::path from = fs::path(opt_.restart) / "fields.h5", to = dir_ / "fields.h5";
        if (!fs::equivalent(from, to, ec)) fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
        if (ec) error = "cannot copy " + from.string() + " to " + to.string() + ": " + ec.message();
      }
      agreeRuntime(*comm_, error);
    }
    if (!opt_.quiet && rank0_) {
      std::printf("restart from %s: step %d, t=%.4g\n", restart.dir.string().c_str(), restart.step, tDone);
      std::fflush(stdout);
    }
  }
  if (scene_.writeFields) {
    if (restart.in) {
      const FieldLayout layout = fieldLayout();
      try {
        writer_ = std::make_unique<FieldWriter>(dir_.string(), layout, FieldWriter::Append{restart.step});
      } catch (const std::exception& e) {
        throw InputError(scene_.file + ": --restart " + opt_.restart + ": cannot continue fields.h5: " + e.what());
      }
    } else {
      writer_ = std::make_unique<FieldWriter>(dir_.string(), fieldLayout());
    }
  }

  assembly_->setInterval(tDone, tDone);
  assembly_->evaluate(*u_, nullptr, nullptr);
  if (!restart.in) writeFields(0, 0.0);
  std::string failure;
  bool ok = true;
  for (int step = firstStep; step <= N && ok; ++step) {
    const auto tStep = Clock::now();
    // A reused preconditioner starts each step afresh, so a run restarted at
    // any step repeats the uninterrupted run's arithmetic exactly.
    newton_->rebuildPreconditioner();
    StepRecord rec;
    rec.step = step;
    rec.time = step * dt;
    // Sub-steps: cut the increment in half on failure, grow it back after success.
    double h = rec.time - tDone;
    // The last written step's state: a failed step's converged sub-steps are
    // not outputs, so the final figures go back to it.
    Vector uStep(*u_, Teuchos::Copy);
    const auto mStep = saveState();
    const double tStep0 = tDone;
    const double hMin = dt / 1024;
    while (tDone < rec.time - 1e-12 * dt) {
      const double tEnd = std::min(tDone + h, rec.time);
      Vector uSaved(*u_, Teuchos::Copy);
      const auto mSaved = saveState();
      std::vector<double> rotationsSaved;
      for (const auto& core : assembly_->rigidCores()) rotationsSaved.push_back(core.rotation);
      std::string why;
      if (solveAt(tDone, tEnd, rec, why)) {
        previous_ = rcp(new Vector(uSaved, Teuchos::Copy));
        tPrevious_ = tDone;
        previousRotation_ = rotationsSaved;
        tDone = tEnd;
        // History (friction) moves on to this converged state; the step's
        // last sub-step commits after the step's figures are taken, which
        // belong to the increment that just converged.
        if (tDone < rec.time - 1e-12 * dt)
          for (const auto& e : assembly_->effects()) e->commit(assembly_->positions());
        h = std::min(2 * h, rec.time - tDone);
        continue;
      }
      u_->update(1.0, uSaved, 0.0);
      restoreState(mSaved);
      ++rec.cutbacks;
      h /= 2;
      if (!opt_.quiet && rank0_)
        std::printf("  step %d: cut back to dt = %.4g (%s)\n", step, h, why.c_str());
      if (h < hMin) {
        failure = "step " + std::to_string(step) + " failed at minimum step size " +
                  Teuchos::toString(hMin) + ": " + why + brakeDiagnosis();
        ok = false;
        u_->update(1.0, uStep, 0.0);
        restoreState(mStep);
        tDone = tStep0;
        assembly_->setInterval(tDone, tDone);
        break;
      }
    }
    if (!ok) break;
    {
      assembly_->applyConstraints(*u_, tDone);  // rigid cores' face nodes where the cores are
      Vector f(u_->getMap());
      assembly_->evaluate(*u_, &f, nullptr);  // reactions at the converged state
    }
    recordStep(rec);
    rec.wall = since(tStep);
    steps_.push_back(rec);
    writeFields(step, rec.time);
    for (const auto& e : assembly_->effects()) e->commit(assembly_->positions());
    writeHistory();
    if (scene_.checkpointEvery > 0 && step % scene_.checkpointEvery == 0) writeCheckpoint(step, tDone);
    if (!opt_.quiet && rank0_) {
      std::printf("step %d/%d  t=%.4g  newton=%d  linear=%d  |R|=%.3e  dV=%.1e  max_penetration=%.3e  %.2fs\n",
                  step, N, rec.time, rec.newton, rec.linear, rec.residual, rec.volumeChange,
                  rec.maxPenetration(), since(t0_) + timingOffset_[0]);
      for (const auto& sr : rec.supports) {
        if (!sr.core) continue;
        std::printf("    %s: rotation=%.5g  omega=%.5g", sr.name.c_str(), sr.rotation, sr.angularVelocity);
        if (sr.hasSpeedRatio) std::printf("  speed_ratio=%.6f", sr.speedRatio);
        std::printf("  force=(%.5g, %.5g, %.5g)  torque=%.4g\n", sr.force[0], sr.force[1], sr.force[2], sr.torque);
      }
      std::fflush(stdout);
    }
  }
  if (!ok) assembly_->evaluate(*u_, nullptr, nullptr);  // final figures: last converged state
  writeHistory();
  writeSummary(ok, failure);
  if (!ok && rank0_) std::fprintf(stderr, "capstan: did not converge: %s\n", failure.c_str());
  return ok ? 0 : 2;
}

}  // namespace

int runScene(const Scene& scene, const RCP<const Comm>& comm, const RunOptions& options) {
  Run run(scene, comm, options);
  return run.execute();
}

}  // namespace capstan
