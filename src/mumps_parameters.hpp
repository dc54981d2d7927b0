// The MUMPS settings a scene may give in Solver/Stratimikos/Linear Solver
// Types/MUMPS (defined in mumps_solve_factory.cpp, which reads them): kept in
// a light header so that `capstan params` can print them without Thyra.
#pragma once

#include <Teuchos_ParameterList.hpp>
#include <Teuchos_RCP.hpp>

namespace capstan {

// "Ordering" (Auto | Metis | Pord | AMD | AMF | QAMD), "Verbose", "Scaling",
// "Host Only Below", "Nonzero Pattern" (MumpsOptions), with their defaults.
Teuchos::RCP<const Teuchos::ParameterList> validMumpsOptions();

}  // namespace capstan
