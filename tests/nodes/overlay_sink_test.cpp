// sink.overlay: in a graph, a playable MP4 with one picture per frame that had both inputs and PNG
// snapshots, the frames read again from the file (video_path), a killed run's video that plays;
// alone in the test harness, every frame drawn however far (within the bound) the 3D lags its 2D,
// nothing hung beyond it, the optional video input under the 2D people, and errors naming the file.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "graph/harness.hpp"
#include "sink_test_util.hpp"
#include "support/small_pose_database.hpp"
#include "video/mp4_writer.hpp"

namespace mocap::nodes {
namespace {

using testing::run_graph;
using testing::stats_of;

std::string two_people_script(int frames) {
  std::string script;
  for (int f = 0; f < frames; ++f) {
    char frame[64];
    std::snprintf(frame, sizeof frame, "%s0:0:%d:0,1:1:%d:3", f ? ";" : "", f, f);
    script += frame;
  }
  return script;
}

int count_video_frames(const std::string& path, cv::Size& size) {
  cv::VideoCapture video(path, cv::CAP_FFMPEG);
  if (!video.isOpened()) return -1;
  int frames = 0;
  for (cv::Mat picture; video.read(picture); ++frames) size = picture.size();
  return frames;
}

TEST(OverlaySink, WritesAPlayableMp4AndPngsOfEveryJoinedFrame) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string mp4 = dir.file("out/overlay.mp4");
  const graph::RunResult result =
      run_graph(R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
                db + ", script: \"" + two_people_script(30) + R"(", skip_2d: [7] } }
  overlay: { type: sink.overlay, params: { video: )" +
                mp4 + ", png_every: 10, png_dir: " + dir.file("png") +
                R"(, panel_height: 240 } }
edges:
  - [src.people2d, overlay.people2d]
  - [src.people3d, overlay.people3d]
)");
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(stats_of(result, "overlay").drops, 1u);  // frame 7 had no 2D people
  cv::Size size;
  EXPECT_EQ(count_video_frames(mp4, size), 29);
  EXPECT_EQ(size, cv::Size(2 * 426, 240));  // two panels of the 1920 x 1080 canvas scaled to 240
  int pngs = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.file("png"))) {
    ++pngs;
    EXPECT_EQ(cv::imread(e.path().string()).size(), size) << e.path();
  }
  EXPECT_EQ(pngs, 3);  // pictures 0, 10 and 20
  EXPECT_TRUE(std::filesystem::exists(dir.file("png/overlay_000000.png")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("png/overlay_000011.png")));  // after the drop
}

// --- alone in the test harness (graph/harness.hpp): no pose database needed

// A person standing at the canvas centre (COCO-17, pixels) and the same body in 3D (metres).
People2D people2d(std::int64_t frame) {
  People2D m;
  m.header = {"cam", static_cast<std::uint64_t>(frame), frame * 33'000'000, frame};
  Person2D p;
  p.id = 1;
  for (int j = 0; j < 17; ++j) {
    p.joints.push_back({960.0f + 10.0f * static_cast<float>(j % 3), 300.0f + 25.0f * j, 0.9f});
  }
  p.box = {900, 280, 120, 440};
  m.people.push_back(p);
  return m;
}

People3D people3d(std::int64_t frame) {
  People3D m;
  m.header = {"cam", static_cast<std::uint64_t>(frame), frame * 33'000'000, frame};
  Person3D p;
  p.id = 1;
  for (int j = 0; j < kBodyJoints; ++j) {
    p.positions[static_cast<std::size_t>(j)] = {0.05f * static_cast<float>(j % 3), -0.8f + 0.1f * j,
                                                0.0f};
  }
  m.people.push_back(p);
  return m;
}

// The order a graph delivers them in when the 3D lags `lag` frames behind the 2D (the offline
// fit's windows): the 2D of frame f, then the 3D of frame f - lag.
void push_lagging(graph::Harness& overlay, int frames, int lag) {
  for (int f = 0; f < frames + lag; ++f) {
    if (f < frames) overlay.push("people2d", people2d(f));
    if (f >= lag) overlay.push("people3d", people3d(f - lag));
    overlay.process_ready();
  }
}

graph::HarnessOptions one_source() {
  graph::HarnessOptions options;
  options.unconnected = {"video"};
  options.at_bound =
      graph::AtBound::pass_partial;  // the runtime's choice: 2D and 3D share a source
  return options;
}

