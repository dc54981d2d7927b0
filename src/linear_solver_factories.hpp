// Which linear solver: capstan's Solver settings as a Stratimikos parameter
// list, and the Thyra factories that solve with it.
//
// Why two paths: Stratimikos' builder, Ifpack2 and MueLu pull about 40 more
// shared libraries into the process (Teko, ML, Epetra, AztecOO, Zoltan2, ...),
// and resolving their symbols at start-up costs about 50 ms of every run
// (docs/performance.md, "Start-up"). The lists a direct solve or GMRES with the
// MUMPS preconditioner need (`Linear Solver = Direct`, `Preconditioner = LU`
// or `None`: Auto's choice up to 50,000 unknowns) are built here from the
// factories themselves; every other list (Ifpack2, MueLu, a scene's own
// Stratimikos choices) goes to the builder in the krylov plugin
// (src/krylov_plugin.cpp), loaded the first time one is needed.
#pragma once

#include <Teuchos_AbstractFactory.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Thyra_LinearOpWithSolveFactoryBase.hpp>
#include <Thyra_PreconditionerFactoryBase.hpp>

#include <stdexcept>

namespace capstan {

class Assembly;
struct SolverSettings;

// capstan's solver knobs (Auto resolved) as a Stratimikos list, the scene's
// Solver/Stratimikos sublist applied over them; MueLu's gets the body's
// rigid-body modes (and on several ranks the unknowns' coordinates).
Teuchos::ParameterList stratimikosList(const SolverSettings& solver, const Assembly& assembly);

struct LinearSolverFactories {
  Teuchos::RCP<Thyra::LinearOpWithSolveFactoryBase<double>> lows;  // "Linear Solver Type"
  Teuchos::RCP<Thyra::PreconditionerFactoryBase<double>> prec;     // "Preconditioner Type"; null for None
};

// What the plugin's entry point receives and fills: the list, capstan's MUMPS
// factories (registered in the builder as "MUMPS"), and the factories built.
struct StratimikosRequest {
  const Teuchos::ParameterList* list = nullptr;
  Teuchos::RCP<const Teuchos::AbstractFactory<Thyra::LinearOpWithSolveFactoryBase<double>>> mumpsSolve;
  Teuchos::RCP<const Teuchos::AbstractFactory<Thyra::PreconditionerFactoryBase<double>>> mumpsPreconditioner;
  LinearSolverFactories built;
};
// The plugin's entry point (extern "C", looked up by name).
using BuildFromStratimikos = void (*)(StratimikosRequest&);
constexpr const char* kBuildFromStratimikosName = "capstan_build_from_stratimikos";

// The plugin could not be loaded (an installation problem, not the scene's).
struct PluginError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// True where the list names only MUMPS or Belos with no preconditioner or
// MUMPS', and no other solver's or preconditioner's sublist.
bool builtWithoutStratimikos(const Teuchos::ParameterList& stratimikos);

// The factories for the list; each call builds new ones. Throws the builder's
// or a factory's exception on a bad list, PluginError if the plugin is needed
// and cannot be loaded.
LinearSolverFactories linearSolverFactories(const Teuchos::ParameterList& stratimikos);

}  // namespace capstan
