#pragma once
// Per-node statistics: messages in and out, drops on its inputs, processing latency percentiles
// and queue depth. Printed when a graph ends and available as a stream (node type graph.stats).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "core/messages.hpp"

namespace mocap::graph {

// The synchroniser of a node with joined inputs (graph/synchronizer.hpp).
struct SyncInputStats {
  std::string name;                // the input ("people3d", "view:2"); set by the runtime
  std::uint64_t received = 0;      // messages (not end of stream) taken in
  std::uint64_t missing = 0;       // sets passed on without a message of this input
  std::uint64_t late = 0;          // messages that came after their set had gone on
  std::uint64_t late_dropped = 0;  // of those, dropped (sync_late: drop) rather than passed alone
  std::size_t held = 0, max_held = 0;
  bool ended = false;

  bool operator==(const SyncInputStats&) const = default;
};

struct SyncStats {
  std::uint64_t sets = 0;      // passed on, late ones included
  std::uint64_t complete = 0;  // sets with every input present
  std::uint64_t restarts = 0;  // an input's stream went back (a restarted producer)
  // Skew: the newest minus the oldest capture time of a set's members (sets of two or more
  // members with capture times), how far apart a rig's cameras took one set's frames.
  std::uint64_t skew_sets = 0;
  double skew_p50_ms = 0, skew_p95_ms = 0;  // over the last Synchronizer::kSkewSamples sets
  double skew_max_ms = 0;                   // over the whole run
  std::vector<SyncInputStats> inputs;       // empty: the node joins nothing

  bool operator==(const SyncStats&) const = default;
};

// One line: "joined 795 sets (790 complete), skew p50 1.2 ms p95 3.4 ms max 9.0 ms; people3d: 5
// missing, 2 late; ..."; empty when not joined.
std::string format_sync_stats(const SyncStats& sync);
// Messages the synchroniser dropped for coming after their set (sync_late: drop), all inputs:
// part of a node's drops, like those of its edges.
std::uint64_t late_dropped(const SyncStats& sync);

struct NodeStats {
  std::string node, type, process;
  // drops: messages lost on its input edges, dropped by the node (Context::count_drop) or, late
  // for their set, by its synchroniser (late_dropped).
  std::uint64_t in = 0, out = 0, drops = 0;
  double p50_us = 0, p95_us = 0;  // time spent in process(), over the last samples
  std::size_t queue_depth = 0, max_queue_depth = 0;
  std::string state;   // "running", "done", "failed"
  std::string status;  // the node's latest status line (Context::report_status), e.g. a reconnect
  SyncStats sync{};    // joined inputs only; in-process (not in the wire format's GraphStats)
  // In-process only (not in the wire format's GraphStats), to find the stage a live graph queues
  // behind: how long messages waited in this node's inputs ({p50, p95} over the last samples),
  // and how long in all this node waited for room in a full blocking queue downstream.
  double wait_p50_us = 0, wait_p95_us = 0;
  double blocked_s = 0;

  bool operator==(const NodeStats&) const = default;
};

struct GraphStats : Message {
  static constexpr std::string_view kTypeName = "GraphStats";
  std::string graph;
  std::vector<NodeStats> nodes;
};

std::string format_stats_table(const GraphStats& stats);

// The last kSamples durations in a ring; percentiles over them. Writers and readers may be on
// different threads; the lock is held for a few nanoseconds.
class LatencyWindow {
 public:
  static constexpr std::size_t kSamples = 1024;
  void add(std::int64_t ns);
  // Returns {p50, p95} in microseconds; zeros before the first sample.
  std::array<double, 2> percentiles_us() const;

 private:
  mutable std::mutex mutex_;
  std::array<std::int64_t, kSamples> samples_{};
  std::size_t count_ = 0;
};

// Percentile (0..100) of unsorted values by nearest rank; 0 for an empty set.
double percentile(std::vector<std::int64_t> values, double p);

}  // namespace mocap::graph
