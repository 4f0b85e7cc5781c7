// The single-node harness: messages in, messages out, in the test's thread or the node's own;
// parameters checked as in a graph file; the same synchroniser as the runtime; sources, failures,
// back-pressure on a blocking edge, statistics and status.

#include "graph/harness.hpp"

#include <gtest/gtest.h>

#include <thread>

#include "core/input_error.hpp"

namespace mocap::graph {
namespace {

using namespace std::chrono_literals;

People2D people(std::int64_t frame, std::string stream = "s") {
  People2D m;
  m.header = {std::move(stream), static_cast<std::uint64_t>(frame), 1000 * frame, frame};
  m.people.push_back(Person2D{static_cast<int>(frame), {}, {}});
  return m;
}

TEST(Harness, PassThroughSendsWhatItGetsUnchanged) {
  Harness pass("flow.pass_through");
  const auto first = std::make_shared<const People2D>(people(0));
  pass.push<People2D>("in", first);
  pass.push("in", people(1));
  pass.finish();
  const auto out = pass.pull<People2D>("out");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0], first);  // shared, not copied
  EXPECT_EQ(out[1]->header.frame, 1);
  EXPECT_TRUE(pass.ended("out"));
  EXPECT_EQ(pass.stats().in, 2u);
  EXPECT_EQ(pass.stats().out, 2u);
  EXPECT_EQ(pass.stats().state, "done");
  EXPECT_TRUE(pass.pull<People2D>("out").empty());  // pulled once
}

TEST(Harness, ParametersAreCheckedAsInAGraphFile) {
  EXPECT_THROW(Harness("no.such_type"), InputError);
  try {
    Harness("source.video", {{"path", "x.avi"}, {"mode", "ofline"}});
    FAIL() << "a mode that is no choice was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'ofline' is not one of offline, live, auto; did you mean 'offline'?"),
              std::string::npos)
        << message;
  }
  EXPECT_THROW(Harness("test.counter", {{"count", "-1"}}), InputError);
  EXPECT_THROW(Harness("test.collect"), InputError);  // a required parameter
  EXPECT_THROW(Harness("unit.views", {}, {{{"view", 9}}, {}, {}, AtBound::wait}),
               std::invalid_argument);  // 1 to 8 edges
}

TEST(Harness, SourcesRunUntilTheyFinish) {
  Harness counter("test.counter", {{"count", "5"}, {"stream", "cam3"}});
  EXPECT_EQ(counter.run_source(100), 6u);  // five messages, then ctx.finish()
  const auto out = counter.pull<People2D>("out");
  ASSERT_EQ(out.size(), 5u);
  EXPECT_EQ(out[4]->header.stream, "cam3");
  EXPECT_EQ(out[4]->header.seq, 4u);
  EXPECT_TRUE(counter.ended("out"));
}

TEST(Harness, JoinedInputsArriveAsSetsThroughTheSynchroniser) {
  Harness pair("unit.pair");
  pair.push("a", people(0));
  pair.push("b", people(0));
  pair.push("a", people(1));
  EXPECT_EQ(pair.process_ready(), 1u);  // frame 1 waits for b
  pair.push("a", people(2));
  pair.push("b", people(2));  // b skipped frame 1
  pair.finish();
  const auto out = pair.pull<People2D>("out");
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[1]->header.frame, 1);
  EXPECT_EQ(out[1]->people.size(), 1u);  // a alone
  const NodeStats stats = pair.stats();
  EXPECT_EQ(stats.sync.complete, 2u);
  EXPECT_EQ(stats.sync.inputs[1].name, "b");
  EXPECT_EQ(stats.sync.inputs[1].missing, 1u);
}

TEST(Harness, RepeatedInputsAreReadByIndex) {
  HarnessOptions options;
  options.repeated["view"] = 3;
  Harness views("unit.views", {}, options);
  for (std::int64_t f = 0; f < 2; ++f) {
    for (std::size_t v = 0; v < 3; ++v) {
      if (f == 1 && v == 1) continue;  // camera 1 lost frame 1
      views.push("view", people(f, "cam" + std::to_string(v)), v);
    }
  }
  views.finish();
  const auto out = views.pull<People2D>("out");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0]->header.stream, "cam0+cam1+cam2");
  EXPECT_EQ(out[1]->header.stream, "cam0+cam2");
  EXPECT_EQ(views.stats().sync.inputs[1].name, "view:1");
  EXPECT_THROW(views.push("view", people(3), 3), std::logic_error);  // no edge 3
}

TEST(Harness, AWaitLimitPassesAStalledSetOnInTheNodesThread) {
  Harness pair("unit.pair", {{"sync_wait_ms", "30"}});
  pair.start();
  pair.push("a", people(0));
  std::this_thread::sleep_for(200ms);  // b never comes within the limit
  EXPECT_EQ(pair.pull<People2D>("out").size(), 1u);
  pair.push("b", people(0));  // too late: alone
  pair.end_all();
  pair.join();
  EXPECT_EQ(pair.pull<People2D>("out").size(), 1u);
  EXPECT_EQ(pair.stats().sync.inputs[1].late, 1u);
}

// With a blocking(2) edge and the node in its own thread, the test is the producer: its pushes
// wait for the node, and nothing is lost or reordered.
TEST(Harness, ABlockingEdgeMakesThePusherWait) {
  HarnessOptions options;
  options.policies["in"] = EdgePolicy{PolicyKind::blocking, 2};
  Harness slow("test.delay", {{"delay_ms", "5"}}, options);
  slow.start();
  const auto start = std::chrono::steady_clock::now();
  for (std::int64_t f = 0; f < 10; ++f) slow.push("in", people(f));
  EXPECT_GE(std::chrono::steady_clock::now() - start, 25ms);  // waited for ~7 x 5 ms
  slow.end_all();
  slow.join();
  const auto out = slow.pull<People2D>("out");
  ASSERT_EQ(out.size(), 10u);
  for (std::int64_t f = 0; f < 10; ++f)
    EXPECT_EQ(out[static_cast<std::size_t>(f)]->header.frame, f);
  EXPECT_LE(slow.stats().max_queue_depth, 3u);
}

TEST(Harness, AFailureReachesTheTest) {
  Harness boom("test.fail", {{"after", "2"}});
  for (std::int64_t f = 0; f < 3; ++f) boom.push("in", people(f));
  EXPECT_THROW(boom.process_ready(), std::runtime_error);
  EXPECT_EQ(boom.pull<People2D>("out").size(), 2u);
  EXPECT_EQ(boom.stats().state, "failed");

  Harness threaded("test.fail", {{"after", "0"}});
  threaded.start();
  threaded.push("in", people(0));
  EXPECT_THROW(threaded.join(), std::runtime_error);
}

}  // namespace
}  // namespace mocap::graph
