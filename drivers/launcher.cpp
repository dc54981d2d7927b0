// `capstan`: sets the environment capstan runs in (glibc's heap tunables:
// src/heap_tunables.hpp; Open MPI's start-up: src/mpi_startup.hpp) and starts capstan-solver,
// the program beside it. Why a launcher: glibc reads its tunables only when a
// program starts, and the solver program loads about 110 shared libraries
// (Trilinos, MPI) before main(); starting it once instead of twice saves
// about 0.1 s of every run (docs/performance.md, "Start-up").
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <string>

#include "../src/heap_tunables.hpp"

int main(int, char** argv) {
  char self[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  std::string solver = "capstan-solver";
  if (n > 0) {
    const std::string path(self, size_t(n));
    solver = path.substr(0, path.rfind('/') + 1) + "capstan-solver";
  }
  capstan::setMpiStartupDefaults();
  capstan::addHeapTunables();
  execv(solver.c_str(), argv);
  std::perror(("capstan: cannot start " + solver).c_str());
  return 1;
}
