#include "newton.hpp"

#include <Kokkos_Timer.hpp>
#include <NOX.H>
#include <NOX_Observer.hpp>
#include <NOX_Solver_LineSearchBased.H>
#include <NOX_Thyra.H>
#include <NOX_Thyra_Group.H>
#include <Teuchos_oblackholestream.hpp>
#include <Thyra_DefaultLinearOpSource.hpp>
#include <Thyra_LinearOpWithSolveFactoryHelpers.hpp>
#include <Thyra_StateFuncModelEvaluatorBase.hpp>
#include <Thyra_TpetraThyraWrappers.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "collective.hpp"
#include "errors.hpp"
#include "linear_solver_factories.hpp"
#include "log.hpp"
#include "mumps_solve_factory.hpp"

namespace capstan {

namespace {

// |R| of a state with an inverted element (det F <= 0 at a Gauss point): 1e150
// per dof (Assembly::evaluate); no physical residual comes near.
constexpr double kInvertedResidual = 1e100;

// How far a failed solve got, for its failure: " at |R| a, from b (tolerance c)".
std::string residualsReached(const std::vector<double>& norms, double tolerance) {
  if (norms.empty() || !(norms.back() < kInvertedResidual)) return "";
  return format(" at |R| %.3g, from %.3g (tolerance %.3g)", norms.back(), norms.front(), tolerance);
}

using ConverterT = Thyra::TpetraOperatorVectorExtraction<double>;

// Whether a preconditioner has been built (holds an operator on some side).
bool built(const Thyra::PreconditionerBase<double>& prec) {
  return !prec.getUnspecifiedPrecOp().is_null() || !prec.getRightPrecOp().is_null() ||
         !prec.getLeftPrecOp().is_null();
}

// Times the preconditioner set-up apart from the Krylov iterations (summary.json's timing
// breakdown). With `lagged` a built preconditioner is kept until requestRebuild: Newton's
// matrices change little between iterations, so an old one still serves (LagPolicy below).
class TimedPreconditionerFactory : public Thyra::PreconditionerFactoryBase<double> {
 public:
  TimedPreconditionerFactory(RCP<Thyra::PreconditionerFactoryBase<double>> inner, double& seconds, bool lagged)
      : inner_(inner), seconds_(seconds), lagged_(lagged) {}
  bool isCompatible(const Thyra::LinearOpSourceBase<double>& src) const override { return inner_->isCompatible(src); }
  RCP<Thyra::PreconditionerBase<double>> createPrec() const override { return inner_->createPrec(); }
  void initializePrec(const RCP<const Thyra::LinearOpSourceBase<double>>& src, Thyra::PreconditionerBase<double>* prec,
                      const Thyra::ESupportSolveUse use) const override {
    if (lagged_ && built(*prec) && !rebuild_) return;
    Kokkos::Timer timer;
    inner_->initializePrec(src, prec, use);
    seconds_ += timer.seconds();
    rebuild_ = false;
    ++builds_;
  }
  void uninitializePrec(Thyra::PreconditionerBase<double>* prec, RCP<const Thyra::LinearOpSourceBase<double>>* src,
                        Thyra::ESupportSolveUse* use) const override {
    inner_->uninitializePrec(prec, src, use);
  }
  void setParameterList(const RCP<Teuchos::ParameterList>& p) override { inner_->setParameterList(p); }
  RCP<Teuchos::ParameterList> getNonconstParameterList() override { return inner_->getNonconstParameterList(); }
  RCP<Teuchos::ParameterList> unsetParameterList() override { return inner_->unsetParameterList(); }
  RCP<const Teuchos::ParameterList> getParameterList() const override { return inner_->getParameterList(); }
  RCP<const Teuchos::ParameterList> getValidParameters() const override { return inner_->getValidParameters(); }

  void requestRebuild() { rebuild_ = true; }
  int builds() const { return builds_; }

 private:
  RCP<Thyra::PreconditionerFactoryBase<double>> inner_;
  double& seconds_;
  bool lagged_;
  mutable bool rebuild_ = true;
  mutable int builds_ = 0;
};

// When to rebuild a lagged preconditioner: kept while each Krylov solve's iterations stay within
// `growth` x those of the first solve after the last rebuild + `slack`, and until a solve hits its
// limit; a rebuild costs about as much as a few dozen Krylov iterations (MueLu on G1).
class LagPolicy {
 public:
  LagPolicy(TimedPreconditionerFactory& factory, int maxIterations, double growth, int slack)
      : factory_(factory), maxIterations_(maxIterations), growth_(growth), slack_(slack) {}
  void afterSolve(int iterations) {
    if (factory_.builds() != buildsSeen_) {  // this solve used a fresh preconditioner
      buildsSeen_ = factory_.builds();
      baseline_ = iterations;
    }
    if (iterations >= maxIterations_ || iterations > growth_ * baseline_ + slack_) factory_.requestRebuild();
  }
  // A preconditioner built for the saddle-point step, at the state before it: the
  // step moves the state, so Newton's next solve is no measure of a fresh one (the
  // Hertz ring pressed 400x took that solve's 450 iterations as its baseline, and
  // kept a useless factorisation for ten Newton iterations).
  void builtOutsideNewton() { buildsSeen_ = factory_.builds(); }

