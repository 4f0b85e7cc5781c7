// ChArUco calibration on SYNTHETIC images: no real ChArUco photo is on the machine (opencv-doc
// ships none), so the board is drawn by cv::aruco and warped through a known pinhole camera at
// several poses (support/board_render.hpp); the calibration must recover that camera.

#include "camera/charuco_calibration.hpp"

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "camera/board.hpp"
#include "core/input_error.hpp"
#include "support/board_render.hpp"
#include "support/files.hpp"

namespace mocap::camera {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
const cv::Matx33d kK(780.0, 0.0, 405.0, 0.0, 770.0, 298.0, 0.0, 0.0, 1.0);
const cv::Size kSize(800, 600);

BoardSpec board_5x7() {
  BoardSpec b;
  b.kind = BoardKind::charuco;
  b.columns = 5;
  b.rows = 7;
  b.square_mm = 30.0;
  b.marker_mm = 22.0;
  b.dictionary = "DICT_4X4_50";
  return b;
}

// Eight views: the board tilted up to ~35 degrees about different axes, at 350..520 mm, in
// different parts of the image.
std::vector<std::string> write_views(const test::TempDir& dir, const BoardSpec& b) {
  const test::CharucoTexture texture =
      test::charuco_texture(b.columns, b.rows, b.square_mm, b.marker_mm, cv::aruco::DICT_4X4_50);
  const double w = b.columns * b.square_mm, h = b.rows * b.square_mm;
  struct View {
    double ax, ay, az, x, y, z;
  };
  const View views[] = {{0, 0, 0, 0, 0, 420},        {30, 0, 5, -40, 20, 450},
                        {-30, 0, -5, 40, -20, 450},  {0, 32, 10, 60, 0, 430},
                        {0, -32, -10, -60, 10, 430}, {22, 22, 20, -30, -40, 480},
                        {-22, 25, -15, 50, 40, 520}, {20, -25, 30, 20, 30, 380}};
  std::vector<std::string> files;
  unsigned seed = 1;
  for (const View& v : views) {
    // Rotation about x, then y, then z (degrees), as a Rodrigues vector.
    cv::Matx33d Rx, Ry, Rz;
    cv::Rodrigues(cv::Vec3d(v.ax * kDeg, 0, 0), Rx);
    cv::Rodrigues(cv::Vec3d(0, v.ay * kDeg, 0), Ry);
    cv::Rodrigues(cv::Vec3d(0, 0, v.az * kDeg), Rz);
    cv::Vec3d rvec;
    cv::Rodrigues(Rz * Ry * Rx, rvec);
    const cv::Vec3d t = test::translation_for_centre(rvec, w, h, {v.x, v.y, v.z});
    const cv::Mat image = test::render_board(texture, kK, kSize, rvec, t, seed++);
    files.push_back(dir.file("view" + std::to_string(files.size()) + ".png"));
    cv::imwrite(files.back(), image);
  }
  return files;
}

TEST(CharucoCalibration, RecoversTheSyntheticCamera) {
  test::TempDir dir;
  CharucoOptions options;
  options.board = board_5x7();
  const std::vector<std::string> files = write_views(dir, options.board);
  const BoardCalibration result = calibrate_charuco_images(files, options);
  const Camera& c = result.camera;
  std::cout << "synthetic ChArUco: RMS " << result.rms_px << " px over " << result.used.size()
            << " views; fx " << c.fx << " fy " << c.fy << " cx " << c.cx << " cy " << c.cy
            << " (true 780 770 405 298)\n";
  for (const auto& s : result.skipped)
    std::cout << "  skipped " << s.name << ": " << s.reason << "\n";
  EXPECT_EQ(result.used.size(), files.size());
  EXPECT_GT(result.rms_px, 0.0);
  EXPECT_LT(result.rms_px, 1.0);
  EXPECT_EQ(c.width, 800);
  EXPECT_EQ(c.height, 600);
  EXPECT_NEAR(c.fx, 780.0, 0.02 * 780.0);
  EXPECT_NEAR(c.fy, 770.0, 0.02 * 770.0);
  EXPECT_NEAR(c.cx, 405.0, 0.03 * 405.0);
  EXPECT_NEAR(c.cy, 298.0, 0.03 * 298.0);
  ASSERT_EQ(c.distortion.size(), 5u);
  EXPECT_NEAR(c.distortion[0], 0.0, 0.1);  // the renderer has no lens distortion
}

TEST(CharucoCalibration, SkipsViewsWithReasons) {
  test::TempDir dir;
  CharucoOptions options;
  options.board = board_5x7();
  std::vector<std::string> files = write_views(dir, options.board);
  files.resize(4);
  test::write_file(dir.file("garbage.png"), "not a png");
  cv::imwrite(dir.file("blank.png"), cv::Mat(kSize, CV_8U, cv::Scalar(200)));
  cv::imwrite(dir.file("small.png"), cv::Mat(cv::Size(320, 240), CV_8U, cv::Scalar(0)));
  files.push_back(dir.file("garbage.png"));
  files.push_back(dir.file("blank.png"));
  files.push_back(dir.file("small.png"));
  const BoardCalibration result = calibrate_charuco_images(files, options);
  EXPECT_EQ(result.used.size(), 4u);
  ASSERT_EQ(result.skipped.size(), 3u);
  EXPECT_EQ(result.skipped[0].reason, "unreadable image");
  EXPECT_EQ(result.skipped[1].reason, "no ArUco markers of DICT_4X4_50 found");
  EXPECT_EQ(result.skipped[2].reason, "size differs from the first image");

  // The markers of another dictionary are not this board's: nothing is found, the error says so.
  CharucoOptions wrong = options;
  wrong.board.dictionary = "DICT_6X6_250";
  try {
    calibrate_charuco_images({files.begin(), files.begin() + 3}, wrong);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("was found in 0 views"), std::string::npos) << e.what();
  }
}