// 150 frames whose 3D comes 120 frames after their 2D: all drawn (the old joining kept 64).
TEST(OverlaySink, EveryFrameIsDrawnWhenThe3DLagsWithinTheBound) {
  test::TempDir dir;
  const std::string mp4 = dir.file("overlay.mp4");
  graph::Harness overlay("sink.overlay", {{"video", mp4}, {"panel_height", "96"}}, one_source());
  push_lagging(overlay, 150, 120);
  overlay.finish();
  const graph::NodeStats stats = overlay.stats();
  EXPECT_EQ(stats.sync.complete, 150u);
  EXPECT_EQ(stats.drops, 0u);
  EXPECT_GE(stats.sync.inputs[0].max_held, 120u);
  cv::Size size;
  EXPECT_EQ(count_video_frames(mp4, size), 150);
}

// Beyond the bound nothing hangs: the frames past it go on partial, their 3D comes late, and the
// overlay counts each as a drop; the others are drawn.
TEST(OverlaySink, ALagBeyondTheBoundIsCountedNotHung) {
  test::TempDir dir;
  const std::string mp4 = dir.file("overlay.mp4");
  graph::Harness overlay(
      "sink.overlay", {{"video", mp4}, {"panel_height", "96"}, {"sync_bound", "50"}}, one_source());
  push_lagging(overlay, 150, 120);
  overlay.finish();
  const graph::NodeStats stats = overlay.stats();
  const std::uint64_t late = stats.sync.inputs[1].late;
  EXPECT_GT(late, 0u);
  EXPECT_EQ(stats.sync.inputs[1].missing, late);
  EXPECT_EQ(stats.sync.complete + late, 150u);
  EXPECT_EQ(stats.sync.inputs[1].late_dropped, late);  // sync_late: drop
  EXPECT_EQ(stats.drops, 2 * late);  // the 2D undrawn, its 3D dropped by the synchroniser
  cv::Size size;
  EXPECT_EQ(count_video_frames(mp4, size), static_cast<int>(stats.sync.complete));
}

// A 3D that comes after its frame went on partial (here at the bound: 2D frames 0 and 1 against
// a bound of 2) is counted late and dropped (the overlay's sync_late: drop), not passed on as a
// frame of its own: one picture per frame, the sets counted are the frames.
TEST(OverlaySink, A3DLaterThanItsFrameIsCountedAndDropped) {
  test::TempDir dir;
  graph::Harness overlay("sink.overlay",
                         {{"png_every", "1"},
                          {"png_dir", dir.file("png")},
                          {"panel_height", "96"},
                          {"sync_bound", "2"}},
                         one_source());
  overlay.push("people2d", people2d(0));
  overlay.push("people2d", people2d(1));
  EXPECT_EQ(overlay.process_ready(), 1u);  // frame 0 went on with its 2D alone
  overlay.push("people3d", people3d(0));   // late
  overlay.push("people3d", people3d(1));
  EXPECT_EQ(overlay.process_ready(), 1u);  // frame 1, complete
  overlay.push("people2d", people2d(2));
  overlay.push("people3d", people3d(2));
  overlay.finish();
  std::vector<std::string> pngs;
  for (const auto& entry : std::filesystem::directory_iterator(dir.file("png")))
    pngs.push_back(entry.path().filename().string());
  std::sort(pngs.begin(), pngs.end());
  EXPECT_EQ(pngs, (std::vector<std::string>{"overlay_000001.png", "overlay_000002.png"}));
  const graph::NodeStats stats = overlay.stats();
  EXPECT_EQ(stats.sync.sets, 3u);
  EXPECT_EQ(stats.sync.complete, 2u);
  EXPECT_EQ(stats.sync.inputs[1].late, 1u);
  EXPECT_EQ(stats.sync.inputs[1].late_dropped, 1u);
  EXPECT_EQ(stats.drops, 2u);  // frame 0's 2D (undrawn) and its late 3D
}

// The video input, when connected, is drawn under the 2D people.
TEST(OverlaySink, VideoFramesAreDrawnUnderThe2DPeople) {
  test::TempDir dir;
  graph::Harness overlay("sink.overlay", {{"png_every", "1"}, {"png_dir", dir.file("png")}});
  for (int f = 0; f < 3; ++f) {
    VideoFrame video;
    video.header = people2d(f).header;
    video.image = ImageBuffer(320, 180, PixelFormat::bgr8);
    const auto pixels = video.image.pixels_for_writing();
    for (std::size_t i = 2; i < pixels.size(); i += 3) pixels[i] = std::byte{200};  // red (BGR)
    overlay.push("video", std::move(video));
    overlay.push("people2d", people2d(f));
    overlay.push("people3d", people3d(f));
  }
  overlay.finish();
  EXPECT_EQ(overlay.stats().sync.complete, 3u);
  const cv::Mat picture = cv::imread(dir.file("png/overlay_000002.png"));
  ASSERT_FALSE(picture.empty());
  // The 320 x 180 video fills the left panel (854 x 480 for 16:9); a corner pixel away from the
  // text and the people is its red.
  const cv::Vec3b corner = picture.at<cv::Vec3b>(470, 840);
  EXPECT_NEAR(corner[2], 200, 8);
  EXPECT_LT(corner[0] + corner[1], 16);
}

