// FailureAgreement on 2 ranks (src/collective.hpp), run by
// tests/integration/failure_agreement.py:
//   stuck: rank 1 fails while rank 0 waits inside a collective call that rank
//          1 never enters (a rank-local exception inside a Trilinos solver):
//          the job must end with exit 2 and rank 1's message, not hang;
//   one:   rank 1 fails, rank 0 does not: both get rank 1's message (exit 0);
//   both:  both fail: both get rank 0's (the lowest failed rank's) message;
//   none:  neither fails: both get an empty message.
#include <Tpetra_Core.hpp>

#include <cstdio>
#include <string>

#include "collective.hpp"
#include "mpi_startup.hpp"

int main(int argc, char** argv) {
  capstan::setMpiStartupDefaults();
  Tpetra::ScopeGuard scope(&argc, &argv);
  auto comm = Tpetra::getDefaultComm();
  const int rank = comm->getRank();
  const std::string mode = argc > 1 ? argv[1] : "";
  capstan::FailureAgreement agreement(comm);
  if (mode == "stuck") {
    if (rank == 1) agreement.agree("injected failure on rank 1", 2.0);  // ends the job
    else MPI_Barrier(MPI_COMM_WORLD);                                   // waits for rank 1 for good
    return 1;
  }
  std::string mine, want;
  if (mode == "one") mine = rank == 1 ? "failure on rank 1" : "", want = "failure on rank 1";
  else if (mode == "both") mine = "failure on rank " + std::to_string(rank), want = "failure on rank 0";
  else if (mode != "none") return 1;
  const std::string got = agreement.agree(mine, 30.0);
  std::printf("rank %d: agreed '%s'\n", rank, got.c_str());
  return got == want ? 0 : 1;
}
