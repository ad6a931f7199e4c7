// A one-line progress bar on stderr, drawn only when stderr is a terminal (DESIGN.md §3).
#pragma once
#include <chrono>
#include <mutex>
#include <string>

namespace vpl {

class ProgressBar {
 public:
  ProgressBar(std::string label, bool enabled);
  ~ProgressBar();
  // fraction in [0, 1]; redraws at most ~10 times a second. Thread-safe.
  void update(double fraction, const std::string& detail);
  void finish();

 private:
  std::string label_;
  bool enabled_;
  bool finished_ = false;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point lastDraw_{};
};

}  // namespace vpl
