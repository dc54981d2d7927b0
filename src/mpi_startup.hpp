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
// - Under mpiexec each rank talks to mpiexec's PMIx server over a loopback TCP
//   socket that PMIx (4.2) leaves with Nagle's algorithm on. MPI_Finalize's
//   fence sends small messages while the last one waits for its
//   acknowledgement, which the server delays by 40 ms: every 2-rank run ended
//   44 ms late. So, after MPI_Init, the process' TCP sockets send at once
//   (setTcpNoDelay).
#pragma once

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

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

// After MPI_Init: TCP_NODELAY on every TCP socket this process holds (see
// above); returns how many. Sockets of other kinds and other files are left.
inline int setTcpNoDelay() {
  std::vector<int> open;  // the descriptors (listed first: the listing opens one itself)
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd", ec))
    open.push_back(std::atoi(entry.path().filename().c_str()));
  int count = 0;
  for (int fd : open) {
    int type = 0;
    socklen_t length = sizeof type;
    if (getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &length) != 0 || type != SOCK_STREAM) continue;
    sockaddr_storage address{};
    socklen_t size = sizeof address;
    if (getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) continue;
    if (address.ss_family != AF_INET && address.ss_family != AF_INET6) continue;
    const int on = 1;
    if (setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on) == 0) ++count;
  }
  return count;
}

}  // namespace capstan
