#include "mumps_solve_factory.hpp"

#include <Teuchos_StandardParameterEntryValidators.hpp>
#include <Thyra_DefaultLinearOpSource.hpp>
#include <Thyra_DefaultPreconditioner.hpp>
#include <Thyra_LinearOpWithSolveBase.hpp>
#include <Thyra_TpetraThyraWrappers.hpp>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "log.hpp"
#include "solver_switches.hpp"

namespace capstan {

using Teuchos::RCP;
using Teuchos::rcp;

namespace {

using ConverterT = Thyra::TpetraOperatorVectorExtraction<double>;
using Shared = MumpsShared;

// A single factorisation is checked by its probe (MumpsInverseOp::checkSingle):
// above this error a double one is tried, and kept where it errs this much less.
constexpr double kSingleProbeLimit = 1e-2;
constexpr double kDoubleGain = 0.1;

// An operator with its factorisation in the shared solver.
class MumpsLinearOpWithSolve : public Thyra::LinearOpWithSolveBase<double> {
 public:
  explicit MumpsLinearOpWithSolve(std::shared_ptr<Shared> shared) : shared_(std::move(shared)) {}
  ~MumpsLinearOpWithSolve() override {
    if (shared_->factoredFor == this) shared_->factoredFor = nullptr;
  }

  void initialize(const RCP<const Thyra::LinearOpSourceBase<double>>& src) {
    src_ = src;
    op_ = src->getOp();
    matrix_ = Teuchos::rcp_dynamic_cast<const MumpsSolver::CrsMatrix>(ConverterT::getConstTpetraOperator(op_));
    if (matrix_.is_null()) throw std::invalid_argument("MUMPS: the operator is not a Tpetra::CrsMatrix");
    factor();
  }
  RCP<const Thyra::LinearOpSourceBase<double>> release() {
    auto src = src_;
    if (shared_->factoredFor == this) shared_->factoredFor = nullptr;
    src_ = Teuchos::null, op_ = Teuchos::null, matrix_ = Teuchos::null;
    return src;
  }

  RCP<const Thyra::VectorSpaceBase<double>> range() const override { return op_->range(); }
  RCP<const Thyra::VectorSpaceBase<double>> domain() const override { return op_->domain(); }

 protected:
  bool opSupportedImpl(Thyra::EOpTransp t) const override { return Thyra::opSupported(*op_, t); }
  void applyImpl(Thyra::EOpTransp t, const Thyra::MultiVectorBase<double>& X,
                 const Teuchos::Ptr<Thyra::MultiVectorBase<double>>& Y, double alpha, double beta) const override {
    Thyra::apply(*op_, t, X, Y, alpha, beta);
  }
  bool solveSupportsImpl(Thyra::EOpTransp t) const override { return Thyra::real_trans(t) == Thyra::NOTRANS; }
  bool solveSupportsSolveMeasureTypeImpl(Thyra::EOpTransp, const Thyra::SolveMeasureType&) const override {
    return true;  // exact to round-off
  }
  Thyra::SolveStatus<double> solveImpl(Thyra::EOpTransp, const Thyra::MultiVectorBase<double>& B,
                                       const Teuchos::Ptr<Thyra::MultiVectorBase<double>>& X,
                                       const Teuchos::Ptr<const Thyra::SolveCriteria<double>>) const override {
    // Another operator was factored since this one: its values again.
    if (shared_->factoredFor != this) const_cast<MumpsLinearOpWithSolve*>(this)->factor();
    auto b = ConverterT::getConstTpetraMultiVector(Teuchos::rcpFromRef(B));
    auto x = ConverterT::getTpetraMultiVector(Teuchos::rcpFromPtr(X));
    shared_->solver->solve(*b, *x);
    Thyra::SolveStatus<double> status;
    status.solveStatus = Thyra::SOLVE_STATUS_CONVERGED;
    return status;
  }

 private:
  void factor() {
    if (!shared_->solver) shared_->solver = std::make_unique<MumpsSolver>(shared_->options);
    shared_->factoredFor = nullptr;  // until the factorisation succeeds
    shared_->solver->factor(*matrix_);
    shared_->factoredFor = this;
  }

