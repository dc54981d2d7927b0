#include "step_record.hpp"

#include <algorithm>
#include <cstdio>

#include "checkpoint.hpp"
#include "csv.hpp"
#include "json.hpp"

namespace capstan {

double StepRecord::maxPenetration() const {
  double m = 0;
  for (const auto& c : capstans) m = std::max(m, c.maxPenetration);
  return m;
}

namespace {

std::string text(double x) { return json::number(x); }
std::string text(int x) { return json::number(x); }
std::string text(long x) { return json::number(x); }
std::string text(const std::array<double, 3>& v) { return json::array({v[0], v[1], v[2]}); }

// summary.json's step object: nested objects on a stack.
struct JsonWriter {
  std::vector<json::Object> stack{1};
  template <class T>
  void field(const char* name, const T& value, Show = {}) {
    stack.back().add(name, text(value));
  }
  template <class F>
  void flag(const char*, bool on, F fields) {
    if (on) fields();
  }
  template <class F>
  void group(const char* name, bool on, F fields) {
    if (!on) {
      stack.back().add(name, "null");
      return;
    }
    stack.emplace_back();
    fields();
    close(name);
  }
  template <class L, class F>
  void list(const char* name, L& items, F walkItem) {
    stack.emplace_back();
    for (auto& item : items) {
      stack.emplace_back();
      walkItem(item);
      close(item.name);
    }
    close(name);
  }
  void close(const std::string& name) {
    const std::string body = stack.back().str();
    stack.pop_back();
    stack.back().add(name, body);
  }
};

// history.csv: one column per number, named <item>_<field> (a force's
// components <item>_fx, _fy, _fz).
struct CsvWriter {
  bool header;
  std::string prefix, out;
  void cell(const std::string& name, const std::string& value) {
    out += (out.empty() ? "" : ",") + (header ? csvCell(prefix + name) : value);
  }
  template <class T>
  void field(const char* name, const T& value, Show = {}) {
    cell(name, text(value));
  }
  void field(const char* name, const std::array<double, 3>& v, Show = {}) {
    const bool force = std::string(name) == "force";
    const char* axis[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) cell(force ? std::string("f") + axis[i] : std::string(name) + "_" + axis[i], text(v[i]));
  }
  template <class F>
  void flag(const char*, bool on, F fields) {
    if (on) fields();
  }
  template <class F>
  void group(const char* name, bool on, F fields) {
    if (!on) return;
    const std::string outer = prefix;
    prefix += std::string(name) + "_";
    fields();
    prefix = outer;
  }
  template <class L, class F>
  void list(const char*, L& items, F walkItem) {
    for (auto& item : items) {
      prefix = item.name + "_";
      walkItem(item);
      prefix.clear();
    }
  }
};

// The progress line: "label=value" for each shown field; an item's shown
// fields on a line of its own.
struct ProgressWriter {
  std::string* line;
  std::vector<std::string> items;
  template <class T>
  void field(const char*, const T& value, Show show = {}) {
    if (!show.label) return;
    char buf[64];
    std::snprintf(buf, sizeof buf, show.format, value);
    *line += std::string("  ") + show.label + "=" + buf;
  }
  void field(const char*, const std::array<double, 3>&, Show = {}) {}
  template <class F>
  void flag(const char*, bool on, F fields) {
    if (on) fields();
  }
  template <class F>
  void group(const char*, bool on, F fields) {
    if (on) fields();
  }
  template <class L, class F>
  void list(const char*, L& items_, F walkItem) {
    std::string* outer = line;
    for (auto& item : items_) {
      std::string own;
      line = &own;
      walkItem(item);
      if (!own.empty()) items.push_back("    " + item.name + ":" + own);
    }
    line = outer;
  }
};

struct CheckpointPut {
  checkpoint::Writer& w;
  template <class T>
  void field(const char*, const T& value, Show = {}) {
    w.put(value);
  }
  template <class F>
  void flag(const char*, bool on, F fields) {
    w.put(on);
    if (on) fields();
  }
  template <class F>
  void group(const char* name, bool on, F fields) {
    flag(name, on, fields);
  }
  template <class L, class F>
  void list(const char*, const L& items, F walkItem) {
    w.put<int>(int(items.size()));
    for (const auto& item : items) {
      w.put(item.name);
      walkItem(item);
    }
  }
};

struct CheckpointGet {
  checkpoint::Reader& in;
  template <class T>
  void field(const char*, T& value, Show = {}) {
    value = in.get<T>();
  }
  template <class F>
  void flag(const char*, bool& on, F fields) {
    on = in.get<bool>();
    if (on) fields();
  }
  template <class F>
  void group(const char* name, bool& on, F fields) {
    flag(name, on, fields);
  }
  template <class L, class F>
  void list(const char*, L& items, F walkItem) {
    items.resize(size_t(in.get<int>()));
    for (auto& item : items) {
      item.name = in.getString();
      walkItem(item);
    }
  }
};

}  // namespace

std::string toJson(const StepRecord& record) {
  JsonWriter w;
  walkStep(w, record);
  return w.stack.back().str();
}

std::string csvHeader(const StepRecord& layout) {
  CsvWriter w{true, "", ""};
  walkStep(w, layout);
  return w.out;
}

std::string csvRow(const StepRecord& record) {
  CsvWriter w{false, "", ""};
  walkStep(w, record);
  return w.out;
}

std::vector<std::string> progressLines(const StepRecord& record, int steps, double elapsed) {
  std::string first = "step " + std::to_string(record.step) + "/" + std::to_string(steps);
  ProgressWriter w{&first, {}};
  walkStep(w, record);
  char tail[64];
  std::snprintf(tail, sizeof tail, "  max_penetration=%.3e  %.2fs", record.maxPenetration(), elapsed);
  std::vector<std::string> lines{first + tail};
  lines.insert(lines.end(), w.items.begin(), w.items.end());
  return lines;
}

void checkpoint::put(Writer& w, const StepRecord& record) {
  CheckpointPut v{w};
  walkStep(v, record);
}

StepRecord checkpoint::get(Reader& in) {
  StepRecord record;
  CheckpointGet v{in};
  walkStep(v, record);
  return record;
}

}  // namespace capstan
