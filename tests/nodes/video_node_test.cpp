// source.video in a graph: offline it sends every frame stamped with its time in the video;
// live it replays a file at the file's rate with wall-clock capture times and skips frames a
// slow consumer made late (counted); a truncated video, a stream that stops before the frames it
// announced and an absent camera stop the graph with an error naming the node and the input.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <mutex>
#include <vector>

#include "core/input_error.hpp"
#include "graph/harness.hpp"
#include "graph/registry.hpp"
#include "graph/transport.hpp"
#include "sink_test_util.hpp"
#include "support/files.hpp"
#include "support/http_file_server.hpp"

namespace mocap::nodes {
namespace {

using namespace mocap::graph;
namespace fs = std::filesystem;

const std::string kVtestPart = "../shared/data/eval/opencv_samples/vtest_part0.avi";
const std::string kStreetVideo = "../shared/data/eval/openpose_examples_media/video.avi";

struct Seen {
  Header header;
  int width = 0, height = 0;
  std::int64_t received_ns = 0;
};
std::mutex seen_mutex;
std::vector<Seen> seen;

// unit.capture_frames: keeps the headers and sizes of the frames it receives; `delay_ms` makes
// it a slow consumer.
class CaptureFrames : public Node {
 public:
  static void contract(Contract& c) {
    c.input<VideoFrame>("in");
    c.param<int>("delay_ms", 0, "time spent per frame", {0, 10000});
  }
  void open(Context& ctx) override { delay_ms_ = ctx.param<int>("delay_ms"); }
  void process(Context& ctx) override {
    const VideoFrame& frame = ctx.input<VideoFrame>("in");
    {
      const std::lock_guard lock(seen_mutex);
      seen.push_back({frame.header, frame.image.width(), frame.image.height(), realtime_ns()});
    }
    if (delay_ms_ > 0) ctx.sleep_for(std::chrono::milliseconds(delay_ms_));
  }

 private:
  int delay_ms_ = 0;
};
MOCAP_REGISTER_NODE("unit.capture_frames", CaptureFrames)

std::string graph_yaml(const std::string& source_params, const std::string& edge = "",
                       int delay_ms = 0) {
  return "nodes:\n  src: { type: source.video, params: { " + source_params +
         " } }\n  out: { type: unit.capture_frames, params: { delay_ms: " +
         std::to_string(delay_ms) + " } }\nedges:\n  - [src.frames, out.in" + edge + "]\n";
}

// Alone in the test harness (graph/harness.hpp): run the source a few calls at a time and pull
// what it sent, so only a few decoded frames are held at once.
TEST(VideoSourceNode, OfflineSendsEveryFrameStampedWithItsTimeInTheVideo) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  Harness src("source.video", {{"path", kVtestPart}, {"mode", "offline"}});
  std::size_t count = 0;
  while (!src.ended("frames") && count < 1000) {
    src.run_source(20);
    for (const auto& frame : src.pull<VideoFrame>("frames")) {
      EXPECT_EQ(frame->header.seq, count);
      EXPECT_EQ(frame->header.frame, static_cast<std::int64_t>(count));
      EXPECT_NEAR(static_cast<double>(frame->header.capture_ns) * 1e-9, 0.1 * count, 0.011);
      EXPECT_EQ(frame->image.width(), 768);
      EXPECT_EQ(frame->image.height(), 576);
      ++count;
    }
  }
  EXPECT_EQ(count, 200u);
  EXPECT_EQ(src.stats().drops, 0u);
}

TEST(VideoSourceNode, AFrameOffsetShiftsFrameNumbersAndTimes) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  Harness src("source.video",
              {{"path", kVtestPart}, {"mode", "offline"}, {"frame_offset", "5"}, {"count", "3"}});
  src.run_source(10);
  const auto frames = src.pull<VideoFrame>("frames");
  ASSERT_EQ(frames.size(), 3u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i]->header.seq, i);  // the sequence counts what was sent
    EXPECT_EQ(frames[i]->header.frame, static_cast<std::int64_t>(i) + 5);
    EXPECT_NEAR(static_cast<double>(frames[i]->header.capture_ns) * 1e-9, 0.1 * (i + 5), 0.011);
  }
}

