#include "steady_rolling.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "effects/steady_friction.hpp"
#include "newton.hpp"
#include "rolling.hpp"
#include "stopwatch.hpp"

namespace capstan {

namespace {

// Tanh and Arctan scenes whose slip speed scale lies below the first stage's by more than this
// ratio start through their own law, its scale falling by this ratio a stage to about the
// scene's, not through friction at the held omega (docs/steady-rolling.md, "Tiny regularisation").
constexpr double kStartStageRatio = 5;
// A start stage that fails is tried again from the last one's answer after a stage halfway (in
// log) between them (the first: after one 5x wider), this many times in a start: large
// indentations then start without cuts (docs/steady-rolling.md, "Large indentation"). With the
// start's quick failures (kStartStall) 2 left the 32 N drive a cut under three of the four
// scale sets measured (495-586 Newton iterations, against 73-81 with 4).
constexpr int kStageRefinements = 4;
// The Tanh stages (and, where Newton's solves are direct, the frictionless footprint) are starting
// guesses: one pass each, a Newton solve and the saddle-point step; with GMRES and a kept LU one
// pass costs Krylov iterations (docs/steady-rolling.md, "Start from rest").
constexpr int kGuessPasses = 1;
// Where the steady state after the Tanh stages fails, it is solved again from their answer with
// Coulomb's stick (eps_t) this much softer than the automatic one, then 3x: high friction then
// converges; as the default it slows the brake sweep (docs/steady-rolling.md, "High friction").
constexpr double kRetryStickSoftening = 10;
// The frictionless footprint's Newton solve fails where |R| has not halved over 3 iterations, and
// goes on in pseudo-time from the linear response: under 4-9x the drive's force Newton crawled
// there for 23-34 iterations (docs/steady-rolling.md, "Large indentation"). Without friction (no
// pseudo-time) a failed solve is tried again without the rule.
constexpr StallRule kFootprintStall{3, 0.5};
// ... and pseudo-time fails there where its lowest |R| has not halved over 20 iterations: under
// 16x-25x the drive's force it cycled (|R| 0.1 <-> 0.5) at the wide contact's edge to its iteration
// limit, where the step's cut to half the force converges (docs/steady-rolling.md, "Large
// indentation").
constexpr StallRule kFootprintPseudoTimeStall{20, 0.5};

// While it lives, the start's tries (its Tanh stages and the steady state with each stick), and a
// continuation step's, fail sooner, since each has a cheaper way on (a stage between, a softer
// stick, friction at the held angular velocity, the start's wider laws): Newton's solves on a
// stall, rather than crawling to the iteration limit, and Coulomb's without the smoothed
// stick/slip corner's retry, which converged in 2 of 12 tries.
// Over the 34 scenes of `scripts/steady-start-scales.py --hard` 1,504 Newton iterations from rest
// against 2,098, the speed ratios within 2e-5 (docs/steady-rolling.md, "Failed tries in the start").
class QuickerFailures {
 public:
  QuickerFailures(NewtonSolver& newton, AugmentationLoop& augmentation)
      : stall_(newton, kStartStall), augmentation_(augmentation), cornerRetryBefore_(augmentation.cornerRetryAllowed()) {
    augmentation_.allowCornerRetry(false);
  }
  ~QuickerFailures() { augmentation_.allowCornerRetry(cornerRetryBefore_); }
  QuickerFailures(const QuickerFailures&) = delete;
  QuickerFailures& operator=(const QuickerFailures&) = delete;
  // |R| fell by less than a fifth over the last 4 iterations. It fails some solves that would
  // converge, where the cheaper way on costs less than their crawl: chosen by the totals over
  // those 34 scenes (1,504 against 1,650 with a tenth over 8, 1,551 with a fifth over 6) and 17
  // others (1,530, 1,664, 1,591; with two stage refinements); a rule of 0.7 over 4 cut the 32 N
  // drive (516 against 75).
  static constexpr StallRule kStartStall{4, 0.8};