// With video_path the overlay reads the frame under the 2D people from the file by frame number
// (the script's frames 0..11 are the file's frames 0..11, each its own grey), and the video port
// is not needed.
TEST(OverlaySink, VideoPathFramesAreReadAgainByFrameNumber) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string clip = dir.file("clip.mp4");
  {
    video::Mp4Writer writer(clip, 320, 180, {10.0});
    for (int k = 0; k < 12; ++k) {
      ImageBuffer grey(320, 180, PixelFormat::bgr8);
      for (std::byte& b : grey.pixels_for_writing()) b = std::byte(20 * k);
      writer.write(grey);
    }
  }
  const graph::RunResult result = run_graph(R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
                                            db + ", script: \"" + two_people_script(12) + R"(" } }
  overlay: { type: sink.overlay, params: { video_path: )" +
                                            clip + ", video: " + dir.file("overlay.mp4") +
                                            ", png_every: 1, png_dir: " + dir.file("png") + R"( } }
edges:
  - [src.people2d, overlay.people2d]
  - [src.people3d, overlay.people3d]
)");
  ASSERT_TRUE(result.ok) << result.error;
  cv::Size size;
  EXPECT_EQ(count_video_frames(dir.file("overlay.mp4"), size), 12);
  for (int k = 0; k < 12; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "png/overlay_%06d.png", k);
    const cv::Mat picture = cv::imread(dir.file(name));
    ASSERT_FALSE(picture.empty()) << name;
    const cv::Vec3b corner = picture.at<cv::Vec3b>(470, 840);  // the video, away from people
    EXPECT_NEAR(corner[1], 20 * k, 4) << name;
  }
}

// A child process runs the graph with a source that never ends; SIGKILL lands while the overlay
// writes. The video plays: OpenCV decodes every picture the file had when the parent last looked.
TEST(OverlaySink, VideoOfAKilledRunPlays) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  for (int round = 0; round < 2; ++round) {
    const std::string mp4 = dir.file("killed" + std::to_string(round) + ".mp4");
    const std::string graph = R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
                              db + ", script: \"" + two_people_script(5) +
                              R"(", repeat: true, interval_ms: 5 } }
  overlay: { type: sink.overlay, params: { video: )" +
                              mp4 + R"(, panel_height: 240 } }
edges:
  - [src.people2d, overlay.people2d]
  - [src.people3d, overlay.people3d]
)";
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      run_graph(graph);  // runs until killed
      _exit(2);
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    auto size_now = [&] {
      std::error_code ec;
      const auto bytes = std::filesystem::file_size(mp4, ec);
      return ec ? 0u : bytes;
    };
    while (size_now() < 20000u && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::this_thread::sleep_for(std::chrono::milliseconds(50 + 61 * round));
    // The pictures in the file by now: written whole before the kill, so they must all decode.
    cv::Size size;
    const int before_kill = count_video_frames(mp4, size);
    ASSERT_EQ(kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the graph ended by itself";
    const int after_kill = count_video_frames(mp4, size);
    std::cout << "[ note ] round " << round << ": " << before_kill
              << " pictures decoded before the kill, " << after_kill << " after\n";
    EXPECT_GT(before_kill, 0);
    EXPECT_GE(after_kill, before_kill);
    EXPECT_EQ(size, cv::Size(2 * 426, 240));
  }
}

TEST(OverlaySink, UnwritableVideoFailsNamingTheFile) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.file("taken.mp4"));  // a folder where the file goes
  const std::string mp4 = dir.file("taken.mp4");
  graph::HarnessOptions options;
  options.unconnected = {"video"};
  graph::Harness overlay("sink.overlay", {{"video", mp4}}, options);
  try {
    overlay.push("people2d", people2d(0));
    overlay.push("people3d", people3d(0));
    overlay.finish();
    FAIL() << "writing into a folder worked";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(mp4), std::string::npos) << e.what();
  }
}

TEST(OverlaySink, NothingToWriteIsRefusedAtOpen) {
  graph::Harness overlay("sink.overlay");
  try {
    overlay.open();
    FAIL() << "an overlay writing nothing opened";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("nothing to write"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mocap::nodes
