// MUMPS behind Thyra's linear-solver interface, so that NOX's Newton, the
// predictor and the pressure step solve with it exactly as with the Krylov
// solvers (Stratimikos' "Linear Solver Type" = "MUMPS", registered in
// src/newton.cpp). One MumpsSolver serves every operator the factory
// initialises: its analysis is kept while the sparsity pattern holds, and an
// operator factored for another one is refactored before it solves.
#pragma once

#include <Thyra_LinearOpWithSolveFactoryBase.hpp>
#include <Thyra_PreconditionerFactoryBase.hpp>

#include <memory>

#include "direct_solver.hpp"
#include "mumps_parameters.hpp"

namespace capstan {

// What the factories share: one MUMPS instance for every operator they
// initialise, and which operator's values it holds.
struct MumpsShared {
  MumpsOptions options;
  std::unique_ptr<MumpsSolver> solver;  // created on first use
  const void* factoredFor = nullptr;    // the operator whose values are factored
  bool singleConfirmed = false;         // a double factorisation erred as much: single kept, unprobed
};

// The parameters both factories take: validMumpsOptions (mumps_parameters.hpp).
void readMumpsOptions(Teuchos::ParameterList& list, MumpsShared& shared);

template <class Base>
class MumpsParameters : public Base {
 public:
  void setParameterList(const Teuchos::RCP<Teuchos::ParameterList>& list) override {
    readMumpsOptions(*list, *shared_);
    list_ = list;
  }
  Teuchos::RCP<Teuchos::ParameterList> getNonconstParameterList() override { return list_; }
  Teuchos::RCP<Teuchos::ParameterList> unsetParameterList() override {
    auto old = list_;
    list_ = Teuchos::null;
    return old;
  }
  Teuchos::RCP<const Teuchos::ParameterList> getParameterList() const override { return list_; }
  Teuchos::RCP<const Teuchos::ParameterList> getValidParameters() const override { return validMumpsOptions(); }
  // The shared solver (counters, timings, memory).
  const std::shared_ptr<MumpsShared>& shared() const { return shared_; }

 protected:
  std::shared_ptr<MumpsShared> shared_ = std::make_shared<MumpsShared>();
  Teuchos::RCP<Teuchos::ParameterList> list_;
};

class MumpsSolveFactory : public MumpsParameters<Thyra::LinearOpWithSolveFactoryBase<double>> {
 public:
  // As MumpsParameters', and Precision = Single is refused: a direct solve
  // in single precision would give Newton directions to about 1e-7 only.
  void setParameterList(const Teuchos::RCP<Teuchos::ParameterList>& list) override;
  bool isCompatible(const Thyra::LinearOpSourceBase<double>& fwdOpSrc) const override;
  Teuchos::RCP<Thyra::LinearOpWithSolveBase<double>> createOp() const override;
  void initializeOp(const Teuchos::RCP<const Thyra::LinearOpSourceBase<double>>& fwdOpSrc,
                    Thyra::LinearOpWithSolveBase<double>* op, Thyra::ESupportSolveUse use) const override;
  bool supportsPreconditionerInputType(Thyra::EPreconditionerInputType) const override { return false; }
  // A preconditioner is ignored: the factorisation is exact.
  void initializePreconditionedOp(const Teuchos::RCP<const Thyra::LinearOpSourceBase<double>>& fwdOpSrc,
                                  const Teuchos::RCP<const Thyra::PreconditionerBase<double>>& prec,
                                  Thyra::LinearOpWithSolveBase<double>* op,
                                  Thyra::ESupportSolveUse use) const override;
  void uninitializeOp(Thyra::LinearOpWithSolveBase<double>* op,
                      Teuchos::RCP<const Thyra::LinearOpSourceBase<double>>* fwdOpSrc,
                      Teuchos::RCP<const Thyra::PreconditionerBase<double>>* prec,
                      Teuchos::RCP<const Thyra::LinearOpSourceBase<double>>* approxFwdOpSrc,
                      Thyra::ESupportSolveUse* use) const override;
  std::string description() const override { return "capstan::MumpsSolveFactory"; }
};

// A MUMPS factorisation as a preconditioner (Stratimikos' "MUMPS"): GMRES on Newton's matrix with
// an earlier one's LU, kept (Solver/Preconditioner Reuse) since Newton's matrices change little: a
// few iterations of two triangular solves each cost less than a factorisation.
class MumpsPreconditionerFactory : public MumpsParameters<Thyra::PreconditionerFactoryBase<double>> {
 public:
  bool isCompatible(const Thyra::LinearOpSourceBase<double>& fwdOpSrc) const override;
  Teuchos::RCP<Thyra::PreconditionerBase<double>> createPrec() const override;
  void initializePrec(const Teuchos::RCP<const Thyra::LinearOpSourceBase<double>>& fwdOpSrc,
                      Thyra::PreconditionerBase<double>* prec, Thyra::ESupportSolveUse use) const override;
  void uninitializePrec(Thyra::PreconditionerBase<double>* prec,
                        Teuchos::RCP<const Thyra::LinearOpSourceBase<double>>* fwdOpSrc,
                        Thyra::ESupportSolveUse* use) const override;
  std::string description() const override { return "capstan::MumpsPreconditionerFactory"; }
};

}  // namespace capstan
