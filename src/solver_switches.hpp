// Methods a run takes up partway on its own, each kept from then on: the saddle-point pressure
// step where Auto's Anderson loop failed, double-precision factors where single ones erred, the
// block-triangular pressure step where the factored one failed or was refused. Each is noted
// where it happens (every rank alike: the decisions are collective) and listed by step in
// summary.json's "solver_switches", so a run's answer says which method gave it.
#pragma once

#include <string>
#include <vector>

namespace capstan {

struct SolverSwitch {
  int step = 0;
  std::string what;
};

namespace solver_switches {
void note(const std::string& what);
// The notes since the last take, oldest first.
std::vector<std::string> take();
}  // namespace solver_switches

}  // namespace capstan
