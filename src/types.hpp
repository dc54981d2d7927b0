// Tpetra types shared by the whole code (light header: maps only).
#pragma once

#include <Teuchos_Comm.hpp>
#include <Teuchos_RCP.hpp>
#include <Tpetra_Map.hpp>

namespace capstan {

using Teuchos::RCP;
using Teuchos::rcp;
using LO = Tpetra::Map<>::local_ordinal_type;
using GO = Tpetra::Map<>::global_ordinal_type;
using Map = Tpetra::Map<>;
using Comm = Teuchos::Comm<int>;

}  // namespace capstan