 private:
  TimedPreconditionerFactory& factory_;
  int maxIterations_;
  double growth_;
  int slack_;
  int buildsSeen_ = -1;
  int baseline_ = 0;
};

// R(u) and dR/du of the body for NOX, through Thyra.
class BodyModel : public Thyra::StateFuncModelEvaluatorBase<double> {
 public:
  BodyModel(Assembly& assembly, RCP<Thyra::LinearOpWithSolveFactoryBase<double>> lows)
      : assembly_(assembly), lows_(lows) {
    space_ = Thyra::createVectorSpace<double>(assembly.dofMap());
    Thyra::ModelEvaluatorBase::InArgsSetup<double> in;
    in.setModelEvalDescription("capstan body");
    in.setSupports(Thyra::ModelEvaluatorBase::IN_ARG_x);
    inArgs_ = in;
    Thyra::ModelEvaluatorBase::OutArgsSetup<double> out;
    out.setModelEvalDescription("capstan body");
    out.setSupports(Thyra::ModelEvaluatorBase::OUT_ARG_f);
    out.setSupports(Thyra::ModelEvaluatorBase::OUT_ARG_W_op);
    outArgs_ = out;
    nominal_ = in;
  }
  // The initial guess holds the prescribed values on the constrained dofs; Newton moves only
  // the free ones: a loose Krylov solve leaves drift on the constrained rows, whose residual is
  // zero, so Newton would never correct it and the supports would move.
  void setInitialGuess(const RCP<Vector>& u) {
    nominal_.set_x(Thyra::createVector(u, space_));
    if (pinned_.is_null()) {
      pinned_ = rcp(new Vector(u->getMap()));
      trial_ = rcp(new Vector(u->getMap()));
      for (LO d = 0; d < LO(u->getLocalLength()); ++d)
        if (assembly_.ownedConstrained(d)) constrained_.push_back(d);
    }
    pinned_->update(1.0, *u, 0.0);
  }
  // Puts the prescribed values back on u's constrained dofs.
  void pin(Vector& u) const {
    auto to = u.getDataNonConst();
    auto from = pinned_->getData();
    for (LO d : constrained_) to[d] = from[d];
  }
  RCP<const Thyra::VectorSpaceBase<double>> get_x_space() const override { return space_; }
  RCP<const Thyra::VectorSpaceBase<double>> get_f_space() const override { return space_; }
  Thyra::ModelEvaluatorBase::InArgs<double> getNominalValues() const override { return nominal_; }
  Thyra::ModelEvaluatorBase::InArgs<double> createInArgs() const override { return inArgs_; }
  RCP<Thyra::LinearOpBase<double>> create_W_op() const override {
    RCP<Tpetra::Operator<>> op = assembly_.createMatrix();
    return Thyra::createLinearOp(op);
  }
  RCP<const Thyra::LinearOpWithSolveFactoryBase<double>> get_W_factory() const override {
    return lows_;
  }

 private:
  Thyra::ModelEvaluatorBase::OutArgs<double> createOutArgsImpl() const override { return outArgs_; }
  void evalModelImpl(const Thyra::ModelEvaluatorBase::InArgs<double>& in,
                     const Thyra::ModelEvaluatorBase::OutArgs<double>& out) const override {
    trial_->update(1.0, *ConverterT::getConstTpetraVector(in.get_x()), 0.0);
    pin(*trial_);
    const RCP<const Vector> u = trial_;
    RCP<Vector> f = out.get_f().is_null() ? Teuchos::null : ConverterT::getTpetraVector(out.get_f());
    RCP<FEMatrix> W;
    if (!out.get_W_op().is_null())
      W = Teuchos::rcp_dynamic_cast<FEMatrix>(ConverterT::getTpetraOperator(out.get_W_op()), true);
    assembly_.evaluate(*u, f.get(), W.get());
  }

  Assembly& assembly_;
  RCP<Thyra::LinearOpWithSolveFactoryBase<double>> lows_;
  RCP<const Thyra::VectorSpaceBase<double>> space_;
  Thyra::ModelEvaluatorBase::InArgs<double> inArgs_, nominal_;
  Thyra::ModelEvaluatorBase::OutArgs<double> outArgs_;
  RCP<Vector> pinned_, trial_;
  std::vector<LO> constrained_;
};

// Records |R| after every Newton iteration, and tells the lag policy how many
// Krylov iterations each Newton iteration's solve took.
class History : public NOX::Observer {
 public:
  explicit History(LagPolicy* lag = nullptr) : lag_(lag) {}
  std::vector<double> norms, steps;
  void runPreSolve(const NOX::Solver::Generic&) override { norms.clear(), steps.clear(); }
  void runPreIterate(const NOX::Solver::Generic& s) override {
    if (norms.empty() && s.getSolutionGroup().isF()) norms.push_back(s.getSolutionGroup().getNormF());
  }
  void runPostIterate(const NOX::Solver::Generic& s) override {
    norms.push_back(s.getSolutionGroup().getNormF());
    if (const auto* ls = dynamic_cast<const NOX::Solver::LineSearchBased*>(&s)) steps.push_back(ls->getStepSize());
    if (!lag_) return;
    const Teuchos::ParameterList* list = &s.getList();
    for (const char* name : {"Direction", "Newton", "Linear Solver", "Output"}) {
      if (!list->isSublist(name)) return;  // no linear solve yet
      list = &list->sublist(name);
    }
    if (list->isParameter("Last Iteration Count")) lag_->afterSolve(list->get<int>("Last Iteration Count"));
  }

