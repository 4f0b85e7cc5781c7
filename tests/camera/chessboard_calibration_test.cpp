#include "camera/chessboard_calibration.hpp"

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "camera/camera_file.hpp"
#include "core/input_error.hpp"
#include "support/files.hpp"

namespace mocap::camera {
namespace {

// Debian's opencv-doc ships OpenCV's calibration sample images (9x6 inner corners, 640x480).
const std::string kDataDir = "/usr/share/doc/opencv-doc/examples/data";

std::vector<std::string> opencv_left_images() {
  std::vector<std::string> files;
  for (int i = 1; i <= 14; ++i) {
    const std::string name = kDataDir + "/left" + (i < 10 ? "0" : "") + std::to_string(i) + ".jpg";
    if (std::filesystem::exists(name)) files.push_back(name);
  }
  return files;
}

TEST(ChessboardCalibration, OpenCvSampleImagesGiveSubPixelError) {
  const std::vector<std::string> files = opencv_left_images();
  if (files.size() != 13)
    GTEST_SKIP() << "needs " << kDataDir << "/left01.jpg ... left14.jpg (apt install opencv-doc)";
  ChessboardOptions options;
  options.square_mm = 25.0;
  const ChessboardCalibration result = calibrate_chessboard_images(files, options);
  std::cout << "RMS reprojection error " << result.rms_px << " px over " << result.used.size()
            << " images; fx " << result.camera.fx << " fy " << result.camera.fy << " cx "
            << result.camera.cx << " cy " << result.camera.cy << "\n";
  EXPECT_GT(result.rms_px, 0.0);
  EXPECT_LT(result.rms_px, 1.0);
  EXPECT_GE(result.used.size(), 10u);
  EXPECT_EQ(result.used.size() + result.skipped.size(), files.size());
  EXPECT_EQ(result.camera.width, 640);
  EXPECT_EQ(result.camera.height, 480);
  // A plausible camera: focal length in pixels ~ 530, principal point near the centre.
  EXPECT_NEAR(result.camera.fx, 535.0, 30.0);
  EXPECT_NEAR(result.camera.fy, 535.0, 30.0);
  EXPECT_NEAR(result.camera.cx, 320.0, 40.0);
  EXPECT_NEAR(result.camera.cy, 240.0, 40.0);
  EXPECT_EQ(result.camera.distortion.size(), 5u);

  test::TempDir dir;
  write_camera_file(dir.file("left.yml"), result.camera, result.rms_px);
  EXPECT_EQ(read_camera_file(dir.file("left.yml")), result.camera);
}

TEST(ChessboardCalibration, WrongBoardSizeAndUnreadableFilesAreSkippedByName) {
  const std::vector<std::string> files = opencv_left_images();
  if (files.size() != 13)
    GTEST_SKIP() << "needs " << kDataDir << "/left01.jpg ... left14.jpg (apt install opencv-doc)";
  test::TempDir dir;
  test::write_file(dir.file("garbage.jpg"), "not an image at all");
  std::vector<std::string> inputs(files.begin(), files.begin() + 4);
  inputs.push_back(dir.file("garbage.jpg"));
  inputs.push_back(dir.file("missing.jpg"));
  const ChessboardCalibration result = calibrate_chessboard_images(inputs, {});
  EXPECT_EQ(result.used.size(), 4u);
  ASSERT_EQ(result.skipped.size(), 2u);
  EXPECT_EQ(result.skipped[0].name, dir.file("garbage.jpg"));
  EXPECT_EQ(result.skipped[0].reason, "unreadable image");
  EXPECT_EQ(result.skipped[1].name, dir.file("missing.jpg"));

  // An 8x5 board is not what the images show: nothing is found and the error says so.
  ChessboardOptions wrong;
  wrong.inner_columns = 8;
  wrong.inner_rows = 5;
  try {
    calibrate_chessboard_images({files.begin(), files.begin() + 3}, wrong);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("was found in 0 views"), std::string::npos) << e.what();
  }
}

TEST(ChessboardCalibration, VideoEveryNthFrame) {
  const std::vector<std::string> files = opencv_left_images();
  if (files.size() != 13)
    GTEST_SKIP() << "needs " << kDataDir << "/left01.jpg ... left14.jpg (apt install opencv-doc)";
  // A video of the sample images, each shown for two frames: every 2nd frame is each image once.
  test::TempDir dir;
  const std::string video = dir.file("board.avi");
  {
    cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                           cv::Size(640, 480));
    if (!writer.isOpened()) GTEST_SKIP() << "OpenCV cannot write MJPG video here";
    for (const std::string& f : files) {
      const cv::Mat image = cv::imread(f, cv::IMREAD_COLOR);
      writer.write(image);
      writer.write(image);
    }
  }
  ChessboardOptions options;
  options.video_step = 2;
  const ChessboardCalibration result = calibrate_chessboard_video(video, options);
  EXPECT_EQ(result.used.size() + result.skipped.size(), files.size());
  EXPECT_GE(result.used.size(), 10u);
  EXPECT_EQ(result.used.front(), video + "#0");
  EXPECT_LT(result.rms_px, 1.0);
}

TEST(ChessboardCalibration, VideoThatCannotBeOpenedNamesTheFile) {
  test::TempDir dir;
  test::write_file(dir.file("v.mp4"), "garbage");
  try {
    calibrate_chessboard_video(dir.file("v.mp4"), {});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("v.mp4")), std::string::npos) << e.what();
  }
}

TEST(ChessboardCalibration, BadOptionsAreRejected) {
  ChessboardOptions o;
  o.inner_rows = 1;
  EXPECT_THROW(calibrate_chessboard_images({}, o), std::invalid_argument);
  o = {};
  o.square_mm = 0;
  EXPECT_THROW(calibrate_chessboard_images({}, o), std::invalid_argument);
}

}  // namespace
}  // namespace mocap::camera
