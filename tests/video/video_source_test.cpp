// components/video: the shared sample videos decode completely with monotonic timestamps; a
// truncated copy, random bytes, an empty file, a missing camera device and a damaged image each
// give an InputError naming the input; image folders come in natural number order.

#include "video/video_source.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <opencv2/imgcodecs.hpp>

#include "core/input_error.hpp"
#include "support/errors.hpp"
#include "support/files.hpp"

namespace mocap::video {
namespace {

using test::error_of;

namespace fs = std::filesystem;

const std::string kVtestPart = "../shared/data/eval/opencv_samples/vtest_part0.avi";
const std::string kStreetVideo = "../shared/data/eval/openpose_examples_media/video.avi";

void expect_names(const std::string& error, const std::string& path, const std::string& what) {
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find(what), std::string::npos) << error;
}

TEST(Classify, TellsDevicesStreamsFoldersAndFilesApart) {
  EXPECT_EQ(classify("/dev/video0"), SourceKind::device);
  EXPECT_EQ(classify("2"), SourceKind::device);
  EXPECT_EQ(classify("rtsp://10.0.0.2:554/stream"), SourceKind::network);
  EXPECT_EQ(classify("HTTP://host/a.mjpg"), SourceKind::network);
  EXPECT_EQ(classify("."), SourceKind::image_folder);
  EXPECT_EQ(classify("clip.mp4"), SourceKind::file);
  EXPECT_EQ(classify("2.avi"), SourceKind::file);
  EXPECT_TRUE(is_image_file_name("a/B.PNG"));
  EXPECT_TRUE(is_image_file_name("x.jpeg"));
  EXPECT_FALSE(is_image_file_name("notes.txt"));
}

TEST(VideoSource, ReadsEveryFrameOfVtestWithMonotonicTimestamps) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  VideoSource source(kVtestPart);
  EXPECT_EQ(source.kind(), SourceKind::file);
  EXPECT_FALSE(source.live());
  EXPECT_EQ(source.width(), 768);
  EXPECT_EQ(source.height(), 576);
  EXPECT_NEAR(source.fps(), 10.0, 1e-6);
  EXPECT_EQ(source.frame_count(), 200);
  std::int64_t frames = 0, last_capture = 0;
  double last_time = -1.0;
  while (auto frame = source.read()) {
    EXPECT_EQ(frame->index, frames);
    EXPECT_EQ(frame->image.format(), PixelFormat::bgr8);
    EXPECT_EQ(frame->image.width(), 768);
    EXPECT_EQ(frame->image.height(), 576);
    EXPECT_GT(frame->media_time_s, last_time);
    EXPECT_NEAR(frame->media_time_s, 0.1 * static_cast<double>(frames), 0.011);
    EXPECT_GE(frame->capture_ns, last_capture);
    last_time = frame->media_time_s;
    last_capture = frame->capture_ns;
    ++frames;
  }
  EXPECT_EQ(frames, 200);
  EXPECT_EQ(source.frames_read(), 200);
  EXPECT_FALSE(source.read());  // stays at the end
}

TEST(VideoSource, ReadsTheStreetVideoWhoseMp4ContainerIsNamedAvi) {
  if (!fs::exists(kStreetVideo)) GTEST_SKIP() << "shared video absent: " << kStreetVideo;
  VideoSource source(kStreetVideo);
  EXPECT_EQ(source.width(), 1280);
  EXPECT_EQ(source.height(), 720);
  EXPECT_NEAR(source.fps(), 50.0, 1e-6);
  std::int64_t frames = 0;
  double last_time = -1.0;
  while (auto frame = source.read()) {
    EXPECT_GT(frame->media_time_s, last_time);
    last_time = frame->media_time_s;
    ++frames;
  }
  EXPECT_EQ(frames, 205);
  EXPECT_NEAR(last_time, 204.0 / 50.0, 0.03);
}

TEST(VideoSource, SkipPassesOverFramesAndKeepsTheCount) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  VideoSource source(kVtestPart);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(source.skip());
  const auto frame = source.read();
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->index, 5);
  EXPECT_NEAR(frame->media_time_s, 0.5, 0.011);
}

