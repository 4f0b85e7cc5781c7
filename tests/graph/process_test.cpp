// End-to-end tests that drive the built `mocap` binary in real processes: one process versus two
// (ipc:// and tcp://), SIGTERM, supervisor restarts, failures, validation messages, plugins and
// garbage on a live socket. Every wait is bounded and every child is killed and reaped at the end.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <zmq.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <optional>
#include <regex>
#include <thread>

#include "graph_test_util.hpp"
#include "support/mocap_process.hpp"

namespace mocap::graph {
namespace {

using namespace std::chrono_literals;
using test::Mocap;
using testing::TempDir;

std::string endpoint(const std::string& kind, const TempDir& dir, const std::string& name) {
  if (kind == "ipc") return "ipc://" + dir.file(name);
  return "tcp://127.0.0.1:" + std::to_string(testing::free_tcp_port());
}

// Counter and frames in process `capture`, their consumers in `solve`.
std::string split_graph(const TempDir& dir, const std::string& kind, long count,
                        double interval_ms) {
  return "graph: split\nnodes:\n"
         "  src:    { type: test.counter, params: { count: " +
         std::to_string(count) + ", interval_ms: " + std::to_string(interval_ms) +
         ", people: 2 } }\n"
         "  cam:    { type: test.frames, params: { count: 10, width: 320, height: 240 } }\n"
         "  pass:   { type: flow.pass_through }\n"
         "  sink:   { type: test.collect, params: { path: " +
         dir.file("sink.txt") +
         " } }\n"
         "  images: { type: test.collect, params: { path: " +
         dir.file("images.txt") +
         " } }\n"
         "edges:\n"
         "  - [src.out, pass.in, { transport: \"" +
         endpoint(kind, dir, "people") +
         "\" }]\n"
         "  - [pass.out, sink.in]\n"
         "  - [cam.frames, images.in, { transport: \"" +
         endpoint(kind, dir, "frames") +
         "\", policy: blocking(2) }]\n"
         "processes:\n  capture: [src, cam]\n  solve: [pass, sink, images]\n";
}

void expect_contiguous_from_zero(const std::vector<std::string>& lines) {
  for (std::size_t i = 0; i < lines.size(); ++i) {
    ASSERT_EQ(testing::fields(lines[i])[1], std::to_string(i)) << "line " << i;
  }
}

class SplitGraph : public ::testing::TestWithParam<std::string> {};

TEST_P(SplitGraph, SameGraphInOneProcessAndSplitOverTwoGivesIdenticalOutputs) {
  TempDir dir;
  const std::string graph = dir.file("g.yaml");
  testing::write_file(graph, split_graph(dir, GetParam(), 1000, 0));
  Mocap single(dir, "single",
               {"run", graph, "--single-process", "--set", "sink.path=" + dir.file("one.txt"),
                "--set", "images.path=" + dir.file("one-images.txt")});
  ASSERT_EQ(single.wait(60s), 0) << single.err();
  Mocap split(dir, "split",
              {"run", graph, "--set", "sink.path=" + dir.file("two.txt"), "--set",
               "images.path=" + dir.file("two-images.txt")});
  ASSERT_EQ(split.wait(60s), 0) << split.err();
  EXPECT_NE(split.err().find("started group 'solve'"), std::string::npos);  // really two processes
  EXPECT_EQ(testing::read_lines(dir.file("one.txt")).size(), 1000u);
  EXPECT_EQ(testing::read_file(dir.file("one.txt")), testing::read_file(dir.file("two.txt")));
  EXPECT_EQ(testing::read_lines(dir.file("one-images.txt")).size(), 10u);
  EXPECT_EQ(testing::read_file(dir.file("one-images.txt")),
            testing::read_file(dir.file("two-images.txt")));
}

TEST_P(SplitGraph, SigtermToTheSupervisorDrainsEveryGroupAndExitsZero) {
  TempDir dir;
  const std::string graph = dir.file("g.yaml");
  testing::write_file(graph, split_graph(dir, GetParam(), 0, 2));
  Mocap run(dir, "run", {"run", graph});
  // Both groups up (their libraries loaded, their signal watchers on), then messages flow.
  ASSERT_TRUE(run.wait_for_log(R"(\[capture\]: running)", 30s)) << run.err();
  ASSERT_TRUE(run.wait_for_log(R"(\[solve\]: running)", 30s)) << run.err();
  std::this_thread::sleep_for(1s);
  kill(run.pid(), SIGTERM);
  ASSERT_EQ(run.wait(60s), 0) << run.err();
  const auto lines = testing::read_lines(dir.file("sink.txt"));
  EXPECT_GT(lines.size(), 5u);
  expect_contiguous_from_zero(lines);
}

TEST_P(SplitGraph, KillingOneProcessOfASupervisedGraphRestartsIt) {
  TempDir dir;
  const std::string graph = dir.file("g.yaml");
  testing::write_file(graph, split_graph(dir, GetParam(), 1500, 2));
  Mocap run(dir, "run", {"run", graph});
  const auto pid = run.wait_for_log(R"(started group 'solve' \(pid (\d+)\))", 20s);
  ASSERT_TRUE(pid) << run.err();
  std::this_thread::sleep_for(500ms);
  ASSERT_EQ(kill(std::stoi(*pid), SIGKILL), 0);
  ASSERT_TRUE(run.wait_for_log("group 'solve' killed by signal 9; restarting", 20s)) << run.err();
  ASSERT_TRUE(run.wait_for_log("started group 'solve'", 20s, 2)) << run.err();
  ASSERT_EQ(run.wait(90s), 0) << run.err();
  // The restarted group received the rest of the stream, through to the end.
  const auto lines = testing::read_lines(dir.file("sink.txt"));
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(testing::fields(lines.back())[1], "1499");
}

INSTANTIATE_TEST_SUITE_P(IpcAndTcp, SplitGraph, ::testing::Values("ipc", "tcp"));

TEST(Process, SigtermMidRunFlushesTheSinksAndExitsZero) {
  TempDir dir;
  const std::string graph = dir.file("g.yaml");
  testing::write_file(
      graph,
      "nodes:\n  src: { type: test.counter, params: { count: 0, interval_ms: 2 } }\n"
      "  slow: { type: test.delay, params: { delay_ms: 1 } }\n"
      "  sink: { type: test.collect, params: { path: " +
          dir.file("out.txt") +
          " } }\n"
          "edges:\n  - [src.out, slow.in, { policy: blocking(100) }]\n  - [slow.out, sink.in]\n");
  Mocap run(dir, "run", {"run", graph});
  ASSERT_TRUE(run.wait_until_blocking(SIGTERM, 30s)) << run.err();
  std::this_thread::sleep_for(500ms);  // messages flow
  kill(run.pid(), SIGTERM);
  ASSERT_EQ(run.wait(30s), 0) << run.err();
  EXPECT_NE(run.err().find("stopping: draining"), std::string::npos) << run.err();
  const auto lines = testing::read_lines(dir.file("out.txt"));
  EXPECT_GT(lines.size(), 10u);
  expect_contiguous_from_zero(lines);
}

TEST(Process, SigtermWithAFullQueueBehindASlowNodeExitsWithinTheDrainDeadline) {
  TempDir dir;
  const std::string graph = dir.file("g.yaml");
  // 60 messages queued at 200 ms each would take 12 s to drain: the deadline (1.5 s) cuts it.
  testing::write_file(
      graph,
      "nodes:\n  src: { type: test.counter, params: { count: 0, interval_ms: 1 } }\n"
      "  slow: { type: test.delay, params: { delay_ms: 200 } }\n"
      "  sink: { type: test.collect, params: { path: " +
          dir.file("out.txt") +
          " } }\n"
          "edges:\n  - [src.out, slow.in, { policy: blocking(60) }]\n  - [slow.out, sink.in]\n");
  Mocap run(dir, "run", {"run", graph});
  ASSERT_TRUE(run.wait_until_blocking(SIGTERM, 30s)) << run.err();
  std::this_thread::sleep_for(1s);  // the queue fills
  const auto stop = std::chrono::steady_clock::now();
  kill(run.pid(), SIGTERM);
  ASSERT_EQ(run.wait(30s), 0) << run.err();
  const auto took = std::chrono::steady_clock::now() - stop;
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_LT(took, 6s) << run.err();
#else
  EXPECT_LT(took, 2s) << run.err();
#endif
  EXPECT_NE(run.err().find("queued message(s) not processed: the stop's drain deadline (1500 ms)"),
            std::string::npos)
      << run.err();
  const auto lines = testing::read_lines(dir.file("out.txt"));
  EXPECT_GE(lines.size(), 4u);  // what was processed before the deadline reached the sink
  expect_contiguous_from_zero(lines);
}

TEST(Process, NodeFailureExitsNonZeroNamingTheNode) {
  TempDir dir;
  const std::string graph = dir.file("g.yaml");
  testing::write_file(graph,
                      "nodes:\n  src: { type: test.counter, params: { count: 100 } }\n"
                      "  boom: { type: test.fail, params: { after: 3 } }\n"
                      "  sink: { type: test.collect, params: { path: " +
                          dir.file("out.txt") +
                          " } }\n"
                          "edges:\n  - [src.out, boom.in]\n  - [boom.out, sink.in]\n");
  Mocap run(dir, "run", {"run", graph});
  ASSERT_EQ(run.wait(30s), 1) << run.err();
  EXPECT_NE(run.err().find("node 'boom' (test.fail) failed"), std::string::npos) << run.err();
  EXPECT_EQ(testing::read_lines(dir.file("out.txt")).size(), 3u);
}

TEST(Process, GraphValidateInspectAndDot) {
  TempDir dir;
  const std::string bad = dir.file("bad.yaml");
  testing::write_file(bad,
                      "graph: bad\nnodes:\n  a: { type: no.such }\n  b: { type: test.counter, "
                      "params: { count: x } }\n");
  Mocap validate_bad(dir, "validate-bad", {"graph", "validate", bad});
  ASSERT_EQ(validate_bad.wait(30s), 1);
  EXPECT_NE(validate_bad.err().find(bad + ":3: node 'a': unknown node type 'no.such'"),
            std::string::npos)
      << validate_bad.err();
  EXPECT_NE(validate_bad.err().find(bad + ":4: node 'b': parameter 'count'"), std::string::npos)
      << validate_bad.err();

  const std::string good = dir.file("good.yaml");
  testing::write_file(good, split_graph(dir, "ipc", 10, 0));
  Mocap validate_good(dir, "validate-good", {"graph", "validate", good});
  ASSERT_EQ(validate_good.wait(30s), 0) << validate_good.err();
  EXPECT_NE(validate_good.out().find("ok (5 nodes, 3 edges, 2 processes)"), std::string::npos);

  Mocap inspect(dir, "inspect", {"graph", "inspect"});
  ASSERT_EQ(inspect.wait(30s), 0);
  EXPECT_NE(inspect.out().find("flow.limiter"), std::string::npos);
  Mocap inspect_one(dir, "inspect-one", {"graph", "inspect", "test.collect"});
  ASSERT_EQ(inspect_one.wait(30s), 0);
  EXPECT_NE(inspect_one.out().find("path : string (required)"), std::string::npos)
      << inspect_one.out();
  Mocap inspect_unknown(dir, "inspect-unknown", {"graph", "inspect", "no.such"});
  EXPECT_EQ(inspect_unknown.wait(30s), 1);

  Mocap dot(dir, "dot", {"graph", "dot", good});
  ASSERT_EQ(dot.wait(30s), 0);
  EXPECT_NE(dot.out().find("subgraph \"cluster_capture\""), std::string::npos) << dot.out();
  EXPECT_NE(dot.out().find("\"src\" -> \"pass\""), std::string::npos) << dot.out();
}

TEST(Process, PluginFromThePluginPathAndFromTheGraphFile) {
  TempDir dir;
  const std::string plugin = MOCAP_TEST_PLUGIN;
  const std::string body =
      "nodes:\n  src: { type: test.counter, params: { count: 4 } }\n"
      "  tag: { type: plugin.tag, params: { stream: from_plugin } }\n"
      "  sink: { type: test.collect, params: { path: " +
      dir.file("out.txt") +
      " } }\n"
      "edges:\n  - [src.out, tag.in]\n  - [tag.out, sink.in]\n";
  testing::write_file(dir.file("env.yaml"), body);
  testing::write_file(dir.file("key.yaml"), body + "plugins: [" + plugin + "]\n");

  Mocap without(dir, "without", {"graph", "validate", dir.file("env.yaml")});
  ASSERT_EQ(without.wait(30s), 1);
  EXPECT_NE(without.err().find("unknown node type 'plugin.tag'"), std::string::npos)
      << without.err();

  const std::string plugin_dir = std::filesystem::path(plugin).parent_path().string();
  Mocap from_env(dir, "env", {"run", dir.file("env.yaml")},
                 {"MOCAP_PLUGIN_PATH=/nonexistent:" + plugin_dir});
  ASSERT_EQ(from_env.wait(30s), 0) << from_env.err();
  auto lines = testing::read_lines(dir.file("out.txt"));
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(testing::fields(lines[0])[0], "from_plugin");

  std::filesystem::remove(dir.file("out.txt"));
  Mocap from_key(dir, "key", {"run", dir.file("key.yaml")});
  ASSERT_EQ(from_key.wait(30s), 0) << from_key.err();
  EXPECT_EQ(testing::read_lines(dir.file("out.txt")).size(), 4u);
}

TEST(Process, GarbageSentToARunningGraphIsRejectedWithAMessage) {
  TempDir dir;
  const std::string graph = dir.file("g.yaml");
  testing::write_file(graph, split_graph(dir, "ipc", 50, 0));
  Mocap solve(dir, "solve", {"run", graph, "--process", "solve"});
  // Speak ZeroMQ to its people edge, but not the wire format.
  void* context = zmq_ctx_new();
  void* raw = zmq_socket(context, ZMQ_DEALER);
  // Sent before `solve` may have bound (a slow start: a loaded machine, a sanitizer build); the
  // linger keeps them queued until it has, for at most 20 s.
  const int linger = 20000;
  zmq_setsockopt(raw, ZMQ_LINGER, &linger, sizeof linger);
  ASSERT_EQ(zmq_connect(raw, ("ipc://" + dir.file("people")).c_str()), 0);
  for (const char* junk :
       {"hello", "MOCP\x03\x00garbage-with-a-plausible-start-but-version-3-and-too-short"}) {
    zmq_send(raw, junk, std::strlen(junk), 0);
  }
  zmq_close(raw);
  zmq_ctx_term(context);
  ASSERT_TRUE(solve.wait_for_log("rejected a malformed message \\(2 so far\\)", 20s))
      << solve.err();
  Mocap capture(dir, "capture", {"run", graph, "--process", "capture"});
  ASSERT_EQ(capture.wait(30s), 0) << capture.err();
  ASSERT_EQ(solve.wait(30s), 0) << solve.err();
  EXPECT_EQ(testing::read_lines(dir.file("sink.txt")).size(), 50u);
}

}  // namespace
}  // namespace mocap::graph
