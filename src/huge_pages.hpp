// Transparent huge pages for the whole heap: the programs call
// reexecWithHugePages(argv) first thing in main().
//
// Why: on the virtual machines capstan runs on, a TLB miss costs a nested
// page walk, and one assembly streams through every element matrix, its CRS
// offsets and the matrix values (G1 4x: ~200 MB in 4 KiB pages). With huge
// pages G1 4x's assembly took 3-5x less time and the whole run 1.45x less on
// 1 rank, and G1 8x 1.31x less on 2 ranks, for under 2% more memory
// (docs/performance.md, "Huge pages").
//
// How: Debian's kernels hand out huge pages only where a program asks
// (transparent_hugepage = madvise); glibc's malloc asks for every heap and
// large block when the tunable glibc.malloc.hugetlb=1 is set, and it reads
// GLIBC_TUNABLES only when a program starts. So the program runs itself
// again, once, with the tunable added. A GLIBC_TUNABLES that already names
// glibc.malloc.hugetlb is left as it is (=0 turns huge pages off). A glibc
// without the tunable (before 2.35) ignores it. Must run before MPI starts.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>

namespace capstan {

inline constexpr const char* kHugePagesTunable = "glibc.malloc.hugetlb";

inline void reexecWithHugePages(char** argv) {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, kHugePagesTunable)) return;
  const std::string on = std::string(kHugePagesTunable) + "=1";
  const std::string value = tunables && *tunables ? std::string(tunables) + ":" + on : on;
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);  // returns only if it failed: run on without huge pages
}

// Whether this process asked for huge pages (for the programs' reports).
inline bool hugePagesRequested() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const char* setting = tunables ? std::strstr(tunables, kHugePagesTunable) : nullptr;
  return setting && setting[std::strlen(kHugePagesTunable)] == '=' && setting[std::strlen(kHugePagesTunable) + 1] != '0';
}

}  // namespace capstan
