#include "log.hpp"

#include <algorithm>
#include <cstdarg>

namespace capstan {

const std::vector<std::string>& Log::topics() {
  static const std::vector<std::string> all{"newton"};
  return all;
}

Log::Log(bool rank0, bool quiet, std::vector<std::string> topics)
    : rank0_(rank0), quiet_(quiet), topics_(std::move(topics)) {}

Log::~Log() {
  if (jsonl_) std::fclose(jsonl_);
}

bool Log::on(const std::string& topic) const {
  return std::find(topics_.begin(), topics_.end(), topic) != topics_.end();
}

void Log::open(const std::filesystem::path& dir, bool append) {
  if (!rank0_ || topics_.empty() || jsonl_) return;
  jsonl_ = std::fopen((dir / "log.jsonl").string().c_str(), append ? "a" : "w");
}

void Log::event(const std::string& topic, const std::string& text, json::Object fields) {
  if (!rank0_ || !on(topic)) return;
  if (!quiet_) std::printf("    %s\n", text.c_str());
  if (jsonl_) {
    json::Object line;
    line.add("topic", json::string(topic)).add("step", json::number(step_));
    const std::string body = fields.str();
    std::string all = line.str();
    if (body.size() > 2) all = all.substr(0, all.size() - 1) + ", " + body.substr(1);
    std::fprintf(jsonl_, "%s\n", all.c_str());
    std::fflush(jsonl_);
  }
}

void Log::progress(const std::string& line) {
  if (!rank0_) return;
  if (!quiet_) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  }
  if (jsonl_) {
    std::fprintf(jsonl_, "%s\n",
                 json::Object().add("topic", json::string("progress")).add("step", json::number(step_))
                     .add("text", json::string(line)).str().c_str());
    std::fflush(jsonl_);
  }
}

std::string format(const char* fmt, ...) {
  va_list args, copy;
  va_start(args, fmt);
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, fmt, args);
  va_end(args);
  std::string out(size_t(std::max(n, 0)), '\0');
  std::vsnprintf(out.data(), out.size() + 1, fmt, copy);
  va_end(copy);
  return out;
}

}  // namespace capstan
