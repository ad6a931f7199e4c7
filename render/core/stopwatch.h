// Wall-clock seconds for stage timings and budgets (steady clock: never jumps with the system time).
#pragma once
#include <chrono>

namespace vpl {

using SteadyClock = std::chrono::steady_clock;

inline double secondsSince(SteadyClock::time_point t) {
  return std::chrono::duration<double>(SteadyClock::now() - t).count();
}

// Seconds since the previous lap() (or construction): consecutive stages timed with one object.
class Stopwatch {
 public:
  double lap() {
    const SteadyClock::time_point now = SteadyClock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  SteadyClock::time_point last_ = SteadyClock::now();
};

}  // namespace vpl
