// source.aravis in a running graph against the fake GigE camera: frames with headers, a camera
// that cannot be opened, and a camera that dies mid-stream and comes back.

#include <gtest/gtest.h>

#include <functional>
#include <iostream>
#include <mutex>
#include <thread>

#include "fake_gv_camera.hpp"
#include "graph/graph_spec.hpp"
#include "graph/registry.hpp"
#include "graph/runtime.hpp"
#include "graph/validation.hpp"

namespace mocap::nodes {
namespace {

using namespace std::chrono_literals;
using namespace mocap::graph;

// What the collector saw, shared with the test thread (the node runs on its own thread).
struct Seen {
  Header header;
  int width = 0, height = 0;
  PixelFormat format = PixelFormat::rgb8;
};
std::mutex seen_mutex;
std::vector<Seen> seen;

std::size_t seen_count() {
  const std::lock_guard lock(seen_mutex);
  return seen.size();
}

class FrameRecorder : public Node {
 public:
  static void contract(Contract& c) { c.input<VideoFrame>("in"); }
  void process(Context& ctx) override {
    const auto& f = ctx.input<VideoFrame>("in");
    const std::lock_guard lock(seen_mutex);
    seen.push_back({f.header, f.image.width(), f.image.height(), f.image.format()});
  }
};
MOCAP_REGISTER_NODE("unit.frame_recorder", FrameRecorder)

std::string graph_text(const std::string& id, int count, int width = 512, int height = 512) {
  return "nodes:\n"
         "  cam: { type: source.aravis, params: { id: " +
         id + ", fps: 25, width: " + std::to_string(width) + ", height: " + std::to_string(height) +
         ", pixel_format: Mono8, count: " + std::to_string(count) +
         " } }\n"
         "  rec: { type: unit.frame_recorder }\n"
         "edges:\n"
         "  - [cam.frames, rec.in]\n";
}

bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(20ms);
  }
  return true;
}

class AravisSourceTest : public test::FakeCameraFixture {
 protected:
  void SetUp() override {
    FakeCameraFixture::SetUp();
    if (IsSkipped()) return;
    const std::lock_guard lock(seen_mutex);
    seen.clear();
  }
};

TEST_F(AravisSourceTest, EmitsFramesWithHeaders) {
  test::FakeGvCamera fake(*program_, test::unique_serial("NODE"));
  Runtime runtime(resolve(parse_graph_text(graph_text(fake.serial(), 10), "test.yaml")));
  const RunResult result = runtime.run();
  ASSERT_TRUE(result.ok) << result.error;
  const std::lock_guard lock(seen_mutex);
  ASSERT_EQ(seen.size(), 10u);
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].width, 512);
    EXPECT_EQ(seen[i].height, 512);
    EXPECT_EQ(seen[i].format, PixelFormat::gray8);
    EXPECT_EQ(seen[i].header.seq, i);
    EXPECT_EQ(seen[i].header.frame, static_cast<std::int64_t>(i));
    EXPECT_EQ(seen[i].header.stream, "cam_01");  // the camera's name (kDefaultCamera)
    if (i > 0) {
      EXPECT_GT(seen[i].header.capture_ns, seen[i - 1].header.capture_ns);
    }
  }
}

// Packets lost on the way (the fake camera drops 3 % of them): incomplete frames are the node's
// drops in the graph's statistics, and only whole frames reach the next node. Small frames (a
// few packets each), so that most of them still arrive whole.
TEST_F(AravisSourceTest, IncompleteFramesAreCountedAsDrops) {
  test::FakeGvCamera fake(*program_, test::unique_serial("NODE"), /*loss_per_thousand=*/30);
  Runtime runtime(resolve(parse_graph_text(graph_text(fake.serial(), 40, 128, 96), "test.yaml")));
  const RunResult result = runtime.run();
  ASSERT_TRUE(result.ok) << result.error;
  std::uint64_t drops = 0;
  for (const NodeStats& s : result.stats.nodes) {
    if (s.node == "cam") drops = s.drops;
  }
  EXPECT_GT(drops, 0u);
  const std::lock_guard lock(seen_mutex);
  ASSERT_EQ(seen.size(), 40u);
  for (const Seen& s : seen) EXPECT_EQ(s.width * s.height, 128 * 96);
}

TEST_F(AravisSourceTest, ACameraThatCannotBeOpenedFailsTheGraphNamingIt) {
  Runtime runtime(resolve(parse_graph_text(graph_text("no-such-camera-4711", 5), "test.yaml")));
  const RunResult result = runtime.run();
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("no-such-camera-4711"), std::string::npos) << result.error;
}

std::string status_of(const Runtime& runtime, const std::string& node) {
  for (const NodeStats& s : runtime.stats().nodes) {
    if (s.node == node) return s.status;
  }
  return "";
}

// The camera dies mid-stream and comes back: the node notices within its loss timeout (1 s of
// no data here, not Aravis' heartbeat), says so in its status line in the graph's statistics,
// reconnects, and the stream goes on, with seq and frame still counting up from where they were.
TEST_F(AravisSourceTest, ReconnectsWhenTheCameraComesBack) {
  const std::string serial = test::unique_serial("NODE");
  auto fake = std::make_unique<test::FakeGvCamera>(*program_, serial);
  Runtime runtime(resolve(parse_graph_text(graph_text(serial, 0), "test.yaml")));
  RunResult result;
  ::testing::internal::CaptureStderr();
  std::thread graph([&] { result = runtime.run(); });
  const bool first = wait_until([] { return seen_count() >= 5; }, 15s);
  const std::string before_status = status_of(runtime, "cam");
  fake.reset();  // killed: no more data; the watchdog reports the camera lost
  const auto killed = std::chrono::steady_clock::now();
  const std::size_t before = seen_count();
  const bool noticed =
      wait_until([&] { return status_of(runtime, "cam").find("lost") != std::string::npos; }, 30s);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
  const std::string lost_status = status_of(runtime, "cam");
  fake = std::make_unique<test::FakeGvCamera>(*program_, serial);
  const bool again = wait_until([&] { return seen_count() >= before + 5; }, 60s);
  const std::string after_status = status_of(runtime, "cam");
  runtime.request_stop();
  graph.join();
  const std::string log = ::testing::internal::GetCapturedStderr();
  std::cout << "[ measured ] source.aravis noticed the dead camera after " << seconds << " s\n";
  RecordProperty("node_loss_s", std::to_string(seconds));
  EXPECT_NE(log.find("lost (no data for"), std::string::npos) << log;
  EXPECT_NE(log.find("reconnected to camera"), std::string::npos) << log;
  ASSERT_TRUE(first) << "no frames before the camera was killed";
  EXPECT_NE(before_status.find("streaming from"), std::string::npos) << before_status;
  ASSERT_TRUE(noticed) << "the status never said the camera was lost";
  EXPECT_LT(seconds, 3.0) << lost_status;  // loss_timeout_ms 1000 (the default)
  EXPECT_NE(lost_status.find("[1 lost, 0 reconnects]"), std::string::npos) << lost_status;
  ASSERT_TRUE(again) << "no frames after the camera came back";
  EXPECT_NE(after_status.find("reconnected to camera"), std::string::npos) << after_status;
  EXPECT_NE(after_status.find("[1 lost, 1 reconnects]"), std::string::npos) << after_status;
  EXPECT_TRUE(result.ok) << result.error;
  const std::lock_guard lock(seen_mutex);
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i].header.seq, i);
}

}  // namespace
}  // namespace mocap::nodes
