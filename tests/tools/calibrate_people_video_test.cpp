// `mocap calibrate rig --from-people` with videos and image folders as views, driven as a user
// would (the built binary). There is no real multi-view video in ../shared, so the plumbing is
// tested on the first frames of vtest (a real video, cut short here) given as several views: the
// detector runs on each, the detections are kept as OpenPose JSON per camera and a second run
// takes them without detecting; the calibration is then refused for the reason it must be (the
// same video in two views: cameras without a baseline). Garbage and empty videos, a video of
// another size than its camera, of another frame rate and of another length are refused naming
// the view, before any detection.

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "detect/model_files.hpp"
#include "support/files.hpp"
#include "support/mocap_process.hpp"
#include "support/shared_data.hpp"

namespace mocap::test {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr int kFrames = 6;
const fs::path kVideo = shared_data() / "eval" / "opencv_samples" / "vtest_part0.avi";

// The models of the default detector (topdown: CenterNet boxes, MoveNet Lightning per person).
bool topdown_models_present() {
  try {
    detect::cached_model_json("centernet");
    detect::cached_model_json("movenet-lightning");
    return true;
  } catch (const detect::ModelMissing&) {
    return false;
  }
}

std::size_t keypoint_files(const fs::path& folder) {
  std::size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec))
    n += e.path().filename().string().ends_with("_keypoints.json");
  return n;
}

