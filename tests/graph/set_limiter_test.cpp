// flow.set_limiter: cameras' frames joined by capture time and passed on as whole sets only while
// every stage after it is idle (graph/set_limiter.hpp). Alone in the harness (busy stages drop
// whole sets, the sets are numbered as frames, dropped ones counted), its repeated output checked
// by graph validation, and in a running graph with a stage slower than the cameras: every set
// the limiter passed reaches the join after the stages as it was (complete sets stay complete).

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>

#include "core/input_error.hpp"
#include "graph/harness.hpp"
#include "graph/runtime.hpp"
#include "graph/set_limiter.hpp"

namespace mocap::graph {
namespace {

VideoFrame frame(const std::string& camera, std::int64_t capture_ms, std::int64_t frame_number) {
  VideoFrame f;
  f.header = {camera, static_cast<std::uint64_t>(frame_number), capture_ms * 1'000'000,
              frame_number};
  f.camera = camera;
  f.image = ImageBuffer(4, 2, PixelFormat::gray8);
  return f;
}

TEST(SetLimiter, NumbersEverySetAndPassesOnlyWhileIdle) {
  constexpr std::int64_t kMs = 1'000'000;
  SetLimiter limiter(2, 200 * kMs);
  const std::vector<bool> both = {true, true}, first = {true, false};
  EXPECT_EQ(limiter.admit(both, 0, true), 0);
  EXPECT_EQ(limiter.admit(both, 33 * kMs, false), std::nullopt);  // busy
  // Camera 1 seen 33 ms ago: its frame fell outside this set (jitter), which is dropped.
  EXPECT_EQ(limiter.admit(first, 66 * kMs, true), std::nullopt);
  // Nothing from camera 1 for more than 200 ms: it is away, the other goes on alone.
  EXPECT_EQ(limiter.admit(first, 300 * kMs, true), 3);  // dropped sets keep their numbers
  EXPECT_EQ(limiter.counts().sets, 4u);
  EXPECT_EQ(limiter.counts().passed, 2u);
  EXPECT_EQ(limiter.counts().passed_complete, 1u);
  EXPECT_EQ(limiter.counts().dropped_busy, 1u);
  EXPECT_EQ(limiter.counts().dropped_partial, 1u);
  EXPECT_EQ(limiter.describe(),
            "passed 2 of 4 sets (1 complete), 1 dropped while the stage was busy, 1 partial");
  // A camera never seen is away: the others start without it.
  SetLimiter starting(2, 200 * kMs);
  EXPECT_EQ(starting.admit(first, 0, true), 0);
}

TEST(SetLimiter, NodeDropsWholeSetsWhileAnyStageIsBusy) {
  Harness limit("flow.set_limiter", {{"sync_tolerance_ms", "5"}},
                {{{"frames", 2}}, {}, {}, AtBound::wait});
  // Set 0 (both idle) passes; set 1 finds stream 1 busy: dropped whole, stream 0 included.
  limit.push("frames", frame("a", 100, 7), 0);
  limit.push("frames", frame("b", 102, 40), 1);
  limit.process_ready();
  limit.set_output_idle("frames", 1, false);
  limit.push("frames", frame("a", 133, 8), 0);
  limit.push("frames", frame("b", 135, 41), 1);
  limit.process_ready();
  limit.set_output_idle("frames", 1, true);
  limit.push("frames", frame("a", 166, 9), 0);
  limit.push("frames", frame("b", 168, 42), 1);
  limit.finish();
  const auto a = limit.pull<VideoFrame>("frames", 0), b = limit.pull<VideoFrame>("frames", 1);
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  // Each camera's frame of a set, renumbered by the set (the cameras' own counters differ).
  EXPECT_EQ(a[0]->header.frame, 0);
  EXPECT_EQ(b[0]->header.frame, 0);
  EXPECT_EQ(a[1]->header.frame, 2);
  EXPECT_EQ(b[1]->header.frame, 2);
  EXPECT_EQ(a[1]->header.capture_ns, 166'000'000);
  EXPECT_EQ(b[1]->camera, "b");
  EXPECT_EQ(limit.stats().drops, 2u);  // the two frames of set 1
  EXPECT_EQ(limit.status(),
            "passed 2 of 3 sets (2 complete), 1 dropped while the stage was busy, 0 partial");
}

// Camera a's frame waits alone past sync_wait_ms and goes on as set 0; camera b's frame of that
// instant then comes late. Returns the calls so far (1: set 0).
std::size_t push_set_that_goes_on_without_b(Harness& node, const std::string& input) {
  using namespace std::chrono_literals;
  node.push(input, frame("a", 100, 7), 0);
  std::size_t calls = node.process_ready();  // taken in: waits for b
  std::this_thread::sleep_for(60ms);
  calls += node.process_ready();             // its wait (30 ms) is over: on without b
  node.push(input, frame("b", 102, 40), 1);  // late
  node.push(input, frame("a", 133, 8), 0);
  node.push(input, frame("b", 135, 41), 1);
  return calls;
}

// A frame that comes after its set went on is counted late and dropped (the limiter's sync_late:
// drop). Passed on as a set of its own it would take a set number, and every later set's time
// (number x frame period) would be one period off.
TEST(SetLimiter, AFrameLaterThanItsSetIsDroppedAndTheSetNumbersKeepTime) {
  Harness limit("flow.set_limiter", {{"sync_wait_ms", "30"}},
                {{{"frames", 2}}, {}, {}, AtBound::wait});
  EXPECT_EQ(push_set_that_goes_on_without_b(limit, "frames"), 1u);
  limit.finish();
  const auto a = limit.pull<VideoFrame>("frames", 0), b = limit.pull<VideoFrame>("frames", 1);
  ASSERT_EQ(a.size(), 2u);  // set 0 (b never seen yet: away) and set 1
  ASSERT_EQ(b.size(), 1u);  // set 1 only
  EXPECT_EQ(a[0]->header.frame, 0);
  EXPECT_EQ(a[1]->header.frame, 1);
  EXPECT_EQ(b[0]->header.frame, 1);
  EXPECT_EQ(b[0]->header.capture_ns, 135'000'000);
  const NodeStats stats = limit.stats();
  EXPECT_EQ(stats.sync.inputs[1].late, 1u);
  EXPECT_EQ(stats.sync.inputs[1].late_dropped, 1u);
  EXPECT_EQ(stats.drops, 1u);
  EXPECT_EQ(limit.status(),
            "passed 2 of 2 sets (1 complete), 0 dropped while the stage was busy, 0 partial");
}

// sink.sets counts sets: a late frame is counted late and dropped, not counted as a set.
TEST(SetsSink, AFrameLaterThanItsSetIsDroppedNotCountedAsASet) {
  Harness sets("sink.sets", {{"sync_wait_ms", "30"}}, {{{"in", 2}}, {}, {}, AtBound::wait});
  EXPECT_EQ(push_set_that_goes_on_without_b(sets, "in"), 1u);
  sets.finish();
  const NodeStats stats = sets.stats();
  EXPECT_EQ(stats.sync.sets, 2u);
  EXPECT_EQ(stats.sync.complete, 1u);
  EXPECT_EQ(stats.sync.inputs[1].late, 1u);
  EXPECT_EQ(stats.sync.inputs[1].late_dropped, 1u);
  EXPECT_EQ(stats.drops, 1u);
}

TEST(SetLimiter, RepeatedOutputStreamsFollowTheInputsEdges) {
  const std::string nodes = R"(
nodes:
  a: { type: test.frames, params: { count: 1 } }
  b: { type: test.frames, params: { count: 1 } }
  limit: { type: flow.set_limiter }
  x: { type: flow.pass_through }
  y: { type: flow.pass_through }
edges:
  - [a.frames, limit.frames:0]
  - [b.frames, limit.frames:1]
)";
  EXPECT_NO_THROW(resolve(parse_graph_text(
      nodes + "  - [limit.frames:0, x.in]\n  - [limit.frames:1, y.in]\n", "ok.yaml")));
  const auto error_of = [&](const std::string& edges) {
    try {
      resolve(parse_graph_text(nodes + edges, "bad.yaml"));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("  - [limit.frames, x.in]\n").find("is a repeated output"), std::string::npos);
  const std::string beyond = error_of("  - [limit.frames:2, x.in]\n");
  EXPECT_NE(beyond.find("limit.frames:2 has no stream"), std::string::npos) << beyond;
  EXPECT_NE(beyond.find("limit.frames:0..1"), std::string::npos) << beyond;
  EXPECT_NE(error_of("  - [a.frames:0, x.in]\n").find("an output takes no index"),
            std::string::npos);
}

// Three cameras triggered together at 20 fps, each behind a 120 ms stage (six frame periods):
// through the limiter every set the stages get is one instant of all cameras, so the join after
// them (by the limiter's numbers) sees exactly the sets the limiter passed, complete as they were.
TEST(SetLimiter, SetsThroughAStageSlowerThanTheCamerasJoinAsThePassed) {
  std::string text = "nodes:\n";
  for (int i = 0; i < 3; ++i) {
    const std::string n = std::to_string(i);
    text += "  cam" + n + ": { type: test.frames, params: { count: 40, fps: 20, aligned: true, " +
            "width: 8, height: 8, camera: cam" + n + " } }\n" + "  det" + n +
            ": { type: test.delay, params: { delay_ms: 120 } }\n";
  }
  text +=
      "  limit: { type: flow.set_limiter, params: { sync_tolerance_ms: 20 } }\n"
      "  sets: { type: sink.sets, params: { sync_by: frame, sync_wait_ms: 2000 } }\n"
      "edges:\n";
  for (int i = 0; i < 3; ++i) {
    const std::string n = std::to_string(i);
    text += "  - [cam" + n + ".frames, limit.frames:" + n + "]\n  - [limit.frames:" + n + ", det" +
            n + ".in]\n  - [det" + n + ".out, sets.in:" + n + "]\n";
  }
  Runtime runtime(resolve(parse_graph_text(text, "limiter.yaml")));
  const RunResult result = runtime.run();
  ASSERT_TRUE(result.ok) << result.error;
  SyncStats joined;
  std::string limiter;
  for (const NodeStats& n : result.stats.nodes) {
    if (n.node == "sets") joined = n.sync;
    if (n.node == "limit") limiter = n.status;
  }
  unsigned long long passed = 0, sets = 0, complete = 0, dropped = 0;
  ASSERT_EQ(std::sscanf(limiter.c_str(), "passed %llu of %llu sets (%llu complete), %llu dropped",
                        &passed, &sets, &complete, &dropped),
            4)
      << limiter;
  // Triggered together: one set per instant (a camera that opened a period late adds one).
  EXPECT_GE(sets, 40u) << limiter;
  EXPECT_LE(sets, 42u) << limiter;
  EXPECT_GE(dropped, 20u) << limiter;  // the stage takes one set in six at most
  EXPECT_GE(passed, 4u) << limiter;
  EXPECT_EQ(joined.sets, passed) << format_sync_stats(joined);
  EXPECT_EQ(joined.complete, complete) << format_sync_stats(joined);
  for (const auto& input : joined.inputs) EXPECT_EQ(input.late, 0u);
}

}  // namespace
}  // namespace mocap::graph
