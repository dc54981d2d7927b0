#include "solver_switches.hpp"

#include <utility>

namespace capstan::solver_switches {

namespace {
std::vector<std::string>& pending() {
  static std::vector<std::string> notes;
  return notes;
}
}  // namespace

void note(const std::string& what) { pending().push_back(what); }

std::vector<std::string> take() { return std::exchange(pending(), {}); }

}  // namespace capstan::solver_switches
