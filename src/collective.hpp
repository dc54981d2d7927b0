// Collective helpers over the run's communicator: errors that every rank
// agrees on (so none is left waiting in a collective call), and the raw MPI
// communicator for HDF5 and MPI_Exscan.
#pragma once

#include <mpi.h>

#include <string>

#include "types.hpp"

namespace capstan {

MPI_Comm rawComm(const RCP<const Comm>& comm);

// The lowest rank with a non-empty `error`, or -1 when no rank has one;
// `error` then holds that rank's message on every rank.
int firstError(const Comm& comm, std::string& error);

// Every rank throws together when any rank has an error: InputError (exit 1)
// or std::runtime_error.
void agreeInput(const Comm& comm, std::string error);
void agreeRuntime(const Comm& comm, std::string error);

// Rank 0's string on every rank.
std::string broadcastString(const Comm& comm, std::string s);

}  // namespace capstan
