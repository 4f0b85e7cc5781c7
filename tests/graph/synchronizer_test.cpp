// The synchroniser alone: sets by frame number in any arrival order, gaps, end of stream, the
// bound (wait or pass on partial, late parts alone), capture times within a tolerance, the
// wall-clock wait limit, restarted streams, keys from garbage. What viz/overlay_inputs checked
// (the overlay's joining by frame before the synchroniser) is here too.

#include "graph/synchronizer.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace mocap::graph {
namespace {

using Clock = Synchronizer::Clock;
using namespace std::chrono_literals;

template <class T = People2D>
Packet message(std::int64_t frame, std::int64_t capture_ns = 0) {
  auto m = std::make_shared<T>();
  m->header.frame = frame;
  m->header.capture_ns = capture_ns;
  return Packet::of<T>(std::move(m));
}

// Every set ready now, as "key:present inputs" strings ("3:01" = frame 3 with inputs 0 and 1;
// a late set is marked "L").
std::vector<std::string> drain(Synchronizer& sync, Clock::time_point now = Clock::now()) {
  std::vector<std::string> sets;
  SyncSet set;
  while (sync.pop(now, set)) {
    std::string text = std::to_string(set.key) + ":";
    for (std::size_t i = 0; i < set.packets.size(); ++i) {
      if (set.has(i)) text += std::to_string(i);
    }
    sets.push_back(set.late ? text + "L" : text);
  }
  return sets;
}

using Sets = std::vector<std::string>;

TEST(Synchronizer, FramesJoinInAnyArrivalOrder) {
  Synchronizer sync(2, {});
  const auto now = Clock::now();
  sync.push(1, message(0), now);  // the 3D of frame 0 first
  EXPECT_EQ(drain(sync), Sets{});
  sync.push(0, message(0), now);
  sync.push(0, message(1), now);
  EXPECT_EQ(drain(sync), Sets{"0:01"});
  sync.push(1, message(1), now);
  EXPECT_EQ(drain(sync), Sets{"1:01"});
  EXPECT_EQ(sync.stats().sets, 2u);
  EXPECT_EQ(sync.stats().complete, 2u);
  EXPECT_EQ(sync.stats().inputs[0].missing + sync.stats().inputs[1].missing, 0u);
  EXPECT_EQ(sync.stats().inputs[0].held, 0u);
}

TEST(Synchronizer, AFrameSkippedByOneStreamGoesOnPartialOnceThatStreamPassedIt) {
  Synchronizer sync(2, {});
  const auto now = Clock::now();
  sync.push(0, message(0), now);
  sync.push(0, message(2), now);  // stream 0 skipped frame 1 (a drop on a lossy edge)
  sync.push(1, message(0), now);
  sync.push(1, message(1), now);
  sync.push(1, message(2), now);
  EXPECT_EQ(drain(sync), (Sets{"0:01", "1:1", "2:01"}));
  EXPECT_EQ(sync.stats().inputs[0].missing, 1u);
  EXPECT_EQ(sync.stats().inputs[1].missing, 0u);
  EXPECT_EQ(sync.stats().complete, 2u);
}

TEST(Synchronizer, AnInputThatMovedPastASetSettlesItEvenWhenItHoldsNothing) {
  Synchronizer sync(2, {});
  const auto now = Clock::now();
  sync.push(1, message(5), now);
  EXPECT_EQ(drain(sync), Sets{});  // input 0 may still send frame 5
  sync.push(0, message(5), now);
  sync.push(0, message(6), now);
  EXPECT_EQ(drain(sync), Sets{"5:01"});
  sync.push(1, message(6), now);
  sync.push(1, message(7), now);  // input 0 holds nothing, but input 1 moved past 6
  EXPECT_EQ(drain(sync), Sets{"6:01"});
  sync.push(0, message(8), now);  // 0 passed 7: it can never come
  EXPECT_EQ(drain(sync), Sets{"7:1"});
}

TEST(Synchronizer, EndOfStreamClosesTheSetsOfThatInput) {
  Synchronizer sync(3, {});
  const auto now = Clock::now();
  for (int f = 0; f < 3; ++f) {
    sync.push(0, message(f), now);
    sync.push(1, message(f), now);
  }
  EXPECT_EQ(drain(sync), Sets{});  // input 2 (the video) may still come
  sync.end(2);
  EXPECT_EQ(drain(sync), (Sets{"0:01", "1:01", "2:01"}));
  EXPECT_FALSE(sync.finished());
  sync.end(0);
  sync.end(1);
  EXPECT_TRUE(sync.finished());
  EXPECT_EQ(sync.stats().inputs[2].missing, 3u);
}

// The overlay's case: the 3D comes long after the 2D. With the bound above the lag nothing goes
// on partial; the 2D input is simply held.
TEST(Synchronizer, ALagWithinTheBoundJoinsEverySet) {
  Synchronizer sync(2, {SyncKey::frame, 0, 0ns, 128, AtBound::pass_partial});
  const auto now = Clock::now();
  Sets sets;
  for (int f = 0; f < 400; ++f) {
    sync.push(0, message(f), now);
    if (f >= 100) sync.push(1, message(f - 100), now);  // 100 frames behind
    for (const auto& s : drain(sync)) sets.push_back(s);
  }
  for (int f = 300; f < 400; ++f) sync.push(1, message(f), now);
  sync.end(0);
  sync.end(1);
  for (const auto& s : drain(sync)) sets.push_back(s);
  ASSERT_EQ(sets.size(), 400u);
  EXPECT_EQ(sets.front(), "0:01");
  EXPECT_EQ(sets.back(), "399:01");
  EXPECT_EQ(sync.stats().complete, 400u);
  EXPECT_EQ(sync.stats().inputs[0].max_held, 101u);
  EXPECT_TRUE(sync.finished());
}

TEST(Synchronizer, AtTheBoundAFullInputIsNotReadWhileItsSetWaits) {
  Synchronizer sync(2, {SyncKey::frame, 0, 0ns, 4, AtBound::wait});
  const auto now = Clock::now();
  for (int f = 0; f < 4; ++f) sync.push(0, message(f), now);
  EXPECT_FALSE(sync.readable(0));  // its edge fills and the producer waits: nothing is lost
  EXPECT_TRUE(sync.readable(1));
  EXPECT_EQ(drain(sync), Sets{});
  sync.push(1, message(0), now);
  EXPECT_EQ(drain(sync), Sets{"0:01"});
  EXPECT_TRUE(sync.readable(0));
  EXPECT_EQ(sync.stats().inputs[0].max_held, 4u);
}

// Branches of one source whose lag exceeds the bound: the oldest set goes on partial and its
// late part follows alone; every message is passed on once and counted.
TEST(Synchronizer, AtTheBoundThePassPartialPolicyDeliversLatePartsAlone) {
  Synchronizer sync(2, {SyncKey::frame, 0, 0ns, 4, AtBound::pass_partial});
  const auto now = Clock::now();
  Sets sets;
  for (int f = 0; f < 6; ++f) {
    sync.push(0, message(f), now);
    for (const auto& s : drain(sync)) sets.push_back(s);
  }
  // Each time input 0 reached 4 held messages its oldest frame went on without input 1.
  EXPECT_EQ(sets, (Sets{"0:0", "1:0", "2:0"}));
  EXPECT_EQ(sync.stats().inputs[0].held, 3u);
  EXPECT_EQ(sync.stats().inputs[0].max_held, 4u);
  for (int f = 0; f < 6; ++f) {
    sync.push(1, message(f), now);
    for (const auto& s : drain(sync)) sets.push_back(s);
  }
  EXPECT_EQ(sets, (Sets{"0:0", "1:0", "2:0", "0:1L", "1:1L", "2:1L", "3:01", "4:01", "5:01"}));
  EXPECT_EQ(sync.stats().inputs[1].missing, 3u);
  EXPECT_EQ(sync.stats().inputs[1].late, 3u);
  EXPECT_EQ(sync.stats().complete, 3u);
  EXPECT_EQ(sync.stats().sets, 9u);
}

TEST(Synchronizer, CaptureTimesWithinTheToleranceJoin) {
  // Two cameras at 30 fps, the second 4 ms later; a tolerance of 10 ms.
  Synchronizer sync(2, {SyncKey::capture_time, 10'000'000, 0ns, 64, AtBound::wait});
  const auto now = Clock::now();
  const std::int64_t start = 1'700'000'000'000'000'000;
  for (int f = 0; f < 3; ++f) {
    sync.push(0, message(f, start + f * 33'333'333), now);
    sync.push(1, message(100 + f, start + f * 33'333'333 + 4'000'000), now);
  }
  sync.push(1, message(103, start + 3 * 33'333'333 + 4'000'000), now);
  const Sets sets = drain(sync);
  ASSERT_EQ(sets.size(), 3u);
  EXPECT_EQ(sync.stats().complete, 3u);
  // A frame of camera 1 that came 15 ms after camera 0's is its own set.
  Synchronizer strict(2, {SyncKey::capture_time, 10'000'000, 0ns, 64, AtBound::wait});
  strict.push(0, message(0, start), now);
  strict.push(1, message(0, start + 15'000'000), now);
  strict.push(0, message(1, start + 33'333'333), now);
  strict.push(1, message(1, start + 48'333'333), now);
  const Sets apart = drain(strict);
  ASSERT_GE(apart.size(), 2u);
  EXPECT_EQ(apart[0].substr(apart[0].find(':')), ":0");
  EXPECT_EQ(apart[1].substr(apart[1].find(':')), ":1");
}

// The skew of a set: its newest minus its oldest capture time; sets of one member or without
// capture times (0) give none.
TEST(Synchronizer, EachSetsSkewIsCountedWithItsPercentilesAndMaximum) {
  Synchronizer sync(3, {SyncKey::capture_time, 10'000'000, 0ns, 64, AtBound::wait});
  const auto now = Clock::now();
  for (std::int64_t i = 0; i < 100; ++i) {
    const std::int64_t t = 1'000'000'000 + i * 33'000'000;
    sync.push(0, message(i, t), now);
    sync.push(1, message(i, t + 1'000'000), now);                      // 1 ms after
    sync.push(2, message(i, t + (i == 50 ? 9 : 2) * 1'000'000), now);  // 2 ms, once 9 ms
  }
  const Sets sets = drain(sync);
  EXPECT_EQ(sets.size(), 100u);
  SyncStats stats = sync.stats();
  EXPECT_EQ(stats.skew_sets, 100u);
  EXPECT_DOUBLE_EQ(stats.skew_p50_ms, 2.0);
  EXPECT_DOUBLE_EQ(stats.skew_p95_ms, 2.0);
  EXPECT_DOUBLE_EQ(stats.skew_max_ms, 9.0);
  EXPECT_NE(format_sync_stats(stats).find("skew p50 2.0 ms p95 2.0 ms max 9.0 ms"),
            std::string::npos)
      << format_sync_stats(stats);
  // Without capture times: no skew.
  Synchronizer frames(2, {});
  frames.push(0, message(0), now);
  frames.push(1, message(0), now);
  EXPECT_EQ(drain(frames), Sets{"0:01"});
  EXPECT_EQ(frames.stats().skew_sets, 0u);
  EXPECT_EQ(format_sync_stats(frames.stats()).find("skew"), std::string::npos);
}

TEST(Synchronizer, AWallClockWaitLimitPassesAStalledSetOnAndItsLatePartAlone) {
  Synchronizer sync(2, {SyncKey::capture_time, 5'000'000, 50ms, 64, AtBound::wait});
  const auto t0 = Clock::now();
  sync.push(0, message(0, 1'000'000'000), t0);
  ASSERT_TRUE(sync.deadline());
  EXPECT_EQ(*sync.deadline(), t0 + 50ms);
  EXPECT_EQ(drain(sync, t0 + 49ms), Sets{});
  EXPECT_EQ(drain(sync, t0 + 50ms), Sets{"1000000000:0"});
  EXPECT_FALSE(sync.deadline());
  sync.push(1, message(0, 1'003'000'000), t0 + 60ms);  // camera 1 finally delivers that frame
  EXPECT_EQ(drain(sync, t0 + 60ms), Sets{"1003000000:1L"});
  EXPECT_EQ(sync.stats().inputs[1].missing, 1u);
  EXPECT_EQ(sync.stats().inputs[1].late, 1u);
}

TEST(Synchronizer, LateMessagesDropIsCountedAndNothingIsPassedTwiceForAFrame) {
  // A node making one output per set (multiview.reconstruct) drops a view that comes after its
  // set went on: frame 0 is passed on once, partial; the late view is counted, not passed alone.
  SyncOptions options;
  options.wait = 50ms;
  options.late = LateMessages::drop;
  Synchronizer sync(2, options);
  const auto t0 = Clock::now();
  sync.push(0, message(0), t0);
  EXPECT_EQ(drain(sync, t0 + 50ms), Sets{"0:0"});
  sync.push(1, message(0), t0 + 60ms);  // its set went on without it
  sync.push(0, message(1), t0 + 60ms);
  sync.push(1, message(1), t0 + 60ms);
  EXPECT_EQ(drain(sync, t0 + 60ms), Sets{"1:01"});
  const SyncStats stats = sync.stats();
  EXPECT_EQ(stats.sets, 2u);
  EXPECT_EQ(stats.inputs[1].late, 1u);
  EXPECT_EQ(stats.inputs[1].late_dropped, 1u);
  EXPECT_NE(format_sync_stats(stats).find("1 late (1 dropped)"), std::string::npos)
      << format_sync_stats(stats);
}

TEST(Synchronizer, ARestartedStreamPassesOnWhatIsHeldAndJoinsAfresh) {
  Synchronizer sync(2, {});
  const auto now = Clock::now();
  sync.push(0, message(500), now);
  sync.push(0, message(501), now);
  sync.push(1, message(500), now);
  EXPECT_EQ(drain(sync), Sets{"500:01"});
  sync.push(0, message(0), now);  // input 0's producer restarted: frame numbers from 0
  EXPECT_EQ(drain(sync), Sets{"501:0"});
  EXPECT_EQ(sync.stats().restarts, 1u);
  sync.push(1, message(0), now);  // and input 1's
  sync.push(0, message(1), now);
  sync.push(1, message(1), now);
  EXPECT_EQ(drain(sync), (Sets{"0:01", "1:01"}));
  EXPECT_EQ(sync.stats().restarts, 1u);  // input 1 went 500 -> 0 after the reset: no second one
}

TEST(Synchronizer, DuplicateAndExtremeKeysDoNotBreakIt) {
  Synchronizer sync(2, {SyncKey::frame, 0, 0ns, 8, AtBound::pass_partial});
  const auto now = Clock::now();
  const auto low = std::numeric_limits<std::int64_t>::min();
  const auto high = std::numeric_limits<std::int64_t>::max();
  sync.push(0, message(low), now);
  sync.push(1, message(high), now);
  sync.push(0, message(high), now);
  sync.push(0, message(high), now);  // the same frame twice
  sync.end(0);
  sync.end(1);
  std::size_t passed = 0;
  for (const auto& s : drain(sync)) passed += s.size() - s.find(':') - 1 - (s.back() == 'L');
  EXPECT_EQ(passed, 4u);  // every message passed on exactly once
  EXPECT_TRUE(sync.finished());
}

TEST(Synchronizer, RefusesNoInputsAndAZeroBound) {
  EXPECT_THROW(Synchronizer(0, {}), std::invalid_argument);
  EXPECT_THROW(Synchronizer(2, {SyncKey::frame, 0, 0ns, 0, AtBound::wait}), std::invalid_argument);
}

// Before the synchroniser, the overlay kept 64 pending frames and dropped the rest; a video frame
// the detector skipped was let go. Now such a frame is a partial set (the overlay draws nothing
// for it), and nothing is dropped while the lag stays within the bound.
TEST(Synchronizer, OverlayInputsVideoFramesWithoutPeopleArePartialSets) {
  Synchronizer sync(3, {SyncKey::frame, 0, 0ns, 64, AtBound::pass_partial});
  const auto now = Clock::now();
  sync.push(2, message<VideoFrame>(0), now);  // the detector skipped this one
  sync.push(2, message<VideoFrame>(1), now);
  sync.push(0, message(1), now);
  sync.push(1, message<People3D>(1), now);
  EXPECT_EQ(drain(sync), (Sets{"0:2", "1:012"}));
  EXPECT_EQ(sync.stats().complete, 1u);
}

}  // namespace
}  // namespace mocap::graph
