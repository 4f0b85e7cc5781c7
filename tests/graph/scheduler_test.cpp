// The in-process scheduler: ordering through blocking edges, bounded latency and counted drops on
// lossy edges, end of stream through fan-out and fan-in, failures, stop requests, statistics.

#include <gtest/gtest.h>

#include <thread>

#include "graph/inbox.hpp"
#include "graph/runtime.hpp"
#include "graph_test_util.hpp"

namespace mocap::graph {
namespace {

using testing::TempDir;

// Two inputs of any type, both forwarded: end of stream must wait for both.
class Zip : public Node {
 public:
  static void contract(Contract& c) {
    c.input_any("a");
    c.input_any("b");
    c.input_any("spare", "never connected", PortFlag::optional);
    c.output_same_as("out", "a");
  }
  void process(Context& ctx) override { ctx.forward("out", ctx.input_port()); }
};
MOCAP_REGISTER_NODE("unit.zip", Zip)

// Builds a new message without a header: it must inherit the input's.
class Relabel : public Node {
 public:
  static void contract(Contract& c) {
    c.input<People2D>("in");
    c.output<People2D>("out");
  }
  void process(Context& ctx) override {
    People2D fresh;
    fresh.people = ctx.input<People2D>("in").people;
    ctx.send("out", std::move(fresh));
  }
};
MOCAP_REGISTER_NODE("unit.relabel", Relabel)

// Sends the wrong type on its output: a bug the framework must report, naming the node.
class WrongType : public Node {
 public:
  static void contract(Contract& c) {
    c.input<People2D>("in");
    c.output<People3D>("out");
  }
  void process(Context& ctx) override { ctx.send("out", People2D{}); }
};
MOCAP_REGISTER_NODE("unit.wrong_type", WrongType)

ResolvedGraph graph_from(const std::string& text) {
  return resolve(parse_graph_text(text, "test.yaml"));
}

const NodeStats& stats_of(const RunResult& result, const std::string& node) {
  for (const NodeStats& s : result.stats.nodes) {
    if (s.node == node) return s;
  }
  throw std::runtime_error("no stats for " + node);
}

RunResult run(const std::string& text, RunOptions options = {}) {
  Runtime runtime(graph_from(text), std::move(options));
  return runtime.run();
}

TEST(Scheduler, TenThousandMessagesThroughBlockingEdgesAllArriveInOrder) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  src: { type: test.counter, params: { count: 10000 } }
  a:   { type: flow.pass_through }
  b:   { type: flow.pass_through }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [src.out, a.in, { policy: blocking(2) }]
  - [a.out, b.in, { policy: blocking(1) }]
  - [b.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const auto lines = testing::read_lines(dir.file("out.txt"));
  ASSERT_EQ(lines.size(), 10000u);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    ASSERT_EQ(testing::fields(lines[i])[1], std::to_string(i)) << "line " << i;
  }
  for (const char* node : {"a", "b", "sink"}) {
    EXPECT_EQ(stats_of(result, node).in, 10000u) << node;
    EXPECT_EQ(stats_of(result, node).drops, 0u) << node;
  }
  EXPECT_LE(stats_of(result, "b").max_queue_depth, 2u);  // blocking(1) plus end of stream
  EXPECT_EQ(stats_of(result, "src").out, 10000u);
}

TEST(Scheduler, SlowConsumerOnLatestEdgeKeepsLatencyBoundedAndCountsDrops) {
  TempDir dir;
  // 400 messages at 2 ms into a 25 ms stage: an unbounded queue would reach ~9 s of latency.
  const RunResult result = run(R"(
nodes:
  src:  { type: test.counter, params: { count: 400, interval_ms: 2 } }
  slow: { type: test.delay, params: { delay_ms: 25 } }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"(, timing: true } }
edges:
  - [src.out, slow.in, { policy: latest }]
  - [slow.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const auto lines = testing::read_lines(dir.file("out.txt"));
  const NodeStats& slow = stats_of(result, "slow");
  EXPECT_GT(slow.drops, 0u);
  EXPECT_EQ(slow.in + slow.drops, 400u);  // every message was either processed or counted
  EXPECT_LE(slow.max_queue_depth, 2u);    // one waiting message plus end of stream
  ASSERT_EQ(lines.size(), slow.in);
  EXPECT_EQ(testing::fields(lines.back())[1], "399");  // the newest message always wins
  long previous = -1;
  for (const std::string& line : lines) {
    const auto f = testing::fields(line);
    EXPECT_GT(std::stol(f[1]), previous);  // order kept
    previous = std::stol(f[1]);
    EXPECT_LT(std::stod(f[6]), 1.5e6) << line;  // generous: ~2 x 25 ms expected, seconds if queued
  }
}

TEST(Scheduler, StatisticsShowWhereMessagesWaitAndWhoIsHeldBack) {
  TempDir dir;
  // 60 messages as fast as possible into a 5 ms stage behind blocking(4): the stage's input
  // queue is full, each message waits there about 4 x 5 ms, and the pass-through feeding it
  // spends most of the run waiting for room (back-pressure), not working.
  const RunResult result = run(R"(
nodes:
  src:  { type: test.counter, params: { count: 60 } }
  feed: { type: flow.pass_through }
  slow: { type: test.delay, params: { delay_ms: 5 } }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [src.out, feed.in]
  - [feed.out, slow.in, { policy: blocking(4) }]
  - [slow.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& slow = stats_of(result, "slow");
  const NodeStats& feed = stats_of(result, "feed");
  const NodeStats& sink = stats_of(result, "sink");
  EXPECT_GT(slow.wait_p50_us, 10'000.0);  // about 4 messages x 5 ms ahead of each
  EXPECT_GE(slow.wait_p95_us, slow.wait_p50_us);
  EXPECT_LT(sink.wait_p50_us, slow.wait_p50_us);  // the sink keeps up
  EXPECT_GT(feed.blocked_s, 0.1);                 // ~55 messages x 5 ms held back
  EXPECT_LT(slow.blocked_s, 0.1);                 // nothing downstream of it is full
  const std::string table = format_stats_table(result.stats);
  EXPECT_NE(table.find("wait p95"), std::string::npos) << table;
  EXPECT_NE(table.find("blocked"), std::string::npos) << table;
}

TEST(Scheduler, DropOldestKeepsTheNewestAndCountsDrops) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  src:  { type: test.counter, params: { count: 200 } }
  slow: { type: test.delay, params: { delay_ms: 2 } }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [src.out, slow.in, { policy: drop_oldest(3) }]
  - [slow.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& slow = stats_of(result, "slow");
  EXPECT_GT(slow.drops, 0u);
  EXPECT_EQ(slow.in + slow.drops, 200u);
  EXPECT_LE(slow.max_queue_depth, 4u);
  const auto lines = testing::read_lines(dir.file("out.txt"));
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(testing::fields(lines.back())[1], "199");
}

TEST(Scheduler, EndOfStreamWaitsForEveryInputThroughFanOutAndFanIn) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  src:  { type: test.counter, params: { count: 300 } }
  fast: { type: flow.pass_through }
  slow: { type: test.delay, params: { delay_ms: 0.2 } }
  zip:  { type: unit.zip }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [src.out, fast.in]
  - [src.out, slow.in]
  - [fast.out, zip.a]
  - [slow.out, zip.b]
  - [zip.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(testing::read_lines(dir.file("out.txt")).size(), 600u);
  EXPECT_EQ(stats_of(result, "zip").in, 600u);
}

TEST(Scheduler, MessagesWithoutHeaderInheritTheInputHeader) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  src:  { type: test.counter, params: { count: 5, stream: cam7 } }
  re:   { type: unit.relabel }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [src.out, re.in]
  - [re.out, sink.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const auto lines = testing::read_lines(dir.file("out.txt"));
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(testing::fields(lines[3])[0], "cam7");
  EXPECT_EQ(testing::fields(lines[3])[1], "3");
}

TEST(Scheduler, NodeFailureStopsCleanlyNamingTheNodeAndFlushesSinks) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  src:  { type: test.counter, params: { count: 0, interval_ms: 1 } }
  boom: { type: test.fail, params: { after: 5 } }
  sink: { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
edges:
  - [src.out, boom.in, { policy: blocking(1) }]
  - [boom.out, sink.in]
)");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("node 'boom' (test.fail) failed in process: failing on purpose"),
            std::string::npos)
      << result.error;
  EXPECT_EQ(testing::read_lines(dir.file("out.txt")).size(), 5u);  // the sink still flushed
  EXPECT_EQ(stats_of(result, "boom").state, "failed");
}

TEST(Scheduler, SendingTheWrongTypeIsReportedAsAFailureOfThatNode) {
  const RunResult result = run(R"(
nodes:
  src: { type: test.counter, params: { count: 3 } }
  bad: { type: unit.wrong_type }
edges:
  - [src.out, bad.in]
)");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("node 'bad'"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("carries People3D, not People2D"), std::string::npos) << result.error;
}

TEST(Scheduler, StopRequestDrainsAndFlushesWithoutGaps) {
  TempDir dir;
  Runtime runtime(graph_from(R"(
nodes:
  src:  { type: test.counter, params: { count: 0, interval_ms: 1 } }
  slow: { type: test.delay, params: { delay_ms: 1 } }
  sink: { type: test.collect, params: { path: )" +
                             dir.file("out.txt") + R"( } }
edges:
  - [src.out, slow.in, { policy: blocking(64) }]
  - [slow.out, sink.in]
)"));
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    runtime.request_stop();
  });
  const RunResult result = runtime.run();
  stopper.join();
  EXPECT_TRUE(result.ok) << result.error;
  EXPECT_TRUE(result.stopped);
  const auto lines = testing::read_lines(dir.file("out.txt"));
  ASSERT_GT(lines.size(), 10u);
  EXPECT_EQ(lines.size(), stats_of(result, "src").out);  // everything sent was processed
  for (std::size_t i = 0; i < lines.size(); ++i)
    ASSERT_EQ(testing::fields(lines[i])[1], std::to_string(i));
}

TEST(Scheduler, StatisticsAreAStream) {
  TempDir dir;
  const RunResult result = run(R"(
nodes:
  src:   { type: test.counter, params: { count: 50, interval_ms: 2 } }
  sink:  { type: test.collect, params: { path: )" +
                               dir.file("out.txt") + R"( } }
  stats: { type: graph.stats, params: { period_ms: 20 } }
  report: { type: test.collect, params: { path: )" +
                               dir.file("stats.txt") + R"( } }
edges:
  - [src.out, sink.in]
  - [stats.out, report.in]
)");
  ASSERT_TRUE(result.ok) << result.error;
  const auto lines = testing::read_lines(dir.file("stats.txt"));
  ASSERT_GE(lines.size(), 1u);  // at least the final snapshot, sent when the rest has ended
  EXPECT_EQ(testing::fields(lines.back())[3], "GraphStats");
  EXPECT_EQ(stats_of(result, "stats").out, lines.size());
  EXPECT_NE(format_stats_table(result.stats).find("test.counter"), std::string::npos);
}

TEST(Inbox, EndOfStreamIsNeverDroppedAndClosingReleasesBlockedProducers) {
  Inbox inbox({EdgePolicy{PolicyKind::latest, 1}, EdgePolicy{PolicyKind::blocking, 1}});
  auto message = [](std::uint64_t seq) {
    auto m = std::make_shared<People2D>();
    m->header.seq = seq;
    return Packet::of<People2D>(m);
  };
  EXPECT_TRUE(inbox.push(0, message(1)));
  EXPECT_TRUE(inbox.push(0, Packet::end_of_stream()));
  EXPECT_TRUE(inbox.push(0, message(2)));  // replaces 1, keeps the end of stream
  EXPECT_EQ(inbox.drops(), 1u);
  auto first = inbox.pop();
  ASSERT_TRUE(first);
  EXPECT_TRUE(first->packet.is_end_of_stream());  // queued before message 2
  EXPECT_EQ(inbox.pop()->packet.header().seq, 2u);

  EXPECT_TRUE(inbox.push(1, message(3)));
  std::thread blocked([&] { EXPECT_FALSE(inbox.push(1, message(4))); });  // full: waits
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  inbox.close();
  blocked.join();
  EXPECT_FALSE(inbox.pop());
}

TEST(Scheduler, PolicyTextRoundTrips) {
  for (const char* text : {"blocking(16)", "latest", "drop_oldest(4)"}) {
    EXPECT_EQ(parse_policy(text)->str(), text);
  }
}

}  // namespace
}  // namespace mocap::graph