 private:
  LagPolicy* lag_;
};

// Fails a solve whose last `window` iterations all took line-search steps of at
// most 1/8 and did not halve |R|: a tangent that no longer describes the problem
// (near-inverted bricks), where a cut step is cheaper than crawling on to the
// iteration limit. The Hertz ring pressed 400x: two such tries of 28-30 iterations
// at 234 GMRES iterations each before its cut (docs/numerics.md, "Newton's crawl").
class Crawl : public NOX::StatusTest::Generic {
 public:
  explicit Crawl(int window) : window_(window) {}
  NOX::StatusTest::StatusType checkStatus(const NOX::Solver::Generic& s, NOX::StatusTest::CheckType) override {
    if (s.getNumIterations() == 0) norms_.clear(), steps_.clear();
    norms_.push_back(s.getSolutionGroup().getNormF());
    if (s.getNumIterations() > 0)
      if (const auto* ls = dynamic_cast<const NOX::Solver::LineSearchBased*>(&s)) steps_.push_back(ls->getStepSize());
    status_ = NOX::StatusTest::Unconverged;
    const size_t k = steps_.size(), w = size_t(window_);
    if (window_ > 0 && k >= w && norms_.size() == k + 1 &&
        *std::max_element(steps_.end() - w, steps_.end()) <= kCrawlStep && norms_[k] > 0.5 * norms_[k - w])
      status_ = NOX::StatusTest::Failed;
    return status_;
  }
  NOX::StatusTest::StatusType getStatus() const override { return status_; }
  std::ostream& print(std::ostream& o, int indent = 0) const override {
    return o << std::string(indent, ' ') << status_ << "Crawl (" << window_ << " short steps)\n";
  }

 private:
  static constexpr double kCrawlStep = 0.125;
  int window_;
  std::vector<double> norms_, steps_;
  NOX::StatusTest::StatusType status_ = NOX::StatusTest::Unconverged;
};

// Fails a solve whose |R| fell by less than 1 - factor over its last `window` iterations,
// whatever its steps (NewtonSolver::failOnStall).
class Stall : public NOX::StatusTest::Generic {
 public:
  explicit Stall(StallRule rule) : rule_(rule) {}
  NOX::StatusTest::StatusType checkStatus(const NOX::Solver::Generic& s, NOX::StatusTest::CheckType) override {
    if (s.getNumIterations() == 0) norms_.clear();
    norms_.push_back(s.getSolutionGroup().getNormF());
    const size_t k = norms_.size() - 1, w = size_t(rule_.window);
    status_ = k >= w && norms_[k] > rule_.factor * norms_[k - w] ? NOX::StatusTest::Failed
                                                                  : NOX::StatusTest::Unconverged;
    return status_;
  }
  NOX::StatusTest::StatusType getStatus() const override { return status_; }
  std::ostream& print(std::ostream& o, int indent = 0) const override {
    return o << std::string(indent, ' ') << status_ << "Stall (|R| over " << rule_.window << " iterations)\n";
  }

 private:
  StallRule rule_;
  std::vector<double> norms_;
  NOX::StatusTest::StatusType status_ = NOX::StatusTest::Unconverged;
};

// Sets `from`'s parameters in `to` (sublists merged, as ParameterList::setParameters) as entries
// nobody has read yet: the scene reader's reading marked the scene's own (unreadParameters).
void setUnread(const Teuchos::ParameterList& from, Teuchos::ParameterList& to) {
  for (auto it = from.begin(); it != from.end(); ++it) {
    const std::string& name = from.name(it);
    if (from.isSublist(name)) {
      setUnread(from.sublist(name), to.sublist(name));
      continue;
    }
    Teuchos::ParameterEntry fresh;
    fresh.setAnyValue(from.entry(it).getAny(false));
    to.setEntry(name, fresh);
  }
}

// The leaves of `given` (paths below it, from `prefix`) whose copies in `used` nobody read:
// Teuchos marks an entry used when its value is got (getAny(false) does not).
void unreadParameters(const Teuchos::ParameterList& given, const Teuchos::ParameterList& used,
                      const std::string& prefix, std::vector<std::string>& out) {
  for (auto it = given.begin(); it != given.end(); ++it) {
    const std::string& name = given.name(it);
    const auto* entry = used.getEntryPtr(name);
    if (given.isSublist(name)) {
      unreadParameters(given.sublist(name),
                       entry && entry->isList() ? Teuchos::any_cast<Teuchos::ParameterList>(entry->getAny(false))
                                                : Teuchos::ParameterList(),
                       prefix + name + "/", out);
      continue;
    }
    if (!entry || !entry->isUsed()) out.push_back(prefix + name);
  }
}

}  // namespace

struct NewtonSolver::Impl {
  Assembly& assembly;
  SolverSettings solver;
  Teuchos::ParameterList strat;
  RCP<Thyra::LinearOpWithSolveFactoryBase<double>> lows;
  RCP<BodyModel> model;
  // Newton's matrix and preconditioner live as long as the solver: no
  // allocation per solve, and a lagged preconditioner outlives a solve.
  RCP<Thyra::LinearOpBase<double>> W;
  RCP<Thyra::PreconditionerBase<double>> prec;
  RCP<TimedPreconditionerFactory> newtonPrecFactory;  // null for direct solves
  std::unique_ptr<LagPolicy> lag;
  double linearSeconds = 0;
  double preconditionerSeconds = 0;  // part of linearSeconds
  // A solver's exception on one rank alone, made every rank's (or the job's end).
  FailureAgreement agreement;
  StallRule stall;            // off: window 0
  StallRule pseudoTimeStall;  // off: window 0
  bool noxChecked = false;              // the scene's NOX names checked (takeUnreadNoxParameters)
  std::vector<std::string> noxUnread;   // those NOX did not read, until taken
  Impl(Assembly& a, const SolverSettings& s) : assembly(a), solver(s), agreement(a.dofMap()->getComm()) {}