 private:
  ScopedStallRule stall_;
  AugmentationLoop& augmentation_;
  bool cornerRetryBefore_;
};

// Pseudo-time behind the start's regularised stages: allowed once the stages between are spent,
// withdrawn when the start ends however it ends.
class RegularisedPseudoTime {
 public:
  explicit RegularisedPseudoTime(AugmentationLoop& augmentation) : augmentation_(augmentation) {}
  ~RegularisedPseudoTime() { augmentation_.allowPseudoTimeOnRegularisedLaws(false); }
  RegularisedPseudoTime(const RegularisedPseudoTime&) = delete;
  RegularisedPseudoTime& operator=(const RegularisedPseudoTime&) = delete;
  void allow() {
    augmentation_.allowPseudoTimeOnRegularisedLaws(true);
    allowed_ = true;
  }
  bool allowed() const { return allowed_; }

 private:
  AugmentationLoop& augmentation_;
  bool allowed_ = false;
};

}  // namespace

SteadyRolling::SteadyRolling(Model& model, Log& log, AugmentationLoop& augmentation, Predictors& predictors,
                             bool started)
    : m_(model), log_(log), augmentation_(augmentation), predictors_(predictors), started_(started) {}

bool SteadyRolling::solve(double t, StepRecord& rec, std::string& failure) {
  const bool wasStarted = started_;
  if (!solveSteadyState(t, rec, failure)) return false;
  failure = rollerTurningBackwards();
  if (failure.empty()) return true;
  started_ = wasStarted;  // the caller restores u: a refused start from rest starts from rest again
  return false;
}

std::string SteadyRolling::rollerTurningBackwards() const {
  // A free roller turns with the capstan's surface: where its surface runs backwards (a negative
  // speed ratio) the nip cannot have carried it, and the state is the mesh's, not the scene's. The
  // drive on 4 cells round with the capstan reversed converged with a speed ratio of -13.8
  // (randomized sweep 12; 8 cells round: 0.967, the shipped mesh 0.987).
  for (const auto& core : m_.assembly->rigidCores()) {
    const double ratio = speedRatio(m_.scene, core, core.angularVelocity);
    if (!core.free[3] || core.holding() || !(ratio < 0)) continue;
    return format("support '%s': the steady state found has the roller's surface running against the capstan's "
                  "(speed ratio %.4g), which no nip carries: the mesh does not resolve the nip (finer Mesh/Cells "
                  "round the ring)", core.name.c_str(), ratio);
  }
  return "";
}

bool SteadyRolling::solveSteadyState(double t, StepRecord& rec, std::string& failure) {
  if (!started_) {
    started_ = startFromRest(t, rec, failure);
    return started_;
  }
  // A continuation step's tries fail fast as the start's do: the first try has the start's
  // wider laws to go on with, and those have the step's cut. The drive's force ramped over two
  // steps to 7x-10x: second steps of 57, 61, 49 and 118 Newton iterations against 192, 308, 149
  // and 268 (the first try had crawled to the iteration limit twice, and the Tanh stages after
  // it too); the steps of the scenes of "The scales" take what they took (docs/steady-rolling.md,
  // "Large indentation").
  const QuickerFailures quicker(*m_.newton, augmentation_);
  const auto before = m_.snapshot();
  if (solveStage(t, "steady state", rec, failure, 0, false)) {
    wideRetryUsed_ = false;
    return true;
  }
  // The last steady state is too far from this one for Coulomb's exact stick
  // to sort stick and slip from: once until a step converges, from it again
  // through the start's wider laws, before the step is cut.
  const auto widened = frictionsStartedWide();
  if (widened.empty() || wideRetryUsed_) return false;
  wideRetryUsed_ = true;
  if (log_.on("newton"))
    log_.event("newton", format("steady rolling: the steady state failed (%s): again through wider laws", failure.c_str()),
               json::Object().add("event", json::string("steady state failed")));
  m_.restore(before);
  std::string why;
  if (startThroughWideLaws(t, widened, rec, why) && steadyStateWithStickRetries(t, widened, rec, why)) {
    wideRetryUsed_ = false;
    return true;
  }
  failure += "; again through wider laws: " + why;
  return false;
}

bool SteadyRolling::startFromRest(double t, StepRecord& rec, std::string& failure) {
  holdCores(true);
  enableFriction(false);
  if (!solveFootprint(t, rec, failure)) return false;
  enableFriction(true);
  const auto widened = frictionsStartedWide();
  if (!widened.empty()) {
    const auto footprint = m_.snapshot();
    std::string why;
    const QuickerFailures quicker(*m_.newton, augmentation_);
    if (startThroughWideLaws(t, widened, rec, why) && steadyStateWithStickRetries(t, widened, rec, why)) return true;
    // Back to the footprint, for the start through friction at the held angular velocity.
    if (log_.on("newton"))
      log_.event("newton", format("steady rolling: the start through wider laws failed (%s): from the footprint again",
                                  why.c_str()),
                 json::Object().add("event", json::string("steady tanh start failed")));
    m_.restore(footprint);
    holdCores(true);
  }
  if (!solveStage(t, "friction at the no-slip angular velocity", rec, failure)) return false;
  holdCores(false);
  return solveStage(t, "steady state", rec, failure);
}

bool SteadyRolling::solveFootprint(double t, StepRecord& rec, std::string& failure) {
  const auto rest = m_.snapshot();
  predictors_.linearResponse(t, rec);
  const int passes = m_.newton->direct() ? kGuessPasses : 0;
  {
    // Where frictions are present a stalled solve goes on in pseudo-time (AugmentationLoop).
    const ScopedStallRule quick(*m_.newton, kFootprintStall, kFootprintPseudoTimeStall);
    if (solveStage(t, "frictionless footprint", rec, failure, passes)) return true;
  }
  // Pseudo-time ran where frictions are present: from rest again would repeat it (under 16x-25x
  // the drive's force 112-115 Newton iterations for nothing), and the step's cut eases the force.
  if (!m_.assembly->frictionsPresent().empty()) return false;
  if (log_.on("newton"))
    log_.event("newton", format("steady rolling: the footprint failed (%s): from rest again", failure.c_str()),
               json::Object().add("event", json::string("footprint failed")));
  m_.restore(rest);
  predictors_.linearResponse(t, rec);
  return solveStage(t, "frictionless footprint", rec, failure, passes);
}

bool SteadyRolling::steadyStateWithStickRetries(double t, const std::vector<SteadyFrictionEffect*>& widened,
                                                StepRecord& rec, std::string& failure) {
  std::vector<SteadyFrictionEffect*> coulomb;
  for (auto* f : widened)
    if (f->augmented()) coulomb.push_back(f);
  const auto afterTanh = m_.snapshot();
  // 0: the scene's stick; then (Coulomb) kRetryStickSoftening and 3x that
  // times the automatic one (softer than the automatic stick, and stiffer
  // than a scene's much softer one).
  const std::vector<double> sticks = coulomb.empty() ? std::vector<double>{0.0}
                                                     : std::vector<double>{0.0, kRetryStickSoftening, 3 * kRetryStickSoftening};
  for (double stick : sticks) {
    for (auto* f : coulomb) f->setStick(stick);
    bool ok = solveStage(t, "steady state", rec, failure);
    for (auto* f : coulomb) f->setStick(0.0);
    // The retry's answer is the scene's too (the multipliers make the stick
    // exact either way); the scene's eps_t from there.
    if (ok && stick != 0.0) ok = solveStage(t, "steady state, the scene's stick", rec, failure);
    if (ok) return true;
    if (log_.on("newton"))
      log_.event("newton",
                 stick == 0.0 ? format("steady rolling: the steady state failed (%s)", failure.c_str())
                              : format("steady rolling: the steady state with the stick %g x the automatic one failed (%s)",
                                       stick, failure.c_str()),
                 json::Object().add("event", json::string("steady state failed")));
    m_.restore(afterTanh);
  }
  return false;
}

std::vector<SteadyFrictionEffect*> SteadyRolling::frictionsStartedWide() const {
  std::vector<SteadyFrictionEffect*> widened;
  for (auto* f : m_.assembly->frictionsPresent()) {
    auto* steady = dynamic_cast<SteadyFrictionEffect*>(f);
    if (!steady) continue;
    const double fraction = steady->sceneSlipFraction();
    if (steady->augmented() || (fraction > 0 && fraction < m_.scene.analysis.startSlipScales[0] / kStartStageRatio))
      widened.push_back(steady);
  }
  return widened;
}

std::vector<double> SteadyRolling::startSlipScales(const std::vector<SteadyFrictionEffect*>& widened) const {
  std::vector<double> scales = m_.scene.analysis.startSlipScales;
  double narrowest = std::numeric_limits<double>::infinity();
  for (auto* f : widened)
    if (!f->augmented()) narrowest = std::min(narrowest, f->sceneSlipFraction());
  while (scales.back() / kStartStageRatio > kStartStageRatio * narrowest / 2)
    scales.push_back(scales.back() / kStartStageRatio);
  return scales;
}

bool SteadyRolling::startThroughWideLaws(double t, const std::vector<SteadyFrictionEffect*>& widened, StepRecord& rec,
                                         std::string& failure) {
  holdCores(false);
  bool ok = true;
  std::vector<double> scales = startSlipScales(widened);
  // Coulomb starts through Tanh; Tanh and Arctan through themselves, wider
  // (asked before the first stage turns Coulomb's effects into Tanh).
  const bool coulomb = std::any_of(widened.begin(), widened.end(), [](auto* f) { return f->augmented(); });
  int refinements = 0;
  RegularisedPseudoTime pseudoTime(augmentation_);
  for (int k = 0; k < int(scales.size()); ++k) {
    const double scale = scales[k];
    int wider = 0;
    for (auto* f : widened) {
      if (!f->augmented() && scale <= f->sceneSlipFraction()) continue;  // not wider than its own
      f->useStartLaw(scale);
      ++wider;
    }
    if (wider == 0) break;
    const auto before = m_.snapshot();
    const std::string stage = format("start: slip speed scale %g x the capstan's (%s)", scale,
                                     coulomb ? "Tanh in Coulomb's place" : "the scene's law, wider");
    ok = solveStage(t, stage.c_str(), rec, failure, kGuessPasses);
    if (ok) continue;
    if (refinements == kStageRefinements) {
      if (pseudoTime.allowed()) break;
      // The stages between spent: this one again, and the rest, with pseudo-time behind each
      // Newton solve (the laws are regularised: the answer does not depend on the path), and
      // as many stages between again. The drive at 10x force stalls at |R| ~ 1e-2 at every
      // scale between 0.015 and 0.004: 874 Newton iterations and 3 cuts before, 139 now (139-164
      // under four scale sets). Pseudo-time behind every stage from the first: 116 there, but
      // 8-22 more on three scenes whose stages between converge (docs/steady-rolling.md,
      // "Large indentation").
      m_.restore(before);
      pseudoTime.allow();
      refinements = 0;
      ok = true;
      --k;
      continue;
    }
    // From the last stage's answer again, through a stage halfway (in log) to
    // this one (the first: from the footprint through a wider one).
    m_.restore(before);
    scales.insert(scales.begin() + k, k == 0 ? scale * kStartStageRatio : std::sqrt(scales[k - 1] * scale));
    ++refinements;
    ok = true;
    --k;
  }
  if (ok) m_.assembly->evaluate(*m_.u, nullptr, nullptr);  // the tractions Coulomb starts from
  for (auto* f : widened) f->useSceneLaw(ok);
  return ok;
}

bool SteadyRolling::solveStage(double t, const char* what, StepRecord& rec, std::string& failure, int passLimit,
                               bool announce) {
  auto& assembly = *m_.assembly;
  assembly.applyConstraints(*m_.u, t);
  // Newton's tolerance relative to the body's force scale c L^2 (the
  // continuation's first residuals say nothing about the answer's size).
  if (log_.on("newton"))
    log_.event("newton", format("steady rolling: %s", what),
               json::Object().add("event", json::string("steady stage")).add("stage", json::string(what)));
  const int newtonBefore = rec.newton;
  const auto start = Clock::now();
  const bool ok = augmentation_.solve(t, m_.forceScale, rec, failure, passLimit);
  if (announce)
    log_.progress(format("  %s: %s, newton=%d, %.2fs", what, ok ? "done" : "failed", rec.newton - newtonBefore,
                         since(start)));
  return ok;
}

void SteadyRolling::holdCores(bool hold) {
  auto& cores = m_.assembly->cores();
  for (size_t c = 0; c < cores.size(); ++c) {
    const auto& core = cores.records()[c];
    if (!core.free[3]) continue;
    cores.holdAngularVelocity(c, hold ? noSlipAngularVelocity(m_.scene, core) : std::numeric_limits<double>::quiet_NaN());
  }
}

void SteadyRolling::enableFriction(bool on) {
  for (auto* f : m_.assembly->frictionsPresent())
    if (auto* steady = dynamic_cast<SteadyFrictionEffect*>(f)) steady->setEnabled(on);
}

}  // namespace capstan