  std::shared_ptr<Shared> shared_;
  RCP<const Thyra::LinearOpSourceBase<double>> src_;
  RCP<const Thyra::LinearOpBase<double>> op_;
  RCP<const MumpsSolver::CrsMatrix> matrix_;
};

// The inverse of the matrix a preconditioner was initialised with, applied by
// MUMPS' triangular solves; refactored if another operator was factored since.
class MumpsInverseOp : public Thyra::LinearOpBase<double> {
 public:
  MumpsInverseOp(std::shared_ptr<Shared> shared, RCP<const Thyra::LinearOpBase<double>> op)
      : shared_(std::move(shared)), op_(std::move(op)) {
    matrix_ = Teuchos::rcp_dynamic_cast<const MumpsSolver::CrsMatrix>(ConverterT::getConstTpetraOperator(op_));
    if (matrix_.is_null()) throw std::invalid_argument("MUMPS: the operator is not a Tpetra::CrsMatrix");
    factor();
  }
  ~MumpsInverseOp() override {
    if (shared_->factoredFor == this) shared_->factoredFor = nullptr;
  }
  RCP<const Thyra::VectorSpaceBase<double>> range() const override { return op_->domain(); }
  RCP<const Thyra::VectorSpaceBase<double>> domain() const override { return op_->range(); }
  const RCP<const Thyra::LinearOpBase<double>>& forward() const { return op_; }

 protected:
  bool opSupportedImpl(Thyra::EOpTransp t) const override { return Thyra::real_trans(t) == Thyra::NOTRANS; }
  void applyImpl(Thyra::EOpTransp, const Thyra::MultiVectorBase<double>& X,
                 const Teuchos::Ptr<Thyra::MultiVectorBase<double>>& Y, double alpha, double beta) const override {
    if (shared_->factoredFor != this) const_cast<MumpsInverseOp*>(this)->factor();
    auto x = ConverterT::getConstTpetraMultiVector(Teuchos::rcpFromRef(X));
    auto y = ConverterT::getTpetraMultiVector(Teuchos::rcpFromPtr(Y));
    MumpsSolver::MultiVector z(y->getMap(), y->getNumVectors());
    shared_->solver->solve(*x, z);
    y->update(alpha, z, beta);  // Y = alpha A^-1 X + beta Y
  }

 private:
  void factor() {
    if (!shared_->solver) shared_->solver = std::make_unique<MumpsSolver>(shared_->options);
    shared_->factoredFor = nullptr;
    shared_->solver->factor(*matrix_);
    if (shared_->options.precision == MumpsOptions::Precision::Single && !shared_->singleConfirmed) checkSingle();
    shared_->factoredFor = this;
  }

  // |M^-1 A v - v| / |v| for a fixed v spread over every dof (A's symmetric
  // part where that is factored): single factors err there by about 6e-8 x
  // A's condition, double ones by 1e-16 x it.
  double probeError() const {
    MumpsSolver::MultiVector v(matrix_->getDomainMap(), 1), Av(matrix_->getRangeMap(), 1), z(matrix_->getDomainMap(), 1);
    {
      auto h = v.getLocalViewHost(Tpetra::Access::OverwriteAll);
      const auto& map = *matrix_->getDomainMap();
      for (size_t i = 0; i < h.extent(0); ++i) h(i, 0) = std::sin(0.7548776662 * double(map.getGlobalElement(i)) + 0.3);
    }
    matrix_->apply(v, Av);
    if (shared_->options.symmetricPart) matrix_->apply(v, Av, Teuchos::TRANS, 0.5, 0.5);  // what is factored
    shared_->solver->solve(Av, z);
    z.update(-1.0, v, 1.0);
    std::vector<double> e(1), n(1);
    z.norm2(e), v.norm2(n);
    return e[0] / n[0];
  }

