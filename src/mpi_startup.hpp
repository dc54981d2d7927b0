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
#pragma once

#include <unistd.h>

#include <cstdlib>

namespace capstan {

inline bool launchedByMpiexec() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK"); }

inline bool fastFabricPresent() { return access("/dev/hfi1_0", F_OK) == 0 || access("/dev/infiniband", F_OK) == 0; }

inline void setMpiStartupDefaults() {
  if (!launchedByMpiexec()) setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
  if (!fastFabricPresent() && !std::getenv("OMPI_MCA_mtl")) setenv("OMPI_MCA_pml", "ob1", 0);
}

}  // namespace capstan