  RCP<Teuchos::ParameterList> noxParameters(const RCP<NOX::Observer>& observer) const {
    auto params = Teuchos::parameterList("NOX");
    params->set("Nonlinear Solver", "Line Search Based");
    auto& lsp = params->sublist("Line Search");
    lsp.set("Method", std::string(nameOf(solver.lineSearch, SolverSettings::lineSearches)));
    // Backtrack halves the step until |R| decreases (an inverted element gives |R| = 1e150); where
    // none does (contact chattering, round-off) the solve fails and the step is cut, with no
    // recovery step: NOX's full one lands in inverted states (docs/numerics.md, "Load steps").
    if (solver.lineSearch == SolverSettings::LineSearch::Backtrack) {
      lsp.sublist("Backtrack").set("Max Iters", 20);
      lsp.sublist("Backtrack").set("Recovery Step", 0.0);
    }
    // Polynomial alike: its recovery step of 1 took H4 under Tanh (mu 1.87,
    // GMRES) from |R| 18 into an inverted state, whose next solve was NaN.
    if (solver.lineSearch == SolverSettings::LineSearch::Polynomial)
      lsp.sublist("Polynomial").set("Recovery Step", 0.0);
    auto& newton = params->sublist("Direction").sublist("Newton");
    newton.sublist("Linear Solver").set("Tolerance", solver.linearTolerance);
    // Eisenstat-Walker (NOX's Type 2): far from the solution a tight Krylov solve is wasted work;
    // eta_k ~ (|R_k|/|R_k-1|)^1.5 keeps Newton superlinear. Not with the LU preconditioner, where
    // loose solves only cost Newton iterations (docs/performance.md, "Defaults and why").
    if (solver.linearToleranceMethod == SolverSettings::ToleranceMethod::Adaptive &&
        solver.preconditioner != SolverSettings::Preconditioner::LU) {
      newton.set("Forcing Term Method", "Type 2");
      newton.set("Forcing Term Minimum Tolerance", solver.linearTolerance);
      // Never looser than 1e-3: with NOX's default ceiling a soft foundation
      // under block-Jacobi ILU (H1 on 2 ranks) crawled at the iteration limit.
      newton.set("Forcing Term Maximum Tolerance",
                 std::max(1e-3, solver.linearTolerance));
    }
    params->sublist("Printing").set("Output Information", 0);
    // NOX writes some notes (e.g. "line search failed") to its output stream
    // whatever the print level; capstan reports the outcome itself.
    params->sublist("Printing").set<RCP<std::ostream>>("Output Stream", rcp(new Teuchos::oblackholestream));
    params->sublist("Solver Options").set<RCP<NOX::Observer>>("Observer", observer);
    setUnread(solver.nox, *params);
    return params;
  }
};

NewtonSolver::NewtonSolver(Assembly& assembly, const SolverSettings& settings)
    : impl_(std::make_unique<Impl>(assembly, settings.resolved(long(assembly.dofMap()->getGlobalNumElements()),
                                                                false, false))) {
  const SolverSettings& solver = impl_->solver;
  impl_->strat = stratimikosList(solver, assembly);
  // The scene's Stratimikos and NOX sublists are checked here, before the run
  // starts: Stratimikos validates its list, and building a NOX solver once
  // checks NOX's choices (solver, direction, line search names).
  try {
    auto factories = linearSolverFactories(impl_->strat);
    impl_->lows = factories.lows;
    auto prec = factories.prec;
    if (!prec.is_null() && impl_->lows->acceptsPreconditionerFactory()) {
      // A solve with a preconditioner of its own (Own) builds one here;
      // Newton's may be kept across iterations (Solver/Preconditioner Reuse).
      impl_->lows->setPreconditionerFactory(
          rcp(new TimedPreconditionerFactory(prec, impl_->preconditionerSeconds, false)), "timed");
      const bool lagged = solver.preconditionerReuse == SolverSettings::Reuse::Adaptive;
      impl_->newtonPrecFactory = rcp(new TimedPreconditionerFactory(prec, impl_->preconditionerSeconds, lagged));
      impl_->prec = impl_->newtonPrecFactory->createPrec();
      if (lagged)
        impl_->lag = std::make_unique<LagPolicy>(*impl_->newtonPrecFactory, solver.maxLinearIterations,
                                                 2.0, 10);
    }
  } catch (const PluginError&) {
    throw;
  } catch (const std::exception& e) {
    // Stratimikos checks the Ifpack2 settings here, where Solver/Ifpack2 went.
    std::string what = e.what();
    what = what.substr(0, what.find("The valid parameters and types are"));  // a page of them
    const bool ifpack2 = solver.ifpack2.numParams() > 0 && what.find("Ifpack2 Settings") != std::string::npos;
    throw InputError(std::string("parameter '") + (ifpack2 ? "Solver/Ifpack2" : "Solver/Stratimikos") +
                     "': " + trilinosMessage(what));
  }
  impl_->model = rcp(new BodyModel(assembly, impl_->lows));
  impl_->W = impl_->model->create_W_op();
  // MueLu and Ifpack2 read their parameters only when a preconditioner is built: a scene that
  // passes its own gets one built now, on the undeformed tangent, so that a bad name or value
  // stops the run before anything is written.
  const auto& strat = solver.stratimikos;
  const bool ownIfpack2 = solver.ifpack2.numParams() > 0 && impl_->strat.get<std::string>("Preconditioner Type", "") == "Ifpack2";
  if (!impl_->newtonPrecFactory.is_null() && (strat.isSublist("Preconditioner Types") || ownIfpack2)) {
    try {
      Vector zero(assembly.dofMap());
      auto K = assembly.createMatrix();
      assembly.evaluate(zero, nullptr, K.get());
      RCP<const Thyra::LinearOpBase<double>> op = Thyra::createConstLinearOp(RCP<const Tpetra::Operator<>>(K));
      auto factory = linearSolverFactories(impl_->strat).prec;
      auto trial = factory->createPrec();
      factory->initializePrec(Thyra::defaultLinearOpSource<double>(op), trial.get());
    } catch (const PluginError&) {
      throw;
    } catch (const std::exception& e) {
      std::string what = e.what();
      what = what.substr(0, what.find("The valid parameters and types are"));  // a page of them
      throw InputError(std::string("parameter '") +
                       (strat.isSublist("Preconditioner Types") ? "Solver/Stratimikos/Preconditioner Types" : "Solver/Ifpack2") +
                       "': " + trilinosMessage(what));
    }
  }
  try {
    auto guess = rcp(new Vector(assembly.dofMap()));
    NOX::Thyra::Vector x0(Thyra::createVector(guess, impl_->model->get_x_space()));
    auto group = rcp(new NOX::Thyra::Group(x0, impl_->model));
    NOX::Solver::buildSolver(group, rcp(new NOX::StatusTest::MaxIters(1)), impl_->noxParameters(rcp(new History)));
  } catch (const std::exception& e) {
    throw InputError("parameter 'Solver/NOX': " + trilinosMessage(e.what()));
  }
}

NewtonSolver::~NewtonSolver() = default;

bool NewtonSolver::keepsFactorisation() const {
  const auto& prec = impl_->prec;
  return impl_->solver.preconditioner == SolverSettings::Preconditioner::LU && !impl_->newtonPrecFactory.is_null() &&
         !prec.is_null() && built(*prec);
}

int NewtonSolver::linearSolve(const Vector& b, Vector& x, double tolerance, Preconditioner preconditioner,
                              int maxIterations) {
  Kokkos::Timer timer;
  RCP<const Thyra::LinearOpBase<double>> W = impl_->W;
  auto space = impl_->model->get_x_space();
  auto bt = Thyra::createConstVector(Teuchos::rcpFromRef(b), space);
  auto xt = Thyra::createVector(Teuchos::rcpFromRef(x), space);
  int iterations = -1;
  std::string failure;  // an exception's, on this rank
  try {  // the factorisation (a direct solver's) happens here, and fails on a singular W
    RCP<Thyra::LinearOpWithSolveBase<double>> lows;
    const bool asBuilt = preconditioner == Preconditioner::KeptAsBuilt && keepsFactorisation();
    if (asBuilt || (preconditioner == Preconditioner::Kept && !impl_->newtonPrecFactory.is_null())) {
      if (!asBuilt)
        impl_->newtonPrecFactory->initializePrec(Thyra::defaultLinearOpSource<double>(W), impl_->prec.get(),
                                                 Thyra::SUPPORT_SOLVE_UNSPECIFIED);
      lows = impl_->lows->createOp();
      impl_->lows->initializePreconditionedOp(Thyra::defaultLinearOpSource<double>(W), impl_->prec, lows.get(),
                                              Thyra::SUPPORT_SOLVE_UNSPECIFIED);
    } else {
      lows = Thyra::linearOpWithSolve(*impl_->lows, W);
    }
    Thyra::SolveCriteria<double> criteria;
    criteria.solveMeasureType = Thyra::SolveMeasureType(Thyra::SOLVE_MEASURE_NORM_RESIDUAL, Thyra::SOLVE_MEASURE_NORM_RHS);
    criteria.requestedTol = tolerance;
    if (maxIterations > 0) {
      criteria.extraParameters = Teuchos::parameterList();
      criteria.extraParameters->set("Maximum Iterations", maxIterations);
    }
    const auto status = Thyra::solve<double>(*lows, Thyra::NOTRANS, *bt, xt.ptr(), Teuchos::constPtr(criteria));
    if (status.solveStatus == Thyra::SOLVE_STATUS_CONVERGED || status.solveStatus == Thyra::SOLVE_STATUS_UNKNOWN)
      iterations = status.extraParameters.is_null() ? 0 : status.extraParameters->get("Iteration Count", 0);
  } catch (const std::exception& e) {
    failure = "linear solver error: " + trilinosMessage(e.what());
  }
  if (!impl_->agreement.agree(failure).empty()) iterations = -1;
  impl_->linearSeconds += timer.seconds();
  return iterations;
}

RCP<FEMatrix> NewtonSolver::matrix() const {
  return Teuchos::rcp_dynamic_cast<FEMatrix>(ConverterT::getTpetraOperator(impl_->W), true);
}

std::function<void(const Vector&, Vector&)> NewtonSolver::approximateInverse(bool afterNewton) {
  auto space = impl_->model->get_x_space();
  double* seconds = &impl_->linearSeconds;
  auto wrap = [space](const Vector& r, Vector& z) {
    // As multivectors: MueLu's Thyra operator takes nothing else.
    using MV = Tpetra::MultiVector<>;
    return std::make_pair(Thyra::createConstMultiVector(Teuchos::rcpFromRef<const MV>(r), space),
                          Thyra::createMultiVector(Teuchos::rcpFromRef<MV>(z), space));
  };
  if (!impl_->newtonPrecFactory.is_null()) {
    Kokkos::Timer timer;
    // Lagged (Preconditioner Reuse = Adaptive): keeps the one Newton built.
    impl_->newtonPrecFactory->initializePrec(Thyra::defaultLinearOpSource<double>(impl_->W), impl_->prec.get(),
                                             Thyra::SUPPORT_SOLVE_UNSPECIFIED);
    if (impl_->lag) impl_->lag->builtOutsideNewton();
    *seconds += timer.seconds();
    RCP<const Thyra::LinearOpBase<double>> op = impl_->prec->getUnspecifiedPrecOp();
    if (op.is_null()) op = impl_->prec->getRightPrecOp();
    if (op.is_null()) op = impl_->prec->getLeftPrecOp();
    if (!op.is_null())
      return [op, wrap](const Vector& r, Vector& z) {
        auto [rt, zt] = wrap(r, z);
        Thyra::apply(*op, Thyra::NOTRANS, *rt, zt.ptr());
      };
  }
  // Newton's last factorisation: its tangent one step from the converged
  // state serves the saddle-point step as well as a new one (the steady drive
  // 36 Newton iterations either way, its 7 steps 51 GMRES iterations against
  // 46, 0.86 against 1.04 s; docs/performance.md, "Defaults and why").
  if (afterNewton) {
    auto mumps = Teuchos::rcp_dynamic_cast<MumpsSolveFactory>(impl_->lows);
    if (!mumps.is_null() && mumps->shared()->solver && mumps->shared()->solver->factored()) {
      auto shared = mumps->shared();
      return [shared](const Vector& r, Vector& z) { shared->solver->solve(r, z); };
    }
  }
  Kokkos::Timer timer;
  RCP<const Thyra::LinearOpBase<double>> W = impl_->W;
  auto lows = Thyra::linearOpWithSolve(*impl_->lows, W);
  *seconds += timer.seconds();
  return [lows, wrap](const Vector& r, Vector& z) {
    auto [rt, zt] = wrap(r, z);
    z.putScalar(0.0);
    Thyra::solve<double>(*lows, Thyra::NOTRANS, *rt, zt.ptr());
  };
}

bool NewtonSolver::iterative() const {
  return !impl_->newtonPrecFactory.is_null() && impl_->solver.preconditioner != SolverSettings::Preconditioner::LU;
}

bool NewtonSolver::direct() const { return impl_->solver.linearSolver == SolverSettings::LinearSolver::Direct; }

int NewtonSolver::preconditionerBuilds() const {
  return impl_->newtonPrecFactory.is_null() ? 0 : impl_->newtonPrecFactory->builds();
}

void NewtonSolver::rebuildPreconditioner() {
  if (!impl_->newtonPrecFactory.is_null()) impl_->newtonPrecFactory->requestRebuild();
}

double NewtonSolver::linearSolveSeconds() const { return impl_->linearSeconds; }
std::string NewtonSolver::agree(const std::string& failure) const { return impl_->agreement.agree(failure); }
double NewtonSolver::preconditionerSeconds() const { return impl_->preconditionerSeconds; }
const Teuchos::ParameterList& NewtonSolver::linearSolverParameters() const { return impl_->strat; }

std::vector<std::string> NewtonSolver::takeUnreadNoxParameters(bool runEnded) {
  if (runEnded && !impl_->noxChecked) {
    impl_->noxChecked = true;
    unreadParameters(impl_->solver.nox, Teuchos::ParameterList(), "", impl_->noxUnread);
  }
  return std::move(impl_->noxUnread);
}

namespace {
// Pseudo-transient continuation (NewtonSolver::pseudoTransient): the first
// pseudo-time step (the diagonal's shift is |diag W| / dtau; 10, 100 and 1000
// gave H4's second step 47-62 iterations with each friction law), the most
// iterations, and where dtau has collapsed (every step blew |R| up).
constexpr double kPseudoTimeStart = 100;
constexpr int kPseudoTimeIterations = 100;
constexpr double kPseudoTimeSmallest = 1e-3;
}  // namespace

NewtonResult NewtonSolver::pseudoTransient(Vector& u, double tolerance, bool growWithFall) {
  Assembly& assembly = impl_->assembly;
  const auto map = u.getMap();
  Vector f(map), dx(map), diag(map), trial(map), previous(map);
  bool hasPrevious = false;
  const RCP<FEMatrix> W = matrix();
  NewtonResult r;
  double dtau = kPseudoTimeStart;
  // 1 on the free rows, 0 on the held ones (their unit diagonal and their
  // positions stay), and where each row's diagonal sits in W's values.
  Kokkos::View<double*> freeRow("free rows", dx.getLocalLength());
  {
    auto h = Kokkos::create_mirror_view(freeRow);
    for (LO i = 0; i < LO(h.extent(0)); ++i) h(i) = assembly.ownedConstrained(i) ? 0.0 : 1.0;
    Kokkos::deep_copy(freeRow, h);
  }
  Kokkos::View<size_t*> diagonalAt("diagonal offsets", dx.getLocalLength());
  {
    Teuchos::ArrayRCP<size_t> offsets;
    W->getLocalDiagOffsets(offsets);
    auto h = Kokkos::create_mirror_view(diagonalAt);
    for (LO i = 0; i < LO(h.extent(0)); ++i) h(i) = offsets[i];
    Kokkos::deep_copy(diagonalAt, h);
  }
  bool valid = assembly.evaluate(u, &f, nullptr);
  double norm = f.norm2();  // collective: every rank
  r.residualHistory.push_back(norm);
  // The lowest |R| after each iteration, for the stall rule.
  std::vector<double> lowest{norm};
  const StallRule stall = impl_->pseudoTimeStall;
  bool stalled = false;
  while (valid && std::isfinite(norm) && norm > tolerance && r.iterations < kPseudoTimeIterations &&
         dtau >= kPseudoTimeSmallest && !stalled) {
    assembly.evaluate(u, &f, W.get());
    // W + |diag W| / dtau on the free rows (a held row's unit diagonal stays).
    W->getLocalDiagCopy(diag);
    {
      auto d = Kokkos::subview(diag.getLocalViewDevice(Tpetra::Access::ReadOnly), Kokkos::ALL(), 0);
      W->beginModify();
      auto local = W->getLocalMatrixDevice();
      auto values = local.values;
      auto rows = local.graph.row_map;
      const double shift = 1 / dtau;
      Kokkos::parallel_for(
          "pseudo-time shift", Kokkos::RangePolicy<ExecSpace>(0, freeRow.extent(0)), KOKKOS_LAMBDA(int i) {
            values(rows(i) + diagonalAt(i)) += freeRow(i) * (d(i) < 0 ? -d(i) : d(i)) * shift;
          });
      Kokkos::fence();
      W->endModify();
    }
    dx.putScalar(0.0);
    const int linear = linearSolve(f, dx, impl_->solver.linearTolerance);
    ++r.iterations;
    if (linear < 0) {  // e.g. a singular shifted tangent: a shorter pseudo-time step
      dtau /= 4;
      continue;
    }
    r.linearIterations += linear;
    {
      auto step = Kokkos::subview(dx.getLocalViewDevice(Tpetra::Access::ReadWrite), Kokkos::ALL(), 0);
      Kokkos::parallel_for(  // the supports stay where u holds them
          "held rows stay", Kokkos::RangePolicy<ExecSpace>(0, freeRow.extent(0)),
          KOKKOS_LAMBDA(int i) { step(i) *= freeRow(i); });
      Kokkos::fence();
    }
    trial.update(1.0, u, -1.0, dx, 0.0);
    const bool trialValid = assembly.evaluate(trial, &f, nullptr);
    const double trialNorm = f.norm2();  // collective: every rank
    // A step into an inverted element, or one that multiplies |R| by 10: not taken.
    if (!trialValid || !std::isfinite(trialNorm) || trialNorm > 10 * norm) {
      dtau /= 4;
      continue;
    }
    r.stepLengths.push_back(dtau);
    // A step that turns back on the last one overshot (the tangent's model
    // switches across a kink, e.g. stick and slip): a shorter pseudo-time step.
    // Otherwise dtau doubles, or grows as |R| falls (switched evolution relaxation): where the
    // force is balanced fast the steps become Newton's sooner (docs/friction.md, "What step 2 is").
    const bool reversed = hasPrevious && dx.dot(previous) < -0.5 * dx.norm2() * previous.norm2();
    dtau *= trialNorm <= 1.5 * norm && !reversed ? std::max(2.0, growWithFall ? norm / trialNorm : 0.0) : 0.5;
    previous.update(1.0, dx, 0.0);
    hasPrevious = true;
    u.update(1.0, trial, 0.0);
    norm = trialNorm;
    r.residualHistory.push_back(norm);
    lowest.push_back(std::min(lowest.back(), norm));
    const size_t w = size_t(stall.window), k = lowest.size() - 1;
    stalled = w > 0 && k >= w && lowest[k] > stall.factor * lowest[k - w];
  }
  r.residualNorm = norm;
  r.converged = valid && std::isfinite(norm) && norm <= tolerance;
  if (!r.converged && r.failure.empty())
    r.failure = std::string(stalled ? format("pseudo-transient continuation stalled (its lowest |R| fell by less than %g%% "
                                             "over %d iterations)", 100 * (1 - stall.factor), stall.window)
                            : r.iterations >= kPseudoTimeIterations ? "pseudo-transient continuation: iteration limit reached"
                                                                    : "pseudo-transient continuation failed") +
                residualsReached(r.residualHistory, tolerance);
  assembly.evaluate(u, nullptr, nullptr);  // the effects' state at u
  return r;
}

void NewtonSolver::failOnStall(StallRule rule) { impl_->stall = rule; }
StallRule NewtonSolver::stallRule() const { return impl_->stall; }
void NewtonSolver::failPseudoTimeOnStall(StallRule rule) { impl_->pseudoTimeStall = rule; }
StallRule NewtonSolver::pseudoTimeStallRule() const { return impl_->pseudoTimeStall; }

NewtonResult NewtonSolver::solve(Vector& u, double tolerance) {
  Kokkos::Timer timer;
  const double assemblyBefore = impl_->assembly.assemblySeconds();
  auto guess = rcp(new Vector(u, Teuchos::Copy));
  impl_->model->setInitialGuess(guess);
  NOX::Thyra::Vector x0(Thyra::createVector(guess, impl_->model->get_x_space()));
  auto group = rcp(new NOX::Thyra::Group(x0, impl_->model, impl_->W, impl_->lows, impl_->prec,
                                         impl_->newtonPrecFactory));

  auto history = rcp(new History(impl_->lag.get()));
  auto params = impl_->noxParameters(history);

  auto normF = rcp(new NOX::StatusTest::NormF(tolerance));
  auto maxIters = rcp(new NOX::StatusTest::MaxIters(impl_->solver.maxNewtonIterations));
  auto finite = rcp(new NOX::StatusTest::FiniteValue);
  auto stagnation = rcp(new NOX::StatusTest::Stagnation(5, 0.999));
  auto crawl = rcp(new Crawl(impl_->solver.crawlIterations));
  auto stall = rcp(new Stall(impl_->stall));
  auto tests = rcp(new NOX::StatusTest::Combo(NOX::StatusTest::Combo::OR));
  tests->addStatusTest(finite);
  tests->addStatusTest(normF);
  tests->addStatusTest(maxIters);
  tests->addStatusTest(stagnation);
  tests->addStatusTest(crawl);
  if (impl_->stall.window > 0) tests->addStatusTest(stall);

  NewtonResult r;
  NOX::StatusTest::StatusType status = NOX::StatusTest::Failed;
  try {
    auto solver = NOX::Solver::buildSolver(group, tests, params);
    status = solver->solve();
    const auto& g = dynamic_cast<const NOX::Thyra::Group&>(solver->getSolutionGroup());
    const auto& x = dynamic_cast<const NOX::Thyra::Vector&>(g.getX());
    auto sol = ConverterT::getConstTpetraVector(x.getThyraRCPVector());
    u.update(1.0, *sol, 0.0);
    impl_->model->pin(u);
    r.iterations = solver->getNumIterations();
    r.residualNorm = g.getNormF();
  } catch (const std::exception& e) {
    r.failure = "nonlinear solver error: " + trilinosMessage(e.what());  // less Teuchos' throw details
    // Belos' CG meets negative curvature: say what that means for the scene.
    if (std::string(e.what()).find("non-positive value for p^H*A*p") != std::string::npos)
      r.failure = "the tangent is not positive definite, which Solver/Linear Solver = CG needs (a rolling core, "
                  "friction or the pressure constraint can make it indefinite): use GMRES or Direct";
    // A step the line search let through into an inverted element leaves a
    // tangent no solver can use.
    else if (!history->norms.empty() && history->norms.back() >= kInvertedResidual)
      r.failure = "a Newton step inverted an element (det F <= 0 at a Gauss point), and the solve from there failed (" +
                  r.failure + ")" +
                  std::string(impl_->solver.lineSearch == SolverSettings::LineSearch::FullStep
                                  ? "; Solver/Line Search = Full Step takes every step whole, Backtrack backs off"
                                  : "");
  }
  r.failure = impl_->agreement.agree(r.failure);
  auto& out = params->sublist("Direction").sublist("Newton").sublist("Linear Solver").sublist("Output");
  r.linearIterations = out.get("Cumulative Iteration Count", 0);
  if (!impl_->noxChecked && r.iterations > 0) {
    impl_->noxChecked = true;
    unreadParameters(impl_->solver.nox, *params, "", impl_->noxUnread);
  }
  r.residualHistory = history->norms;
  r.stepLengths = history->steps;
  r.converged = status == NOX::StatusTest::Converged && r.failure.empty() && std::isfinite(r.residualNorm);
  // A solve that ended at an inverted or non-finite state may have built its
  // kept preconditioner there (NaN entries): the next solve builds its own.
  // (Every retry of the sweep's H4 under Full Step failed on it at once.)
  if (!r.converged &&
      ((!history->norms.empty() && !(history->norms.back() < kInvertedResidual)) || !std::isfinite(r.residualNorm)))
    rebuildPreconditioner();
  if (!r.converged && r.failure.empty()) {
    if (finite->getStatus() == NOX::StatusTest::Failed) r.failure = "residual is not finite (NaN/Inf)";
    else if (maxIters->getStatus() == NOX::StatusTest::Failed) r.failure = "Newton iteration limit reached";
    else if (stagnation->getStatus() == NOX::StatusTest::Failed) r.failure = "Newton stagnated";
    else if (stall->getStatus() == NOX::StatusTest::Failed)
      r.failure = format("Newton stalled (|R| fell by less than %g%% over %d iterations)",
                         100 * (1 - impl_->stall.factor), impl_->stall.window);
    else if (crawl->getStatus() == NOX::StatusTest::Failed)
      r.failure = format("Newton crawled (%d line-search steps of at most 1/8 in a row, |R| not halved)",
                         impl_->solver.crawlIterations);
    else r.failure = "Newton did not converge (line search failed)";
    if (finite->getStatus() != NOX::StatusTest::Failed) r.failure += residualsReached(history->norms, tolerance);
  }
  impl_->linearSeconds += timer.seconds() - (impl_->assembly.assemblySeconds() - assemblyBefore);
  return r;
}

}  // namespace capstan
