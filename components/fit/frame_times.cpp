#include "fit/frame_times.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace mocap::fit {

void FrameTimes::stop() { add(Clock::now() - started_); }

void FrameTimes::add(std::chrono::nanoseconds time) {
  samples_[count_ % kSamples] = time.count();
  ++count_;
}

std::array<double, 2> FrameTimes::percentiles_ms() const {
  const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(count_, kSamples));
  if (n == 0) return {0.0, 0.0};
  std::vector<std::int64_t> sorted(samples_.begin(),
                                   samples_.begin() + static_cast<std::ptrdiff_t>(n));
  std::sort(sorted.begin(), sorted.end());
  // Nearest rank, as the graph's latency percentiles (graph/stats.cpp).
  const auto at = [&](double p) {
    const double rank =
        std::clamp(std::ceil(p * static_cast<double>(n)) - 1.0, 0.0, static_cast<double>(n - 1));
    return static_cast<double>(sorted[static_cast<std::size_t>(rank)]) / 1e6;
  };
  return {at(0.50), at(0.95)};
}

std::string FrameTimes::describe(std::string_view unit) const {
  if (count_ == 0) return {};
  const auto [p50, p95] = percentiles_ms();
  char text[96];
  std::snprintf(text, sizeof text, "per %.*s p50 %.2f ms, p95 %.2f ms",
                static_cast<int>(unit.size()), unit.data(), p50, p95);
  return text;
}

}  // namespace mocap::fit
