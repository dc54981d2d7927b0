// Errors that end a run with a defined exit status (interface.md).
#pragma once

#include <stdexcept>
#include <string>

namespace capstan {

// Bad input: exit 1, nothing run, nothing written. The message names the file,
// the parameter path and what is wrong.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// How a failure reason starts where the multiplier loop stalled
// (AugmentationLoop::stalled); stickChatterHint looks for it.
inline constexpr const char* kStalledLoop = "augmentation loop stalled";

// The part of a Trilinos exception text a user needs: Teuchos texts start with
// the throwing source file and line, the throw count and the failed test.
inline std::string trilinosMessage(const std::string& what) {
  std::string out, line;
  for (size_t start = 0; start <= what.size();) {
    size_t end = what.find('\n', start);
    if (end == std::string::npos) end = what.size();
    line = what.substr(start, end - start);
    start = end + 1;
    const auto a = line.find_first_not_of(" \t\r"), b = line.find_last_not_of(" \t\r");
    line = a == std::string::npos ? "" : line.substr(a, b - a + 1);
    // (MueLu lists every valid parameter name as "| name -> score" lines before its verdict.)
    if (line.empty() || line[0] == '|' || line.rfind("Throw number", 0) == 0 ||
        line.rfind("Throw test that evaluated", 0) == 0 ||
        (line.back() == ':' && (line.find(".cpp:") != std::string::npos || line.find(".hpp:") != std::string::npos ||
                                line.find(".C:") != std::string::npos)))
      continue;
    out += (out.empty() ? "" : " ") + line;
  }
  if (out.size() > 400) out = out.substr(0, 400) + "...";
  return out.empty() ? what : out;
}

}  // namespace capstan
