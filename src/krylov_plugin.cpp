// The krylov plugin (libcapstan_krylov.so): Stratimikos' builder with Ifpack2,
// MueLu and capstan's MUMPS factories registered, for every solver list that
// src/linear_solver_factories.cpp does not build itself. A plugin so that runs
// that never need these libraries never load them (that file says why).
#include <Stratimikos_DefaultLinearSolverBuilder.hpp>
#include <Stratimikos_MueLuHelpers.hpp>
#include <Teuchos_AbstractFactoryStd.hpp>
#include <Ifpack2_Parameters.hpp>
#include <Thyra_Ifpack2PreconditionerFactory.hpp>

#include "linear_solver_factories.hpp"

namespace {

// An int where Ifpack2 takes a double (`--set "Solver/Ifpack2/relaxation:
// damping factor=1"` reads as an int) is read as one, as the scene's own
// parameters are; Ifpack2 refused it ("has the wrong type").
void doublesWhereIfpack2TakesThem(Teuchos::ParameterList& strat) {
  if (!strat.isSublist("Preconditioner Types") || !strat.sublist("Preconditioner Types").isSublist("Ifpack2")) return;
  auto& ifpack2 = strat.sublist("Preconditioner Types").sublist("Ifpack2");
  if (!ifpack2.isSublist("Ifpack2 Settings")) return;
  auto& settings = ifpack2.sublist("Ifpack2 Settings");
  Teuchos::ParameterList valid;
  Ifpack2::getValidParameters(valid);
  for (auto it = settings.begin(); it != settings.end(); ++it) {
    const std::string& name = settings.name(it);
    if (settings.isType<int>(name) && valid.isType<double>(name))
      settings.set(name, double(settings.get<int>(name)));
  }
}

}  // namespace

extern "C" void capstan_build_from_stratimikos(capstan::StratimikosRequest& request) {
  using PrecBase = Thyra::PreconditionerFactoryBase<double>;
  using Ifpack2Factory = Thyra::Ifpack2PreconditionerFactory<Tpetra::CrsMatrix<>>;
  Stratimikos::DefaultLinearSolverBuilder builder;
  builder.setPreconditioningStrategyFactory(Teuchos::abstractFactoryStd<PrecBase, Ifpack2Factory>(), "Ifpack2");
  Stratimikos::enableMueLu(builder);
  builder.setLinearSolveStrategyFactory(request.mumpsSolve, "MUMPS");
  builder.setPreconditioningStrategyFactory(request.mumpsPreconditioner, "MUMPS");
  auto list = Teuchos::rcp(new Teuchos::ParameterList(*request.list));
  doublesWhereIfpack2TakesThem(*list);
  builder.setParameterList(list);
  request.built.lows = builder.createLinearSolveStrategy("");
  request.built.prec = builder.createPreconditioningStrategy("");
}