// The first kFrames frames of vtest as an MJPG video and as a folder of PNG images.
void cut_vtest(const TempDir& dir) {
  cv::VideoCapture in(kVideo.string());
  ASSERT_TRUE(in.isOpened()) << kVideo;
  fs::create_directories(dir.file("frames"));
  cv::VideoWriter out;
  for (int i = 0; i < kFrames; ++i) {
    cv::Mat frame;
    ASSERT_TRUE(in.read(frame)) << kVideo << " frame " << i;
    if (!out.isOpened()) {
      ASSERT_TRUE(out.open(dir.file("a.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                           frame.size()));
    }
    out.write(frame);
    char name[32];
    std::snprintf(name, sizeof name, "%03d.png", i);
    ASSERT_TRUE(cv::imwrite(dir.file("frames/" + std::string(name)), frame));
  }
}

void write_video(const std::string& path, double fps, int frames, int width = 64, int height = 48) {
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                         cv::Size(width, height));
  ASSERT_TRUE(writer.isOpened()) << path;
  for (int i = 0; i < frames; ++i)
    writer.write(cv::Mat(height, width, CV_8UC3, cv::Scalar(i * 20, 40, 90)));
}

std::vector<std::string> command(std::vector<std::string> views, std::vector<std::string> extra) {
  std::vector<std::string> a = {"calibrate", "rig", "--from-people", "--hfov", "60"};
  a.insert(a.end(), views.begin(), views.end());
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

TEST(CalibratePeopleVideo, DetectionsAreKeptAndTheSameVideoTwiceIsRefused) {
  MOCAP_REQUIRE_SHARED("eval/opencv_samples/vtest_part0.avi");
  if (!topdown_models_present())
    GTEST_SKIP() << "detector models absent: tools/setup.sh --models-only";
  TempDir dir;
  cut_vtest(dir);
  fs::copy_file(dir.file("a.avi"), dir.file("b.avi"));
  // Two views of one video, and its frames as an image folder.
  Mocap first(dir, "first",
              command({dir.file("a.avi"), dir.file("b.avi"), dir.file("frames")},
                      {"--min-shared", "3", "--out", dir.file("rig.toml")}));
  const auto first_code = first.wait(300s);
  ASSERT_TRUE(first_code.has_value());
  EXPECT_NE(*first_code, 0);
  const std::string err = first.err();
  EXPECT_NE(err.find("detected cam_01 6/6, cam_02 6/6, cam_03 6/6 frames"), std::string::npos)
      << err;
  EXPECT_NE(err.find("camera cam_02 (" + dir.file("b.avi") +
                     "): sees the people at the same "
                     "pixels as camera cam_01 (" +
                     dir.file("a.avi") + ")"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("no baseline"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir.file("rig.toml")));
  // Kept beside --out, a folder per camera, a file per frame (people or not).
  for (const char* camera : {"cam_01", "cam_02", "cam_03"})
    EXPECT_EQ(keypoint_files(dir.file("rig_keypoints/") + camera), std::size_t(kFrames)) << camera;

  // A second run takes the kept detections as its views: no detection, the same refusal.
  Mocap again(dir, "again",
              command({dir.file("rig_keypoints/cam_01"), dir.file("rig_keypoints/cam_02")},
                      {"--size", "768x576", "--min-shared", "3"}));
  const auto again_code = again.wait(60s);
  ASSERT_TRUE(again_code.has_value());
  EXPECT_NE(*again_code, 0);
  EXPECT_EQ(again.err().find("detected"), std::string::npos) << again.err();
  EXPECT_NE(again.err().find("sees the people at the same pixels"), std::string::npos)
      << again.err();

  // Detecting again over them needs --force; without it the folder is named with what to do.
  Mocap over(dir, "over",
             command({dir.file("a.avi"), dir.file("b.avi")}, {"--out", dir.file("rig.toml")}));
  const auto over_code = over.wait(60s);
  ASSERT_TRUE(over_code.has_value());
  EXPECT_NE(*over_code, 0);
  EXPECT_NE(over.err().find(dir.file("rig_keypoints/cam_01") + ": holds detections already"),
            std::string::npos)
      << over.err();
}

TEST(CalibratePeopleVideo, BadVideosAreRefusedNamingTheView) {
  TempDir dir;
  write_video(dir.file("a.avi"), 30.0, 5);
  write_video(dir.file("rate.avi"), 25.0, 5);
  write_video(dir.file("short.avi"), 30.0, 4);
  write_video(dir.file("wide.avi"), 30.0, 5, 80, 48);
  std::ofstream(dir.file("empty.avi"));
  {
    std::ofstream garbage(dir.file("garbage.avi"), std::ios::binary);
    std::mt19937 random(3);
    for (int i = 0; i < 4096; ++i) garbage.put(static_cast<char>(random()));
  }
  const auto refusal = [&](const std::string& name, std::vector<std::string> views,
                           std::vector<std::string> extra = {}) {
    extra.insert(extra.end(), {"--keypoints", dir.file("kept")});
    Mocap run(dir, name, command(std::move(views), std::move(extra)));
    const auto code = run.wait(60s);
    EXPECT_TRUE(code.has_value() && *code != 0) << name;
    return run.err();
  };
  for (const char* bad : {"garbage.avi", "empty.avi"}) {
    const std::string err = refusal(bad, {dir.file("a.avi"), dir.file(bad)});
    EXPECT_NE(err.find(dir.file(bad)), std::string::npos) << err;
  }
  const std::string rate = refusal("rate", {dir.file("a.avi"), dir.file("rate.avi")});
  EXPECT_NE(rate.find("cam_02: " + dir.file("rate.avi") + " is 25 fps but " + dir.file("a.avi") +
                      " (camera 'cam_01') is 30 fps"),
            std::string::npos)
      << rate;
  const std::string length = refusal("short", {dir.file("a.avi"), dir.file("short.avi")});
  EXPECT_NE(length.find(dir.file("short.avi") + " has 4 frames"), std::string::npos) << length;
  const std::string size =
      refusal("size", {dir.file("a.avi"), dir.file("wide.avi")}, {"--size", "64x48"});
  EXPECT_NE(size.find("cam_02: " + dir.file("wide.avi") + " is 80x48 but camera 'cam_02' is 64x48"),
            std::string::npos)
      << size;
  EXPECT_FALSE(fs::exists(dir.file("kept")));  // nothing detected
}

}  // namespace
}  // namespace mocap::test
