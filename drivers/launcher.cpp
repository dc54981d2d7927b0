// `capstan`: sets the environment capstan runs in (glibc's heap tunables:
// src/heap_tunables.hpp; Open MPI's start-up: src/mpi_startup.hpp) and starts capstan-solver,
// the program beside it. Why a launcher: glibc reads its tunables only when a
// program starts, and the solver program loads about 75 shared libraries
// (Trilinos, MPI) before main(); starting it once instead of twice saves
// about 0.1 s of every run (docs/performance.md, "Start-up").
#include <unistd.h>

#include <cstdio>
#include <string>

#include "../src/heap_tunables.hpp"
#include "../src/program_directory.hpp"

int main(int, char** argv) {
  const std::string solver = capstan::programDirectory() + "capstan-solver";
  capstan::setMpiStartupDefaults();
  capstan::addHeapTunables();
  execv(solver.c_str(), argv);
  std::perror(("capstan: cannot start " + solver).c_str());
  return 1;
}
