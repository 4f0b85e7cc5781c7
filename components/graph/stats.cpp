#include "graph/stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace mocap::graph {

double percentile(std::vector<std::int64_t> values, double p) {
  if (values.empty()) return 0;
  const auto rank = static_cast<std::size_t>(
      std::clamp(std::ceil(p / 100.0 * static_cast<double>(values.size())) - 1.0, 0.0,
                 static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank),
                   values.end());
  return static_cast<double>(values[rank]);
}

void LatencyWindow::add(std::int64_t ns) {
  std::lock_guard lock(mutex_);
  samples_[count_ % kSamples] = ns;
  ++count_;
}

std::array<double, 2> LatencyWindow::percentiles_us() const {
  std::vector<std::int64_t> copy;
  {
    std::lock_guard lock(mutex_);
    copy.assign(samples_.begin(),
                samples_.begin() + static_cast<std::ptrdiff_t>(std::min(count_, kSamples)));
  }
  return {percentile(copy, 50) / 1000.0, percentile(copy, 95) / 1000.0};
}

std::uint64_t late_dropped(const SyncStats& sync) {
  std::uint64_t dropped = 0;
  for (const SyncInputStats& input : sync.inputs) dropped += input.late_dropped;
  return dropped;
}

std::string format_sync_stats(const SyncStats& sync) {
  if (sync.inputs.empty()) return {};
  std::ostringstream out;
  out << "joined " << sync.sets << " sets (" << sync.complete << " complete)";
  if (sync.restarts) out << ", " << sync.restarts << " restarts";
  if (sync.skew_sets) {
    char skew[96];
    std::snprintf(skew, sizeof skew, ", skew p50 %.1f ms p95 %.1f ms max %.1f ms", sync.skew_p50_ms,
                  sync.skew_p95_ms, sync.skew_max_ms);
    out << skew;
  }
  for (const SyncInputStats& input : sync.inputs) {
    out << "; " << input.name << ": " << input.missing << " missing";
    if (input.late) out << ", " << input.late << " late";
    if (input.late_dropped) out << " (" << input.late_dropped << " dropped)";
    if (input.held) out << ", " << input.held << " held";
  }
  return out.str();
}

std::string format_stats_table(const GraphStats& stats) {
  std::ostringstream out;
  char line[320];
  std::snprintf(line, sizeof line, "%-16s %-20s %10s %10s %8s %10s %10s %6s %6s %9s %9s %8s  %s\n",
                "node", "type", "in", "out", "drops", "p50 us", "p95 us", "queue", "max",
                "wait p50", "wait p95", "blocked", "state");
  out << line;
  for (const NodeStats& n : stats.nodes) {
    std::snprintf(
        line, sizeof line,
        "%-16s %-20s %10llu %10llu %8llu %10.1f %10.1f %6zu %6zu %7.1fms %7.1fms %7.2fs  %s\n",
        n.node.c_str(), n.type.c_str(), static_cast<unsigned long long>(n.in),
        static_cast<unsigned long long>(n.out), static_cast<unsigned long long>(n.drops), n.p50_us,
        n.p95_us, n.queue_depth, n.max_queue_depth, n.wait_p50_us / 1000.0, n.wait_p95_us / 1000.0,
        n.blocked_s, n.state.c_str());
    out << line;
    if (!n.status.empty()) out << "  " << n.node << ": " << n.status << "\n";
    if (!n.sync.inputs.empty()) out << "  " << n.node << ": " << format_sync_stats(n.sync) << "\n";
  }
  return out.str();
}

}  // namespace mocap::graph
