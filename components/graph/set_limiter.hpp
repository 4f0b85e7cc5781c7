#pragma once
// Whole sets into a stage slower than the cameras (several cameras' detectors): the cameras'
// frames are joined by capture time first (the synchroniser, cheap), and a set goes on only when
// the whole stage is idle; a set that arrives while any part of it is busy is dropped whole. Every
// detector then works on the frames of the same instants, so their outputs join complete, however
// slow they are. Left to each detector (a `latest` edge per camera), a slow stage takes each
// camera's newest frame at a different moment and the join after it sees mostly partial sets.
//
// Newest wins: a set is judged when it arrives, so the set that goes when the stage is idle again
// is the first one after it, at most a frame period old. The stage may idle that long (it is
// waiting for a new instant, not for an old one).
//
// A partial set goes on only when the cameras it lacks are away (nothing from them for `stall`
// of capture time, or never): the others go on without a lost camera. A camera that is there but
// whose frame fell outside the set (its clock or its wake-up jittered beyond the tolerance) would
// make the join after the stage wait for a view that will not come: such a set is dropped.
//
// The sets are numbered in arrival order, dropped ones included, so a set's number times the
// frame period is its time: downstream joins by that number (frame) and time-stamped outputs
// (BVH) keep time across the dropped sets.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace mocap::graph {

struct SetLimiterCounts {
  std::uint64_t sets = 0;             // joined and seen here
  std::uint64_t passed = 0;           // passed on to the stage
  std::uint64_t passed_complete = 0;  // of those, with every camera's frame
  std::uint64_t dropped_busy = 0;     // dropped whole: the stage was busy
  std::uint64_t dropped_partial = 0;  // dropped: partial, the cameras it lacks not away
};

class SetLimiter {
 public:
  // `stall_ns`: a camera with no frame for this long (capture time) counts as away.
  SetLimiter(std::size_t cameras, std::int64_t stall_ns);

  // A set arrived: `present[i]` when camera i has a frame in it, `capture_ns` a capture time of
  // it, `stage_idle` when every part of the stage is idle. Returns its number when it is to be
  // passed on, nullopt when it is dropped.
  std::optional<std::int64_t> admit(const std::vector<bool>& present, std::int64_t capture_ns,
                                    bool stage_idle);

  const SetLimiterCounts& counts() const { return counts_; }
  // "passed 120 of 900 sets (118 complete), 770 dropped while the stage was busy, 10 partial".
  std::string describe() const;

 private:
  std::int64_t stall_ns_;
  std::vector<std::optional<std::int64_t>> last_seen_;  // per camera: its newest capture time
  SetLimiterCounts counts_;
};

}  // namespace mocap::graph
