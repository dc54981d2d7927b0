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

// Whether a step that can fail on some ranks alone (a Trilinos solver's exception) failed anywhere.
// The others would wait in that collective call for good, so a failed rank waits `patience` s, then
// ends the job (MPI_Abort, exit 2). Construct on every rank at once (it duplicates the comm).
class FailureAgreement {
 public:
  explicit FailureAgreement(const RCP<const Comm>& comm);
  ~FailureAgreement();
  FailureAgreement(const FailureAgreement&) = delete;
  FailureAgreement& operator=(const FailureAgreement&) = delete;
  // The lowest failed rank's `failure` on every rank; empty where none failed.
  std::string agree(const std::string& failure, double patience = kPatience) const;
  // Long enough for any rank still in local work (an assembly, a factorisation
  // of its own) to arrive; the time a stuck job takes to end.
  static constexpr double kPatience = 60;

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
};

}  // namespace capstan
