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

}  // namespace capstan
