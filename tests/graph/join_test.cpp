// Joined inputs in running graphs: branches of one source with very different latencies (the
// overlay's 2D and, behind a windowed fit, its 3D) join every frame within the bound and neither
// deadlock nor lose beyond it; independent sources wait at the bound; lossy edges make partial
// sets; repeated inputs; capture times; the same over inproc://, ipc:// and tcp:// edges.

#include <gtest/gtest.h>

#include <deque>

#include "graph/runtime.hpp"
#include "graph_test_util.hpp"

namespace mocap::graph {
namespace {

using testing::TempDir;

RunResult run(const std::string& text) {
  Runtime runtime(resolve(parse_graph_text(text, "test.yaml")));
  return runtime.run();
}

const NodeStats& stats_of(const RunResult& result, const std::string& node) {
  for (const NodeStats& s : result.stats.nodes) {
    if (s.node == node) return s;
  }
  throw std::runtime_error("no stats for " + node);
}

// src -> a (at once) and src -> window(100) -> b: the b branch holds 100 frames and releases them
// at once, as the offline fit does.
std::string fan_out_graph(const std::string& out, int count, int bound,
                          const std::string& transport = "") {
  return R"(
nodes:
  src:    { type: test.counter, params: { count: )" +
         std::to_string(count) + R"( } }
  window: { type: unit.window, params: { size: 100 } }
  pair:   { type: unit.pair, params: { sync_bound: )" +
         std::to_string(bound) + R"( } }
  sink:   { type: test.collect, params: { path: )" +
         out + R"( } }
edges:
  - [src.out, pair.a]
  - [src.out, window.in]
  - [window.out, pair.b)" +
         (transport.empty() ? "" : ", { transport: \"" + transport + "\" }") + R"(]
  - [pair.out, sink.in]
)";
}

TEST(Join, BranchesOfOneSourceWithALagWithinTheBoundJoinEveryFrame) {
  TempDir dir;
  const RunResult result = run(fan_out_graph(dir.file("out.txt"), 600, 256));
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& pair = stats_of(result, "pair");
  EXPECT_EQ(pair.sync.sets, 600u);
  EXPECT_EQ(pair.sync.complete, 600u);
  ASSERT_EQ(pair.sync.inputs.size(), 2u);
  EXPECT_EQ(pair.sync.inputs[0].name, "a");
  EXPECT_EQ(pair.sync.inputs[1].missing, 0u);
  EXPECT_GE(pair.sync.inputs[0].max_held, 100u);  // a waited for the window
  EXPECT_LE(pair.sync.inputs[0].max_held, 256u);
  EXPECT_EQ(pair.drops, 0u);
  const auto lines = testing::read_lines(dir.file("out.txt"));
  ASSERT_EQ(lines.size(), 600u);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    ASSERT_EQ(testing::fields(lines[i])[2], std::to_string(i));  // frame order
  }
  EXPECT_NE(format_stats_table(result.stats).find("pair: joined 600 sets (600 complete)"),
            std::string::npos)
      << format_stats_table(result.stats);
}

// A bound below the lag: the source would wait for `pair`, and `window` for the source. The
// oldest set goes on with `a` alone instead, and its `b` follows late; nothing is lost.
TEST(Join, BranchesOfOneSourceBeyondTheBoundNeitherDeadlockNorLose) {
  TempDir dir;
  const RunResult result = run(fan_out_graph(dir.file("out.txt"), 600, 16));
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& pair = stats_of(result, "pair");
  EXPECT_EQ(pair.in, 1200u);  // every message of both inputs
  EXPECT_GT(pair.sync.inputs[1].missing, 0u);
  EXPECT_EQ(pair.sync.inputs[1].late, pair.sync.inputs[1].missing);
  EXPECT_EQ(pair.sync.complete + pair.sync.inputs[1].missing, 600u);
  EXPECT_EQ(pair.sync.sets, 600u + pair.sync.inputs[1].late);
  EXPECT_LE(pair.sync.inputs[0].max_held, 16u);
  EXPECT_EQ(pair.drops, 0u);
}

// Two sources that do not depend on each other: at the bound the full input is not read, its
// blocking edge fills and its producer waits; every set completes.
TEST(Join, IndependentSourcesWaitAtTheBoundAndJoinEveryFrame) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  fast: { type: test.counter, params: { count: 300 } }
  slow: { type: test.counter, params: { count: 300, interval_ms: 0.5 } }
  pair: { type: unit.pair, params: { sync_bound: 8 } }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [fast.out, pair.a, { policy: blocking(4) }]
  - [slow.out, pair.b]
  - [pair.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& pair = stats_of(result, "pair");
  EXPECT_EQ(pair.sync.complete, 300u);
  EXPECT_EQ(pair.sync.sets, 300u);
  EXPECT_LE(pair.sync.inputs[0].max_held, 8u);
  EXPECT_LE(pair.max_queue_depth, 4u + 16u + 2u);  // the two edges' capacities, ends of stream
  EXPECT_EQ(testing::read_lines(dir.file("out.txt")).size(), 300u);
}

// A drop on a lossy edge only makes its set partial.
TEST(Join, ADropOnALatestEdgeMakesAPartialSet) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  src:  { type: test.counter, params: { count: 200, interval_ms: 0.2 } }
  slow: { type: test.delay, params: { delay_ms: 2 } }
  pair: { type: unit.pair, params: { sync_bound: 1000 } }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [src.out, pair.a]
  - [src.out, slow.in, { policy: latest }]
  - [slow.out, pair.b]
  - [pair.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& pair = stats_of(result, "pair");
  const NodeStats& slow = stats_of(result, "slow");
  EXPECT_GT(slow.drops, 0u);
  EXPECT_EQ(pair.sync.sets, 200u);
  EXPECT_EQ(pair.sync.inputs[1].missing, slow.drops);  // each drop: one set without b
  EXPECT_EQ(pair.sync.inputs[1].late, 0u);
  EXPECT_EQ(pair.sync.complete, 200u - slow.drops);
}

TEST(Join, RepeatedInputsJoinTheirEdgesByIndex) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  cam0:  { type: test.counter, params: { count: 50, stream: cam0 } }
  cam1:  { type: test.counter, params: { count: 50, stream: cam1 } }
  cam2:  { type: test.counter, params: { count: 40, stream: cam2 } }
  views: { type: unit.views }
  sink:  { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [cam2.out, views.view:2]
  - [cam0.out, views.view:0]
  - [cam1.out, views.view:1]
  - [views.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& views = stats_of(result, "views");
  ASSERT_EQ(views.sync.inputs.size(), 3u);
  EXPECT_EQ(views.sync.inputs[2].name, "view:2");
  EXPECT_EQ(views.sync.complete, 40u);
  EXPECT_EQ(views.sync.inputs[2].missing, 10u);  // camera 2 ended early
  const auto lines = testing::read_lines(dir.file("out.txt"));
  ASSERT_EQ(lines.size(), 50u);
  // unit.views names its output stream by the views present, in index order.
  EXPECT_EQ(testing::fields(lines[0])[0], "cam0+cam1+cam2");
  EXPECT_EQ(testing::fields(lines[45])[0], "cam0+cam1");
}

TEST(Join, CaptureTimesJoinTheBranchesOfOneSource) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  src:  { type: test.counter, params: { count: 100, interval_ms: 0.5 } }
  slow: { type: test.delay, params: { delay_ms: 0.3 } }
  pair: { type: unit.pair, params: { sync_by: capture_time, sync_tolerance_ms: 0.01 } }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [src.out, pair.a]
  - [src.out, slow.in]
  - [slow.out, pair.b]
  - [pair.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(stats_of(result, "pair").sync.complete, 100u);
}

class JoinOverTransport : public ::testing::TestWithParam<std::string> {};

// Socket buffers add to the late branch's lag (hundreds of small messages in flight), so the bound
// here exceeds the whole stream: this checks the joining over sockets, not the bound.
TEST_P(JoinOverTransport, TheLateBranchOverASocketJoinsEveryFrame) {
  TempDir dir;
  const std::string kind = GetParam();
  const std::string endpoint = kind == "inproc" ? "inproc://join-test"
                               : kind == "ipc"
                                   ? "ipc://" + dir.file("join-edge")
                                   : "tcp://127.0.0.1:" + std::to_string(testing::free_tcp_port());
  const RunResult result = run(fan_out_graph(dir.file("out.txt"), 300, 1000, endpoint));
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& pair = stats_of(result, "pair");
  EXPECT_EQ(pair.sync.complete, 300u);
  EXPECT_EQ(testing::read_lines(dir.file("out.txt")).size(), 300u);
}

INSTANTIATE_TEST_SUITE_P(AllTransports, JoinOverTransport,
                         ::testing::Values("inproc", "ipc", "tcp"));

}  // namespace
}  // namespace mocap::graph