TEST(VideoSourceNode, AModeThatIsNoChoiceIsRefusedBeforeOpening) {
  try {
    Harness src("source.video", {{"path", kVtestPart}, {"mode", "Live"}});
    FAIL() << "mode Live was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'Live' is not one of offline, live, auto; did you "
                                         "mean 'live'?"),
              std::string::npos)
        << e.what();
  }
}

TEST(VideoSourceNode, LiveReplaysAFileAtItsRateWithWallClockCaptureTimes) {
  if (!fs::exists(kStreetVideo)) GTEST_SKIP() << "shared video absent: " << kStreetVideo;
  seen.clear();
  const auto started = std::chrono::steady_clock::now();
  const RunResult result =
      testing::run_graph(graph_yaml("path: " + kStreetVideo + ", mode: live, count: 25"));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ASSERT_TRUE(result.ok) << result.error;
  ASSERT_GE(seen.size(), 20u);  // a loaded machine may skip a few
  EXPECT_GT(seconds, 0.45);     // 25 frames at 50 fps: paced, not as fast as possible
  const std::int64_t now = realtime_ns();
  for (std::size_t i = 1; i < seen.size(); ++i) {
    const Seen& a = seen[i - 1];
    const Seen& b = seen[i];
    EXPECT_GT(b.header.capture_ns, a.header.capture_ns);
    // Capture time is the frame's due time: its index at 50 fps after the first.
    const double gap_s = static_cast<double>(b.header.capture_ns - a.header.capture_ns) * 1e-9;
    EXPECT_NEAR(gap_s, 0.02 * static_cast<double>(b.header.frame - a.header.frame), 0.002);
    EXPECT_LE(b.header.capture_ns, b.received_ns);
    EXPECT_LT(now - b.header.capture_ns, 5'000'000'000);  // wall clock, not time in the video
  }
}

TEST(VideoSourceNode, LiveSkipsFramesASlowConsumerMadeLateAndCountsThem) {
  if (!fs::exists(kStreetVideo)) GTEST_SKIP() << "shared video absent: " << kStreetVideo;
  seen.clear();
  // The consumer takes 100 ms per frame behind a blocking edge of one slot: the source, held
  // back, finds its frames overdue and skips them; the consumer stays near the present.
  const RunResult result = testing::run_graph(graph_yaml(
      "path: " + kStreetVideo + ", mode: live, count: 10", ", { policy: \"blocking(1)\" }", 100));
  ASSERT_TRUE(result.ok) << result.error;
  ASSERT_EQ(seen.size(), 10u);
  EXPECT_GT(testing::stats_of(result, "src").drops, 20u);
  EXPECT_GT(seen.back().header.frame, 30);  // about 5 frames skipped per frame taken
  // Latency does not build up: at most about two consumer periods plus a decode (an
  // AddressSanitizer build runs our side of the decode several times slower).
#if defined(__SANITIZE_ADDRESS__)
  constexpr std::int64_t kMaxLatencyNs = 500'000'000;
#else
  constexpr std::int64_t kMaxLatencyNs = 250'000'000;
#endif
  for (const Seen& s : seen) {
    EXPECT_LT(s.received_ns - s.header.capture_ns, kMaxLatencyNs) << "frame " << s.header.frame;
  }
}

TEST(VideoSourceNode, ATruncatedVideoStopsTheGraphNamingTheNodeAndTheFile) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  const test::TempDir dir;
  const std::string copy = dir.file("cut.avi");
  const std::string bytes = test::read_file(kVtestPart);
  test::write_file(copy, bytes.substr(0, bytes.size() / 3));
  seen.clear();
  const RunResult result = testing::run_graph(graph_yaml("path: " + copy));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("'src'"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find(copy), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("truncated"), std::string::npos) << result.error;
  EXPECT_GT(seen.size(), 10u);  // the frames before the cut went through
}