  // Single factors of a nearly singular matrix (a body held by soft springs)
  // are wrong in its soft modes, and GMRES on them gave Newton directions no
  // line search could use. Where the probe says so and a double factorisation
  // is much closer, double from here on (docs/numerics.md, "Single-precision factors").
  void checkSingle() {
    const double single = probeError();
    if (!(single > kSingleProbeLimit)) return;
    auto singleSolver = std::move(shared_->solver);
    MumpsOptions options = shared_->options;
    options.precision = MumpsOptions::Precision::Double;
    shared_->solver = std::make_unique<MumpsSolver>(options);
    shared_->solver->factor(*matrix_);
    const double dbl = probeError();
    if (dbl < kDoubleGain * single) {
      shared_->options = options;
      solver_switches::note(format("the LU preconditioner's factors in double precision (single erred by %.2g, "
                                   "double by %.2g)", single, dbl));
      if (matrix_->getComm()->getRank() == 0)
        std::fprintf(stderr,
                     "capstan: note: the LU preconditioner's single-precision factors err by %.2g on this tangent "
                     "(double: %.2g), which is nearly singular (a body held by soft supports?): double precision "
                     "from here on\n", single, dbl);
    } else {  // the error is the matrix', not the precision's: no more double tries
      shared_->solver = std::move(singleSolver);
      shared_->singleConfirmed = true;
    }
  }
  std::shared_ptr<Shared> shared_;
  RCP<const Thyra::LinearOpBase<double>> op_;
  RCP<const MumpsSolver::CrsMatrix> matrix_;
};

}  // namespace

// The factories' parameter list into the shared options (the next
// factorisation uses them).
void readMumpsOptions(Teuchos::ParameterList& list, MumpsShared& shared) {
  try {
    shared.options = mumpsOptionsFrom(list);
  } catch (const MumpsParameterError& e) {
    throw std::invalid_argument("MUMPS: '" + e.name + "': " + e.what());
  }
  list.validateParametersAndSetDefaults(*validMumpsOptions(), 0);
  shared.solver.reset();
  shared.factoredFor = nullptr;
  shared.singleConfirmed = false;
}

void MumpsSolveFactory::setParameterList(const RCP<Teuchos::ParameterList>& list) {
  MumpsParameters::setParameterList(list);
  if (shared_->options.precision == MumpsOptions::Precision::Single)
    throw std::invalid_argument(
        "MUMPS: 'Precision' = 'Single' is for the LU preconditioner (Solver/Preconditioner = LU); a direct solve "
        "factorises in Double");
  if (shared_->options.symmetricPart)
    throw std::invalid_argument(
        "MUMPS: 'Symmetric Part' = true is for the LU preconditioner (Solver/Preconditioner = LU); a direct solve "
        "factorises the matrix itself");
}

bool MumpsSolveFactory::isCompatible(const Thyra::LinearOpSourceBase<double>& src) const {
  auto op = ConverterT::getConstTpetraOperator(src.getOp());
  return !Teuchos::rcp_dynamic_cast<const MumpsSolver::CrsMatrix>(op).is_null();
}

RCP<Thyra::LinearOpWithSolveBase<double>> MumpsSolveFactory::createOp() const {
  return rcp(new MumpsLinearOpWithSolve(shared_));
}

void MumpsSolveFactory::initializeOp(const RCP<const Thyra::LinearOpSourceBase<double>>& src,
                                     Thyra::LinearOpWithSolveBase<double>* op, Thyra::ESupportSolveUse) const {
  Teuchos::dyn_cast<MumpsLinearOpWithSolve>(*op).initialize(src);
}

void MumpsSolveFactory::initializePreconditionedOp(const RCP<const Thyra::LinearOpSourceBase<double>>& src,
                                                   const RCP<const Thyra::PreconditionerBase<double>>&,
                                                   Thyra::LinearOpWithSolveBase<double>* op,
                                                   Thyra::ESupportSolveUse use) const {
  initializeOp(src, op, use);
}

void MumpsSolveFactory::uninitializeOp(Thyra::LinearOpWithSolveBase<double>* op,
                                       RCP<const Thyra::LinearOpSourceBase<double>>* src,
                                       RCP<const Thyra::PreconditionerBase<double>>* prec,
                                       RCP<const Thyra::LinearOpSourceBase<double>>* approx,
                                       Thyra::ESupportSolveUse*) const {
  auto released = Teuchos::dyn_cast<MumpsLinearOpWithSolve>(*op).release();
  if (src) *src = released;
  if (prec) *prec = Teuchos::null;
  if (approx) *approx = Teuchos::null;
}

bool MumpsPreconditionerFactory::isCompatible(const Thyra::LinearOpSourceBase<double>& src) const {
  auto op = ConverterT::getConstTpetraOperator(src.getOp());
  return !Teuchos::rcp_dynamic_cast<const MumpsSolver::CrsMatrix>(op).is_null();
}

RCP<Thyra::PreconditionerBase<double>> MumpsPreconditionerFactory::createPrec() const {
  return rcp(new Thyra::DefaultPreconditioner<double>);
}

void MumpsPreconditionerFactory::initializePrec(const RCP<const Thyra::LinearOpSourceBase<double>>& src,
                                                Thyra::PreconditionerBase<double>* prec,
                                                Thyra::ESupportSolveUse) const {
  auto& p = Teuchos::dyn_cast<Thyra::DefaultPreconditioner<double>>(*prec);
  p.uninitialize();  // the old factorisation's operator goes first
  p.initializeUnspecified(RCP<const Thyra::LinearOpBase<double>>(rcp(new MumpsInverseOp(shared_, src->getOp()))));
}

void MumpsPreconditionerFactory::uninitializePrec(Thyra::PreconditionerBase<double>* prec,
                                                  RCP<const Thyra::LinearOpSourceBase<double>>* src,
                                                  Thyra::ESupportSolveUse*) const {
  auto& p = Teuchos::dyn_cast<Thyra::DefaultPreconditioner<double>>(*prec);
  auto op = Teuchos::rcp_dynamic_cast<const MumpsInverseOp>(p.getUnspecifiedPrecOp());
  if (src) *src = op.is_null() ? Teuchos::null : Thyra::defaultLinearOpSource<double>(op->forward());
  p.uninitialize();
}

}  // namespace capstan
