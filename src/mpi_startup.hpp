// Open MPI settings for a fast start, put in the environment before MPI_Init
// reads them (the launcher, drivers/launcher.cpp, and the programs' main()).
// A setting already in the environment (the user's, or mpiexec's) is kept.
//
// Why (docs/performance.md, "Start-up"):
// - A run started without mpiexec is an MPI singleton: by default Open MPI
//   starts a daemon (orted) for it, 0.12 s of every such run. An isolated
//   singleton needs none and can do all capstan does.
// - Open MPI's cm messaging layer opens its network modules (MTLs); the
//   Omni-Path one loads libpsm2, whose constructor sleeps about 0.2 s on a
//   machine without that hardware. Without such a device Open MPI ends with
//   ob1 (shared memory, TCP) anyway: UCX's layer declines without Mellanox
//   devices, after loading UCX's libraries (5 ms of every start). So ob1 is
//   named there; left alone where an Omni-Path or InfiniBand device exists
//   or the user names a layer or an MTL.
// - Isolated singletons all keep their session directory under job family 0
//   (OMPI's tmpdir/ompi.<host>.<uid>/jf.0): one that finishes removes it while
//   another starts, and the starting one's MPI_Init fails ("A call to mkdir
//   was unable to create the desired directory"; 1 in 450 starts of three
//   concurrent loops here, and twice in a day's ctest runs beside other jobs).
//   So each singleton gets a base directory of its own, removed at its exit
//   (a killed run leaves it, as Open MPI leaves its own session directories).
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace capstan {

// This process' own Open MPI tmpdir base (a singleton's; see above).
inline std::string singletonTmpdir() {
  const char* tmp = std::getenv("TMPDIR");
  return std::string(tmp && *tmp ? tmp : "/tmp") + "/capstan-mpi-" + std::to_string(getpid());
}

inline void removeSingletonTmpdir() {
  const char* base = std::getenv("OMPI_MCA_orte_tmpdir_base");
  std::error_code ec;
  if (base && singletonTmpdir() == base) std::filesystem::remove_all(base, ec);
}

inline bool launchedByMpiexec() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK"); }

inline bool fastFabricPresent() { return access("/dev/hfi1_0", F_OK) == 0 || access("/dev/infiniband", F_OK) == 0; }

inline void setMpiStartupDefaults() {
  if (!launchedByMpiexec()) {
    setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
    // The launcher's choice holds across its exec (the same process id).
    const std::string own = singletonTmpdir();
    if (!std::getenv("OMPI_MCA_orte_tmpdir_base") && (mkdir(own.c_str(), 0700) == 0 || errno == EEXIST))
      setenv("OMPI_MCA_orte_tmpdir_base", own.c_str(), 0);
    static bool cleanup = false;  // after main() returns, so after MPI_Finalize
    if (!cleanup && std::getenv("OMPI_MCA_orte_tmpdir_base") && own == std::getenv("OMPI_MCA_orte_tmpdir_base"))
      cleanup = std::atexit(removeSingletonTmpdir) == 0;
  }
  if (!fastFabricPresent() && !std::getenv("OMPI_MCA_mtl")) setenv("OMPI_MCA_pml", "ob1", 0);
}

}  // namespace capstan
