#include "collective.hpp"

#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_DefaultMpiComm.hpp>

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "errors.hpp"

namespace capstan {

MPI_Comm rawComm(const RCP<const Comm>& comm) {
  auto mpi = Teuchos::rcp_dynamic_cast<const Teuchos::MpiComm<int>>(comm);
  return mpi.is_null() ? MPI_COMM_SELF : (*mpi->getRawMpiComm())();
}

int firstError(const Comm& comm, std::string& error) {
  const int size = comm.getSize();
  int mine = error.empty() ? size : comm.getRank(), first = size;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, mine, Teuchos::outArg(first));
  if (first == size) return -1;
  int length = int(error.size());
  Teuchos::broadcast(comm, first, &length);
  error.resize(size_t(length));
  if (length > 0) Teuchos::broadcast(comm, first, length, &error[0]);
  return first;
}

void agreeInput(const Comm& comm, std::string error) {
  if (firstError(comm, error) >= 0) throw InputError(error);
}

void agreeRuntime(const Comm& comm, std::string error) {
  if (firstError(comm, error) >= 0) throw std::runtime_error(error);
}

std::string broadcastString(const Comm& comm, std::string s) {
  int length = int(s.size());
  Teuchos::broadcast(comm, 0, &length);
  s.resize(size_t(length));
  if (length > 0) Teuchos::broadcast(comm, 0, length, &s[0]);
  return s;
}

FailureAgreement::FailureAgreement(const RCP<const Comm>& comm) {
  size_ = comm->getSize(), rank_ = comm->getRank();
  if (size_ > 1) MPI_Comm_dup(rawComm(comm), &comm_);
}

FailureAgreement::~FailureAgreement() {
  if (comm_ != MPI_COMM_NULL) MPI_Comm_free(&comm_);
}

std::string FailureAgreement::agree(const std::string& failure, double patience) const {
  if (size_ == 1) return failure;
  int mine = failure.empty() ? size_ : rank_, first = size_;
  MPI_Request request;
  MPI_Iallreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm_, &request);
  if (failure.empty()) {
    MPI_Wait(&request, MPI_STATUS_IGNORE);
  } else {
    const auto start = std::chrono::steady_clock::now();
    for (int done = 0; !done;) {
      MPI_Test(&request, &done, MPI_STATUS_IGNORE);
      if (done) break;
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > patience) {
        std::fprintf(stderr,
                     "capstan: did not converge: %s (on rank %d alone; the other ranks are still inside the "
                     "solver's collective call it left, so the run stops here)\n",
                     failure.c_str(), rank_);
        std::fflush(stderr);
        MPI_Abort(MPI_COMM_WORLD, 2);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  if (first == size_) return "";
  int length = first == rank_ ? int(failure.size()) : 0;
  MPI_Bcast(&length, 1, MPI_INT, first, comm_);
  std::string agreed = first == rank_ ? failure : std::string(size_t(length), ' ');
  if (length > 0) MPI_Bcast(&agreed[0], length, MPI_CHAR, first, comm_);
  return agreed;
}

}  // namespace capstan
