// sink.overlay in a graph: a playable MP4 with one picture per frame that had both inputs, PNG
// snapshots, the optional video input under the 2D people or the frames read again from the file
// (video_path), and errors naming the file.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

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
                db + ", script: \"" + two_people_script(30) + R"(", skip_2d: "7" } }
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

// The video input, when connected and waited for, is drawn under the 2D people (it is red).
TEST(OverlaySink, VideoFramesAreDrawnUnderThe2DPeople) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const graph::RunResult result = run_graph(R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
                                            db + ", script: \"" + two_people_script(3) + R"(" } }
  overlay: { type: sink.overlay, params: { png_every: 1, png_dir: )" +
                                            dir.file("png") + R"(, wait_for_video: true } }
edges:
  - [src.people2d, overlay.people2d]
  - [src.people3d, overlay.people3d]
  - [src.video, overlay.video]
)");
  ASSERT_TRUE(result.ok) << result.error;
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

TEST(OverlaySink, UnwritableVideoFailsTheGraphNamingTheFile) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  std::filesystem::create_directories(dir.file("taken.mp4"));  // a folder where the file goes
  const std::string mp4 = dir.file("taken.mp4");
  const graph::RunResult result = run_graph(R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
                                            db + ", script: \"" + two_people_script(2) + R"(" } }
  overlay: { type: sink.overlay, params: { video: )" +
                                            mp4 + R"( } }
edges:
  - [src.people2d, overlay.people2d]
  - [src.people3d, overlay.people3d]
)");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find(mp4), std::string::npos) << result.error;
}

TEST(OverlaySink, NothingToWriteIsRefusedAtOpen) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  const graph::RunResult result = run_graph(R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
                                            db + R"(, script: "0:0:0:0" } }
  overlay: { type: sink.overlay }
edges:
  - [src.people2d, overlay.people2d]
  - [src.people3d, overlay.people3d]
)");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("nothing to write"), std::string::npos) << result.error;
}

}  // namespace
}  // namespace mocap::nodes
