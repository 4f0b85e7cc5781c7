// viz::OverlayOutput: the MP4 is made with the first picture (a run that fails before it leaves an
// existing file as it was), holds every picture written, and a write failure names the file.

#include <gtest/gtest.h>

#include <filesystem>

#include <opencv2/videoio.hpp>

#include "core/input_error.hpp"
#include "support/files.hpp"
#include "video/mp4_writer.hpp"
#include "viz/overlay_output.hpp"

namespace mocap::viz {
namespace {

ImageBuffer grey_picture(int level) {
  ImageBuffer image(64, 48, PixelFormat::bgr8);
  for (std::byte& b : image.pixels_for_writing()) b = std::byte(level);
  return image;
}

TEST(OverlayOutput, NoPictureLeavesAnExistingVideoUntouched) {
  test::TempDir dir;
  const std::string mp4 = dir.file("overlay.mp4");
  test::write_file(mp4, "an earlier run's video");
  {
    OverlayOutput output({mp4, 10.0, 0, ""});
    output.close();
  }
  EXPECT_EQ(test::read_file(mp4), "an earlier run's video");
}

TEST(OverlayOutput, EveryPictureIsAFrameAndPngsAsAskedFor) {
  test::TempDir dir;
  const std::string mp4 = dir.file("out/overlay.mp4");
  OverlayOutput output({mp4, 10.0, 10, dir.file("png")});
  for (int k = 0; k < 31; ++k) output.write(grey_picture(4 * k), 100 + k);
  output.close();
  EXPECT_EQ(output.pictures(), 31);
  EXPECT_EQ(output.pngs(), 4);
  EXPECT_TRUE(std::filesystem::exists(dir.file("png/overlay_000130.png")));
  cv::VideoCapture video(mp4, cv::CAP_FFMPEG);
  int frames = 0;
  for (cv::Mat frame; video.read(frame); ++frames) {
    EXPECT_NEAR(cv::mean(frame)[0], 4 * frames, 3.0) << "frame " << frames;
  }
  EXPECT_EQ(frames, 31);
}

// The preset reaches libx264: a name it does not know stops the first write, naming the file.
TEST(OverlayOutput, TheH264PresetReachesTheEncoder) {
  if (!video::h264_available()) GTEST_SKIP() << "this FFmpeg has no libx264";
  test::TempDir dir;
  OverlayOutputOptions fast{dir.file("fast.mp4"), 10.0, 0, ""};
  fast.h264_preset = "ultrafast";
  OverlayOutput written(fast);
  written.write(grey_picture(100), 0);
  written.close();
  EXPECT_TRUE(cv::VideoCapture(fast.video, cv::CAP_FFMPEG).isOpened());
  OverlayOutputOptions unknown{dir.file("unknown.mp4"), 10.0, 0, ""};
  unknown.h264_preset = "no-such-preset";
  OverlayOutput output(unknown);
  try {
    output.write(grey_picture(100), 0);
    FAIL() << "an unknown preset was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown.mp4"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no-such-preset"), std::string::npos) << e.what();
  }
}

TEST(OverlayOutput, AFailedWriteNamesTheFile) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  OverlayOutput output({"/dev/full", 10.0, 0, ""});
  try {
    for (int k = 0; k < 5; ++k) output.write(grey_picture(k), k);
    output.close();
    FAIL() << "no error writing to /dev/full";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mocap::viz
