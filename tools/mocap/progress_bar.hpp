#pragma once
// A one-line progress bar with an ETA on stderr; silent when stderr is not a terminal.

#include <chrono>
#include <string>
#include <string_view>

namespace mocap::cli {

class ProgressBar {
 public:
  ProgressBar();  // enabled when stderr is a terminal
  explicit ProgressBar(bool enabled);
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  ~ProgressBar();

  // `fraction` of the current stage is done; a new stage name restarts the ETA.
  void update(std::string_view stage, double fraction);
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  bool drawn_ = false;
  std::string stage_;
  Clock::time_point stage_start_, last_draw_;
};

}  // namespace mocap::cli
