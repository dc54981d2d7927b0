// CSV cells (history.csv, nip.csv): RFC 4180 quoting, so that a capstan or
// support named with a comma or a quote keeps its row's columns.
#pragma once

#include <string>

namespace capstan {

inline std::string csvCell(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string quoted = "\"";
  for (char c : s) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace capstan
