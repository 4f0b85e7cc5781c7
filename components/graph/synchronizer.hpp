#pragma once
// Joins the messages of several inputs into sets that belong together: the same frame number
// (offline), or capture times within a tolerance (live, several cameras). The idea of MediaPipe's
// default and timestamp-aligning input stream handlers and of GStreamer's GstAggregator: a plain
// class without threads or clocks of its own, driven by the runtime (and the test harness) and
// testable alone.
//
// Every input's stream arrives in order. The oldest message held on any input anchors the next
// set (its key K); each input contributes its oldest message if that is within the tolerance of K
// (frame numbers: equal to K). The set goes on:
//  * complete, once every input has its member;
//  * partial, once it can no longer complete: each input without a member has a newer message
//    (or has passed K) or has ended; a drop on a lossy edge therefore only makes a set partial;
//  * partial, when a wall-clock wait limit is set and the set's first message waited that long
//    (live sources that stall);
//  * partial, at the bound (AtBound::pass_partial): an input holds `bound` messages and the oldest
//    set still waits for another input.
// A message that arrives after its set went on partial is counted late (per input) and, by the
// options' `late`, passed on alone, marked late, or dropped (a node making one output per set
// would otherwise make a second one for that frame). A message older than its input's previous one
// (a restarted stream) passes on everything held as it is and starts joining afresh (counted as a
// restart).
//
// Memory: each input holds at most `bound` messages. With AtBound::wait a full input is simply
// not read (readable() is false), so a blocking edge into it fills and its producer waits:
// nothing is lost. That is right for independent sources (cameras); for branches of one source
// (the 2D people and, behind a slower chain, their 3D), waiting could deadlock (the source waits
// for this node, the slow branch for the source), so the runtime uses pass_partial there.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "graph/contract.hpp"
#include "graph/packet.hpp"
#include "graph/stats.hpp"

namespace mocap::graph {

enum class AtBound {
  wait,          // the full input is not read until the set completes or can no longer
  pass_partial,  // the oldest set goes on partial; its missing messages come later, alone
};

struct SyncOptions {
  SyncKey key = SyncKey::frame;
  std::int64_t tolerance_ns = 0;     // capture_time: max distance from the set's oldest member
  std::chrono::nanoseconds wait{0};  // a set waiting this long goes on partial; 0: no limit
  std::size_t bound = 64;            // messages held per input at most (at least 1)
  AtBound at_bound = AtBound::wait;
  LateMessages late = LateMessages::pass;
};

struct SyncSet {
  std::vector<Packet> packets;  // one per input; a missing input's packet holds no message
  std::int64_t key = 0;         // the frame number or capture time of its oldest member
  bool late = false;            // a single message whose set had already gone on without it

  bool has(std::size_t input) const { return packets[input].message != nullptr; }
  bool complete() const;
};

class Synchronizer {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::size_t kSkewSamples = 1024;

  // Throws std::invalid_argument for no inputs or a zero bound.
  Synchronizer(std::size_t inputs, SyncOptions options);

  // A message (not end of stream) that arrived on `input` at `now`. Call only while
  // readable(input), except that a caller may always push what it already took from a queue.
  void push(std::size_t input, Packet packet, Clock::time_point now);
  // The input's end of stream: it will send nothing more.
  void end(std::size_t input);

  // The next set to pass on, oldest first, into `set` (its storage is reused: no allocation per
  // set); false while the oldest set may still complete.
  bool pop(Clock::time_point now, SyncSet& set);

  // False while the input holds `bound` messages: do not read it (AtBound::wait).
  bool readable(std::size_t input) const;
  // When pop() will pass the oldest set on partial for its wait limit, if one is set.
  std::optional<Clock::time_point> deadline() const;
  // Every input has ended and everything was passed on.
  bool finished() const;

  // The counters, with the skew percentiles over the last kSkewSamples sets.
  SyncStats stats() const;
  const SyncOptions& options() const { return options_; }
  std::size_t inputs() const { return inputs_.size(); }

 private:
  struct Held {
    Packet packet;
    std::int64_t key;
    Clock::time_point arrival;
  };
  struct Input {
    std::deque<Held> held;
    bool ended = false;
    std::optional<std::int64_t> last_key;  // of the newest message taken in
    std::optional<std::int64_t> late_to;   // a message keyed up to this comes after its set
  };

  std::int64_t key_of(const Packet& packet) const;
  std::optional<std::int64_t> anchor() const;
  bool member(const Input& input, std::int64_t anchor) const;
  bool settled(const Input& input, std::int64_t anchor) const;
  void take(std::int64_t anchor, SyncSet& set);
  void restart();
  void count_skew(const SyncSet& set);

  SyncOptions options_;
  std::vector<Input> inputs_;
  std::deque<SyncSet> ready_;  // late messages and sets flushed by a restart, passed on first
  SyncStats stats_;
  std::array<std::int64_t, kSkewSamples> skews_{};  // a ring: the last sets' skews (ns)
  std::int64_t skew_max_ns_ = 0;
};

}  // namespace mocap::graph
