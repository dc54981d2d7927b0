// Wall-clock seconds since a time point: the phases' and steps' timings.
#pragma once

#include <chrono>

namespace capstan {

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace capstan