TEST(VideoSource, ATruncatedCopyDeliversItsFramesThenNamesTheFileAsTruncated) {
  if (!fs::exists(kVtestPart)) GTEST_SKIP() << "shared video absent: " << kVtestPart;
  const test::TempDir dir;
  const std::string copy = dir.file("vtest_cut.avi");
  const std::string bytes = test::read_file(kVtestPart);
  test::write_file(copy, bytes.substr(0, bytes.size() / 2));
  std::int64_t frames = 0;
  const std::string error = error_of([&] {
    VideoSource source(copy);
    while (source.read()) ++frames;
  });
  expect_names(error, copy, "truncated");
  EXPECT_GT(frames, 20);  // what is there is delivered first
  EXPECT_LT(frames, 200);
}

TEST(VideoSource, AFileCutInsideItsHeaderIsRefusedByName) {
  if (!fs::exists(kStreetVideo)) GTEST_SKIP() << "shared video absent: " << kStreetVideo;
  const test::TempDir dir;
  const std::string copy = dir.file("street_cut.avi");
  test::write_file(copy, test::read_file(kStreetVideo).substr(0, 4000));
  expect_names(error_of([&] { VideoSource source(copy); }), copy, "");
}

TEST(VideoSource, RandomBytesNamedAviAreRefusedByName) {
  const test::TempDir dir;
  const std::string file = dir.file("noise.avi");
  std::mt19937 rng(7);
  std::string bytes(200000, '\0');
  for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
  test::write_file(file, bytes);
  expect_names(error_of([&] { VideoSource source(file); }), file, "");
}

TEST(VideoSource, EmptyAndMissingFilesAreRefusedByName) {
  const test::TempDir dir;
  const std::string empty = dir.file("empty.mp4");
  test::write_file(empty, "");
  expect_names(error_of([&] { VideoSource source(empty); }), empty, "empty");
  const std::string missing = dir.file("missing.mp4");
  expect_names(error_of([&] { VideoSource source(missing); }), missing, "no such file");
}

TEST(VideoSource, AnAbsentCameraDeviceIsRefusedByName) {
  if (fs::exists("/dev/video9")) GTEST_SKIP() << "/dev/video9 exists on this machine";
  expect_names(error_of([] { VideoSource source("/dev/video9"); }), "/dev/video9",
               "no such camera device");
  expect_names(error_of([] { VideoSource source("9"); }), "9", "no such camera device");
}

TEST(VideoSource, AnUnreachableStreamIsRefusedByNameWithinItsTimeout) {
  SourceOptions options;
  options.timeout_ms = 1000;
  const std::string url = "rtsp://127.0.0.1:9/none";  // port 9 (discard): nothing listens
  expect_names(error_of([&] { VideoSource source(url, options); }), url, "network stream");
}

cv::Mat numbered_image(int n) {
  cv::Mat image(24, 32, CV_8UC3, cv::Scalar(n, 2 * n, 3 * n));
  return image;
}

TEST(VideoSource, ReadsAnImageFolderInNaturalNumberOrder) {
  const test::TempDir dir;
  for (int n : {10, 2, 1, 0})
    cv::imwrite(dir.file("frame_" + std::to_string(n) + ".png"), numbered_image(n));
  test::write_file(dir.file("notes.txt"), "not an image");
  SourceOptions options;
  options.folder_fps = 20.0;
  VideoSource source(dir.path().string(), options);
  EXPECT_EQ(source.kind(), SourceKind::image_folder);
  EXPECT_EQ(source.frame_count(), 4);
  EXPECT_EQ(source.width(), 32);
  std::vector<int> order;
  while (auto frame = source.read()) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(frame->image.data());
    order.push_back(p[0]);  // blue channel = the number in the name
    EXPECT_NEAR(frame->media_time_s, 0.05 * static_cast<double>(frame->index), 1e-9);
  }
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 10}));
}

TEST(VideoSource, ADamagedImageInAFolderIsNamed) {
  const test::TempDir dir;
  cv::imwrite(dir.file("a_1.png"), numbered_image(1));
  test::write_file(dir.file("a_2.png"), "\x89PNG but not really");
  VideoSource source(dir.path().string());
  EXPECT_TRUE(source.read());
  expect_names(error_of([&] { source.read(); }), dir.file("a_2.png"), "not an image");
}

TEST(VideoSource, AFolderWithoutImagesIsRefusedByName) {
  const test::TempDir dir;
  test::write_file(dir.file("notes.txt"), "x");
  expect_names(error_of([&] { VideoSource source(dir.path().string()); }), dir.path().string(),
               "no images");
}

}  // namespace
}  // namespace mocap::video
