// The krylov plugin (libcapstan_krylov.so): Stratimikos' builder with Ifpack2,
// MueLu and capstan's MUMPS factories registered, for every solver list that
// src/linear_solver_factories.cpp does not build itself. A plugin so that runs
// that never need these libraries never load them (that file says why).
#include <Stratimikos_DefaultLinearSolverBuilder.hpp>
#include <Stratimikos_MueLuHelpers.hpp>
#include <Teuchos_AbstractFactoryStd.hpp>
#include <Thyra_Ifpack2PreconditionerFactory.hpp>

#include "linear_solver_factories.hpp"

extern "C" void capstan_build_from_stratimikos(capstan::StratimikosRequest& request) {
  using PrecBase = Thyra::PreconditionerFactoryBase<double>;
  using Ifpack2Factory = Thyra::Ifpack2PreconditionerFactory<Tpetra::CrsMatrix<>>;
  Stratimikos::DefaultLinearSolverBuilder builder;
  builder.setPreconditioningStrategyFactory(Teuchos::abstractFactoryStd<PrecBase, Ifpack2Factory>(), "Ifpack2");
  Stratimikos::enableMueLu(builder);
  builder.setLinearSolveStrategyFactory(request.mumpsSolve, "MUMPS");
  builder.setPreconditioningStrategyFactory(request.mumpsPreconditioner, "MUMPS");
  builder.setParameterList(Teuchos::rcp(new Teuchos::ParameterList(*request.list)));
  request.built.lows = builder.createLinearSolveStrategy("");
  request.built.prec = builder.createPreconditioningStrategy("");
}
