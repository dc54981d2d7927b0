// GoogleTest main for tests that use Tpetra/Kokkos: initialises MPI and Kokkos.
#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <cstdlib>

#include "mpi_startup.hpp"

int main(int argc, char** argv) {
  capstan::setMpiStartupDefaults();  // as capstan starts (src/mpi_startup.hpp)
  Tpetra::ScopeGuard scope(&argc, &argv);
  if (capstan::launchedByMpiexec()) capstan::setTcpNoDelay();  // finalize without 40 ms stalls (src/mpi_startup.hpp)
  ::testing::InitGoogleTest(&argc, argv);
  // Only rank 0 prints results.
  if (Tpetra::getDefaultComm()->getRank() != 0 && !std::getenv("CAPSTAN_TEST_ALL_RANKS")) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
