#pragma once
// How long the stream fitters take per input frame (PeopleFitter: a camera's frame;
// MultiViewPeopleFitter: a rig's frame set), from the frame taken in to its people pushed into
// their tracks' fitters, solves included: what a live fit adds to each frame. Kept by the
// bookkeeping both share (TrackFitters) and given in both fitters' summary() line, which the
// nodes report as their status (the graph's statistics) and print when they close.
//
// The last kSamples times in a ring, so that a long live run holds bounded memory and its
// percentiles follow its recent frames; count() is over the whole run.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace mocap::fit {

class FrameTimes {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::size_t kSamples = 4096;

  void start() { started_ = Clock::now(); }  // a frame is taken in
  void stop();                               // ... and done with (after start())
  void add(std::chrono::nanoseconds time);

  std::uint64_t count() const { return count_; }
  // {p50, p95} in milliseconds over the last kSamples frames; zeros before the first.
  std::array<double, 2> percentiles_ms() const;
  // "per frame p50 1.20 ms, p95 8.31 ms" (`unit`: "frame", "frame set"); empty before the first.
  std::string describe(std::string_view unit) const;

 private:
  std::array<std::int64_t, kSamples> samples_{};  // nanoseconds
  std::uint64_t count_ = 0;
  Clock::time_point started_{};
};

}  // namespace mocap::fit
