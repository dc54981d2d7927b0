// The running program's directory, with its trailing '/' ("" where it cannot
// be read): where the launcher finds capstan-solver and the solver finds its
// krylov plugin. Header-only: the launcher links nothing of capstan's.
#pragma once

#include <unistd.h>

#include <climits>
#include <string>

namespace capstan {

inline std::string programDirectory() {
  char self[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  if (n <= 0) return "";
  const std::string path(self, size_t(n));
  return path.substr(0, path.rfind('/') + 1);
}

}  // namespace capstan
