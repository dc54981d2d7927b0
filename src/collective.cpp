#include "collective.hpp"

#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_DefaultMpiComm.hpp>

#include <stdexcept>

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

}  // namespace capstan
