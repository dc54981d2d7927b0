// glibc malloc settings for the whole run: the programs call
// reexecWithHeapTunables(argv) first thing in main().
//
// Why, on the virtual machines capstan runs on (docs/performance.md, "Huge
// pages" and "Page faults"):
// - glibc.malloc.hugetlb=1: the heap in transparent huge pages. A TLB miss
//   costs a nested page walk there, and one assembly streams through every
//   element matrix, its CRS offsets and the matrix values.
// - glibc.malloc.mmap_max=0 and a trim threshold of 64 GiB: freed memory stays
//   with the process. By default glibc gives every block above 32 MiB its own
//   mapping and unmaps it when freed. Each Krylov solve allocates its GMRES
//   basis anew and each MueLu set-up its matrices, so the kernel zeroed fresh
//   pages over and over, at about 1 GB/s here.
//
// How: glibc reads GLIBC_TUNABLES only when a program starts. `capstan` is a
// small launcher (drivers/launcher.cpp) that adds them and starts the solver
// program, capstan-solver; a program started without them (capstan-solver
// itself, capstan_bench) runs itself again, once, with the settings added. A setting the user's
// GLIBC_TUNABLES already names keeps the user's value (glibc.malloc.hugetlb=0
// turns huge pages off). A glibc that lacks a tunable ignores it. Must run
// before MPI starts.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>

#include "mpi_startup.hpp"

namespace capstan {

inline constexpr const char* kHugePagesTunable = "glibc.malloc.hugetlb";

struct HeapTunable {
  const char* name;
  const char* value;
};
inline constexpr HeapTunable kHeapTunables[] = {
    {kHugePagesTunable, "1"},
    {"glibc.malloc.mmap_max", "0"},
    {"glibc.malloc.trim_threshold", "68719476736"},
};

// Adds capstan's tunables to GLIBC_TUNABLES (the user's own settings win);
// returns whether anything was added.
inline bool addHeapTunables() {
  const char* user = std::getenv("GLIBC_TUNABLES");
  std::string value = user ? user : "";
  bool added = false;
  for (const auto& t : kHeapTunables) {
    if (user && std::strstr(user, t.name)) continue;
    value += (value.empty() ? "" : ":") + std::string(t.name) + "=" + t.value;
    added = true;
  }
  return added && setenv("GLIBC_TUNABLES", value.c_str(), 1) == 0;
}

inline void reexecWithHeapTunables(char** argv) {
  setMpiStartupDefaults();  // src/mpi_startup.hpp
  if (addHeapTunables()) execv("/proc/self/exe", argv);  // returns only if it failed: run on with glibc's defaults
}

// Whether this process asked for huge pages (for the programs' reports).
inline bool hugePagesRequested() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const char* setting = tunables ? std::strstr(tunables, kHugePagesTunable) : nullptr;
  return setting && setting[std::strlen(kHugePagesTunable)] == '=' && setting[std::strlen(kHugePagesTunable) + 1] != '0';
}

}  // namespace capstan
