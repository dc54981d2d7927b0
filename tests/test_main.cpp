// GoogleTest main for tests that use Tpetra/Kokkos: initialises MPI and Kokkos.
#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <cstdlib>

int main(int argc, char** argv) {
  Tpetra::ScopeGuard scope(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  // Only rank 0 prints results.
  if (Tpetra::getDefaultComm()->getRank() != 0 && !std::getenv("CAPSTAN_TEST_ALL_RANKS")) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
