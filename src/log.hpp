// The run's voice, on rank 0 only: progress lines (one per step; --quiet
// silences them) and, for the topics named by `capstan run --log TOPIC`, the
// method's inner events. An event is printed as a line of text for people
// and appended as one JSON object per line to OUTDIR/log.jsonl for scripts
// and tests (docs/architecture.md, "Logs"). Logging only reports what the
// method computed anyway: turning a topic on changes no figure.
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "json.hpp"

namespace capstan {

class Log {
 public:
  // The topics a run can log (capstan run --log TOPIC).
  //   newton: every Newton solve's residual history, each constraint's
  //           violation after it, the predictors and the saddle-point steps.
  static const std::vector<std::string>& topics();

  Log(bool rank0, bool quiet, std::vector<std::string> topics);
  ~Log();
  bool on(const std::string& topic) const;
  // Starts DIR/log.jsonl (appends to it when `append`, a restarted run) if a
  // topic is on. Events before it go to stdout only.
  void open(const std::filesystem::path& dir, bool append);
  // The step the next events belong to (their "step" field).
  void setStep(int step) { step_ = step; }
  // One event of `topic` (ignored when the topic is off): `text` on stdout
  // unless quiet, {"topic", "step", fields...} to log.jsonl.
  void event(const std::string& topic, const std::string& text, json::Object fields);
  // A progress line on stdout (unless quiet), flushed; with a topic on also
  // to log.jsonl as {"topic": "progress", "text": line}.
  void progress(const std::string& line);
  bool quiet() const { return quiet_ || !rank0_; }

 private:
  bool rank0_, quiet_;
  std::vector<std::string> topics_;
  int step_ = 0;
  std::FILE* jsonl_ = nullptr;
};

// printf-style formatting into a std::string (the log's and progress lines' text).
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

}  // namespace capstan