// The clip served over HTTP: whole, every frame arrives and the stream ends; cut after half its
// bytes (the connection lost), the graph stops with an error naming the stream, after the frames
// that arrived, as it does for a truncated file.
TEST(VideoSourceNode, AStreamThatStopsMidFileStopsTheGraphLikeATruncatedFile) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  const std::string bytes = test::read_file(kVtestPart);
  {
    const test::HttpFileServer whole(bytes);
    seen.clear();
    const RunResult result = testing::run_graph(
        graph_yaml("path: '" + whole.url("vtest.avi") + "', mode: offline, timeout_ms: 5000"));
    ASSERT_TRUE(result.ok) << result.error;
    EXPECT_EQ(seen.size(), 200u);
  }
  const test::HttpFileServer cut(bytes, bytes.size() / 2);
  const std::string url = cut.url("vtest.avi");
  seen.clear();
  const RunResult result =
      testing::run_graph(graph_yaml("path: '" + url + "', mode: offline, timeout_ms: 5000"));
  ASSERT_FALSE(result.ok) << seen.size() << " frames and no error";
  EXPECT_NE(result.error.find("'src'"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find(url), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("stopped early"), std::string::npos) << result.error;
  EXPECT_GT(seen.size(), 10u);  // the frames before the cut went through
  EXPECT_LT(seen.size(), 200u);
}

// A copy of the clip with 20000 random bytes at a quarter, half and three quarters of it: FFmpeg
// passes over the frames it
// cannot decode; the run goes on to the end and counts them (drops, status line).
TEST(VideoSourceNode, CorruptFramesInTheMiddleAreSkippedAndCounted) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  const test::TempDir dir;
  const std::string copy = dir.file("corrupt.avi");
  std::string bytes = test::read_file(kVtestPart);
  std::uint32_t state = 12345;
  for (const std::size_t start : {bytes.size() / 4, bytes.size() / 2, 3 * bytes.size() / 4}) {
    for (std::size_t i = start; i < start + 20000; ++i) {
      state = state * 1664525u + 1013904223u;
      bytes[i] = static_cast<char>(state >> 24);
    }
  }
  test::write_file(copy, bytes);
  seen.clear();
  const RunResult result = testing::run_graph(graph_yaml("path: " + copy + ", mode: offline"));
  ASSERT_TRUE(result.ok) << result.error;
  const NodeStats& src = testing::stats_of(result, "src");
  EXPECT_GT(src.drops, 0u);
  EXPECT_EQ(seen.size() + src.drops, 200u);  // every announced frame: delivered or counted
  EXPECT_NE(src.status.find(std::to_string(src.drops) + " corrupt frames skipped"),
            std::string::npos)
      << src.status;
  EXPECT_GT(seen.back().header.frame, 180);  // not an early end
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i].header.seq, i);
}

// loop: the clip starts again at its end; sequence numbers and offline stamps go on counting.
TEST(VideoSourceNode, LoopStartsAgainAtTheEndWithSequenceAndTimeGoingOn) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  seen.clear();
  const RunResult result = testing::run_graph(
      graph_yaml("path: " + kVtestPart + ", mode: offline, loop: true, count: 450"));
  ASSERT_TRUE(result.ok) << result.error;
  ASSERT_EQ(seen.size(), 450u);
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].header.seq, i);
    EXPECT_EQ(seen[i].header.frame, static_cast<std::int64_t>(i % 200));
    EXPECT_NEAR(static_cast<double>(seen[i].header.capture_ns) * 1e-9, 0.1 * i, 0.011);
  }
  EXPECT_NE(testing::stats_of(result, "src").status.find("started again 2 times"),
            std::string::npos);
}

TEST(VideoSourceNode, AnAbsentCameraStopsTheGraphWithAClearError) {
  if (fs::exists("/dev/video9")) GTEST_SKIP() << "/dev/video9 exists on this machine";
  const RunResult result = testing::run_graph(graph_yaml("path: /dev/video9"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("/dev/video9"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("no such camera device"), std::string::npos) << result.error;
}

// A mode is a choice: graph validation refuses an unknown one, before any node runs.
TEST(VideoSourceNode, RefusesAnUnknownModeWhenTheGraphIsValidated) {
  try {
    testing::run_graph(graph_yaml("path: " + kVtestPart + ", mode: fast"));
    FAIL() << "mode fast was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test.yaml:2: node 'src': parameter 'mode': 'fast' is "
                                         "not one of offline, live, auto"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mocap::nodes
