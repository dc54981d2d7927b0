// A minimal JSON writer (objects, arrays, numbers, strings) for summary.json.
// Non-finite numbers are written as null, so the file always parses.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace capstan::json {

inline std::string number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}
inline std::string number(long x) { return std::to_string(x); }
inline std::string number(int x) { return std::to_string(x); }

inline std::string string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (static_cast<unsigned char>(c) < 32) out += ' ';
    else out += c;
  }
  return out + "\"";
}

inline std::string array(const std::vector<double>& v) {
  std::string out = "[";
  for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + number(v[i]);
  return out + "]";
}

// [v, ...] from already-serialised values.
inline std::string list(const std::vector<std::string>& rawValues) {
  std::string out = "[";
  for (size_t i = 0; i < rawValues.size(); ++i) out += (i ? ", " : "") + rawValues[i];
  return out + "]";
}

// Builds {"k": v, ...} from already-serialised values.
class Object {
 public:
  Object& add(const std::string& key, const std::string& rawValue) {
    body_ += (body_.empty() ? "" : ", ") + string(key) + ": " + rawValue;
    return *this;
  }
  std::string str() const { return "{" + body_ + "}"; }

 private:
  std::string body_;
};

}  // namespace capstan::json
