// Reading a validated parameter list into a component's typed settings. Each
// component declares its parameters (name, default, doc string: the only place
// a default is stated) and parses them into its settings struct, side by side
// in one file; strings become enums here, so no string comparison survives
// parsing. Messages name the scene file and the parameter path (exit 1).
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace capstan {

struct ParameterReader {
  std::string file;

  [[noreturn]] void fail(const std::string& path, const std::string& what) const;

  // The string parameter `name` of `list` (at `path`) as one of `choices`.
  template <class E>
  E choice(const Teuchos::ParameterList& list, const std::string& path, const std::string& name,
           const std::vector<std::pair<const char*, E>>& choices) const {
    const auto& value = list.get<std::string>(name);
    std::string names;
    for (const auto& [text, e] : choices) {
      if (value == text) return e;
      names += (names.empty() ? "" : ", ") + std::string(text);
    }
    fail(path + "/" + name, "'" + value + "' is not one of " + names);
  }
  double positive(const Teuchos::ParameterList& list, const std::string& path, const std::string& name) const;
  double nonNegative(const Teuchos::ParameterList& list, const std::string& path, const std::string& name) const;
  // In the open interval (0, 1): a relative tolerance.
  double fraction(const Teuchos::ParameterList& list, const std::string& path, const std::string& name) const;
  int atLeast(const Teuchos::ParameterList& list, const std::string& path, const std::string& name, int lowest) const;
  double finite(const Teuchos::ParameterList& list, const std::string& path, const std::string& name) const;
  // An Array of exactly 3 finite numbers.
  template <class T>
  std::array<T, 3> three(const Teuchos::ParameterList& list, const std::string& path, const std::string& name) const {
    const auto& a = list.get<Teuchos::Array<T>>(name);
    if (a.size() != 3) fail(path + "/" + name, "expected 3 values, got " + std::to_string(a.size()));
    for (const T& x : a)
      if (!std::isfinite(double(x))) fail(path + "/" + name, "must be finite numbers");
    return {a[0], a[1], a[2]};
  }
  // Components named by letters, e.g. "xz" or "x, z" (at `path`).
  std::array<bool, 3> components(const std::string& text, const std::string& path) const;
};

// The name of enum value e in `choices` (the scene's spelling).
template <class E>
const char* nameOf(E e, const std::vector<std::pair<const char*, E>>& choices) {
  for (const auto& [text, value] : choices)
    if (value == e) return text;
  return "?";
}

// 0.01, not 1.00000000000000002e-02: 6 digits where they read back the same, else 17.
std::string shortest(double x);
// 6 digits, for descriptions in messages.
std::string brief(double x);

}  // namespace capstan