TEST(CharucoCalibration, Video) {
  test::TempDir dir;
  CharucoOptions options;
  options.board = board_5x7();
  const std::vector<std::string> files = write_views(dir, options.board);
  const std::string video = dir.file("board.avi");
  {
    // Lossless-enough MJPG at high quality; each view shown for two frames.
    cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, kSize, false);
    if (!writer.isOpened()) GTEST_SKIP() << "OpenCV cannot write MJPG video here";
    writer.set(cv::VIDEOWRITER_PROP_QUALITY, 100);
    for (const std::string& f : files) {
      const cv::Mat image = cv::imread(f, cv::IMREAD_GRAYSCALE);
      writer.write(image);
      writer.write(image);
    }
  }
  options.video_step = 2;
  const BoardCalibration result = calibrate_charuco_video(video, options);
  EXPECT_EQ(result.used.size() + result.skipped.size(), files.size());
  EXPECT_GE(result.used.size(), 7u);
  EXPECT_EQ(result.used.front(), video + "#0");
  EXPECT_LT(result.rms_px, 1.0);
  EXPECT_NEAR(result.camera.fx, 780.0, 0.03 * 780.0);
}

TEST(CharucoCalibration, BadBoardsAreRejected) {
  CharucoOptions o;
  o.board = board_5x7();
  o.board.dictionary = "DICT_9X9_1";
  try {
    calibrate_charuco_images({}, o);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown ArUco dictionary 'DICT_9X9_1'"),
              std::string::npos);
  }
  o.board = board_5x7();
  o.board.marker_mm = 30.0;  // not smaller than the square
  EXPECT_THROW(calibrate_charuco_images({}, o), std::invalid_argument);
  o.board = board_5x7();
  o.board.columns = 12;  // 12x7 squares need 42 markers: fine for DICT_4X4_50 ...
  EXPECT_NO_THROW(check_board(o.board));
  o.board.columns = 15;  // ... 52 are too many
  EXPECT_THROW(check_board(o.board), std::invalid_argument);
  o.board = board_5x7();
  o.board.kind = BoardKind::chessboard;
  EXPECT_THROW(calibrate_charuco_images({}, o), std::invalid_argument);
  EXPECT_EQ(aruco_dictionary_names().size(), 21u);
  EXPECT_EQ(describe(board_5x7()), "ChArUco 5x7 squares of 30 mm, markers 22 mm, DICT_4X4_50");
}

}  // namespace
}  // namespace mocap::camera
