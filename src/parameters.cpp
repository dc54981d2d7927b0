#include "parameters.hpp"

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <sstream>

#include "errors.hpp"

namespace capstan {

void ParameterReader::fail(const std::string& path, const std::string& what) const {
  throw InputError(file + ": " + (path.empty() ? "" : "parameter '" + path + "': ") + what);
}

double ParameterReader::positive(const Teuchos::ParameterList& l, const std::string& path,
                                 const std::string& name) const {
  const double x = l.get<double>(name);
  if (!(x > 0) || !std::isfinite(x)) fail(path + "/" + name, "must be a finite number > 0, got " + shortest(x));
  return x;
}

double ParameterReader::nonNegative(const Teuchos::ParameterList& l, const std::string& path,
                                    const std::string& name) const {
  const double x = l.get<double>(name);
  if (!(x >= 0) || !std::isfinite(x)) fail(path + "/" + name, "must be >= 0");
  return x;
}

double ParameterReader::fraction(const Teuchos::ParameterList& l, const std::string& path,
                                 const std::string& name) const {
  const double x = l.get<double>(name);
  if (!(x > 0 && x < 1)) fail(path + "/" + name, "must be in (0, 1)");
  return x;
}

int ParameterReader::atLeast(const Teuchos::ParameterList& l, const std::string& path, const std::string& name,
                             int lowest) const {
  const int x = l.get<int>(name);
  if (x < lowest) fail(path + "/" + name, "must be >= " + std::to_string(lowest));
  return x;
}

double ParameterReader::finite(const Teuchos::ParameterList& l, const std::string& path,
                               const std::string& name) const {
  const double x = l.get<double>(name);
  if (!std::isfinite(x)) fail(path + "/" + name, "must be a finite number");
  return x;
}

std::array<bool, 3> ParameterReader::components(const std::string& s, const std::string& path) const {
  std::array<bool, 3> on{false, false, false};
  if (s.empty()) fail(path, "empty: name at least one of x, y, z");
  for (char ch : s) {
    if (ch == ' ' || ch == ',') continue;
    if (ch < 'x' || ch > 'z') fail(path, "'" + s + "': components are letters x, y, z");
    if (on[ch - 'x']) fail(path, "'" + s + "': component " + ch + " listed twice");
    on[ch - 'x'] = true;
  }
  return on;
}

std::string shortest(double x) {
  std::ostringstream brief, full;
  brief << x;
  full << std::setprecision(17) << x;
  return std::strtod(brief.str().c_str(), nullptr) == x ? brief.str() : full.str();
}

std::string brief(double x) {
  std::ostringstream out;
  out << x;
  return out.str();
}

}  // namespace capstan
