// The floor from a board lying on it: (1) a real photo, opencv-doc's left01.jpg, with the camera
// calibrated from left01..14, checked against a board pose computed independently here; (2) a
// SYNTHETIC ChArUco render with a known camera height and tilt.

#include "camera/ground_from_board.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "camera/chessboard_calibration.hpp"
#include "camera/rig.hpp"
#include "core/input_error.hpp"
#include "support/board_render.hpp"
#include "support/files.hpp"

namespace mocap::camera {
namespace {

const std::string kDataDir = "/usr/share/doc/opencv-doc/examples/data";
constexpr double kPi = 3.14159265358979323846;

std::vector<std::string> opencv_left_images() {
  std::vector<std::string> files;
  for (int i = 1; i <= 14; ++i) {
    const std::string name = kDataDir + "/left" + (i < 10 ? "0" : "") + std::to_string(i) + ".jpg";
    if (std::filesystem::exists(name)) files.push_back(name);
  }
  return files;
}

double dot(const glm::dvec3& a, const cv::Vec3d& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

TEST(GroundFromBoard, RealChessboardPhotoMatchesAnIndependentPose) {
  const std::vector<std::string> files = opencv_left_images();
  if (files.size() != 13)
    GTEST_SKIP() << "needs " << kDataDir << "/left01.jpg ... left14.jpg (apt install opencv-doc)";
  ChessboardOptions options;
  options.square_mm = 25.0;
  const Camera cam = calibrate_chessboard_images(files, options).camera;
  BoardSpec board;  // chessboard 9x6 inner corners
  board.square_mm = 25.0;
  const FloorFromBoard floor = ground_from_board_image(files[0], cam, board);
  std::cout << "left01: height " << floor.plane.offset << " m, tilt "
            << tilt_below_horizon_deg(Camera{}, floor.plane) << " deg, pose RMS " << floor.rms_px
            << " px\n";
  EXPECT_EQ(floor.corners, 54);
  EXPECT_LT(floor.rms_px, 1.0);

  // The board pose computed here, independently: corners, solvePnP (iterative).
  const cv::Mat gray = cv::imread(files[0], cv::IMREAD_GRAYSCALE);
  std::vector<cv::Point2f> corners;
  ASSERT_TRUE(cv::findChessboardCorners(gray, cv::Size(9, 6), corners));
  cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.01));
  std::vector<cv::Point3d> object;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 9; ++c) object.emplace_back(0.025 * c, 0.025 * r, 0.0);  // metres
  const cv::Matx33d K(cam.matrix().data());
  cv::Vec3d rvec, tvec;
  ASSERT_TRUE(cv::solvePnP(object, corners, K, cam.distortion, rvec, tvec));
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);

  const auto& n = floor.plane.normal;
  EXPECT_NEAR(std::hypot(n[0], n[1], n[2]), 1.0, 1e-9);
  EXPECT_GT(floor.plane.offset, 0.0);  // the camera is above the "floor"
  // Every board corner lies on the plane within 1 mm ...
  for (const cv::Point3d& p : object) {
    const cv::Vec3d x = R * cv::Vec3d(p.x, p.y, p.z) + tvec;
    EXPECT_NEAR(dot(n, x) + floor.plane.offset, 0.0, 0.001);
  }
  // ... the camera's distance from it is |t . n| ...
  EXPECT_NEAR(floor.plane.offset, std::abs(dot(n, tvec)), 0.001);
  // ... the normal is the board's z axis, and points to the camera's side.
  const cv::Vec3d z(R(0, 2), R(1, 2), R(2, 2));
  EXPECT_GT(std::abs(dot(n, z)), std::cos(0.5 * kPi / 180.0));
  EXPECT_LT(dot(n, tvec), 0.0);

  // A 4 mm thick board: the floor is 4 mm further from the camera, same normal.
  const FloorFromBoard thick = ground_from_board_image(files[0], cam, board, 4.0);
  EXPECT_NEAR(thick.plane.offset - floor.plane.offset, 0.004, 1e-9);
  EXPECT_EQ(thick.plane.normal, floor.plane.normal);
}

// A camera `height_m` above the floor looking `tilt_deg` below the horizon; a ChArUco board
// (7x5 squares of 100 mm, 5 mm thick) lies on the floor ahead of it, turned by 20 degrees.
struct FloorScene {
  double height_m, tilt_deg, ahead_m, thickness_mm;
};

TEST(GroundFromBoard, SyntheticCharucoRecoversHeightAndTilt) {
  const cv::Matx33d K(1000.0, 0.0, 640.0, 0.0, 1000.0, 480.0, 0.0, 0.0, 1.0);
  const cv::Size size(1280, 960);
  BoardSpec board;
  board.kind = BoardKind::charuco;
  board.columns = 7;
  board.rows = 5;
  board.square_mm = 100.0;
  board.marker_mm = 75.0;
  board.dictionary = "DICT_5X5_100";
  const test::CharucoTexture texture =
      test::charuco_texture(7, 5, 100.0, 75.0, cv::aruco::DICT_5X5_100, 80);
  Camera cam;
  cam.name = "cam_01";
  cam.width = size.width;
  cam.height = size.height;
  cam.fx = K(0, 0);
  cam.fy = K(1, 1);
  cam.cx = K(0, 2);
  cam.cy = K(1, 2);

  test::TempDir dir;
  const FloorScene scenes[] = {{1.2, 40.0, 1.4, 5.0}, {2.0, 35.0, 2.2, 0.0}, {0.8, 55.0, 0.6, 0.0}};
  for (const FloorScene& s : scenes) {
    const double t = s.tilt_deg * kPi / 180.0;
    // World: z up, floor z = 0, camera at (0, 0, h) looking along +y tilted down.
    // Rows of world -> camera: x_c = (1,0,0), y_c = (0,-sin,-cos), z_c = (0,cos,-sin).
    const cv::Matx33d Rwc(1, 0, 0, 0, -std::sin(t), -std::cos(t), 0, std::cos(t), -std::sin(t));
    const double yaw = 20.0 * kPi / 180.0;
    const cv::Vec3d e1(std::cos(yaw), std::sin(yaw), 0), e2(-std::sin(yaw), std::cos(yaw), 0);
    // Board axes: x along e1, y along -e2 (the texture's y points down in the image of a board
    // seen from above), z = x cross y = down; its centre `ahead_m` in front of the camera.
    const cv::Matx33d Rwb(e1[0], -e2[0], 0, e1[1], -e2[1], 0, 0, 0, -1);
    const double w = 700.0, h = 500.0;  // mm
    const cv::Vec3d centre(100.0, 1000.0 * s.ahead_m, s.thickness_mm);
    const cv::Vec3d origin = centre - Rwb * cv::Vec3d(0.5 * w, 0.5 * h, 0.0);
    const cv::Matx33d R = Rwc * Rwb;
    const cv::Vec3d tvec = Rwc * (origin - cv::Vec3d(0, 0, 1000.0 * s.height_m));
    cv::Vec3d rvec;
    cv::Rodrigues(R, rvec);
    const std::string file = dir.file("floor.png");
    cv::imwrite(file, test::render_board(texture, K, size, rvec, tvec, 3));
    const FloorFromBoard floor = ground_from_board_image(file, cam, board, s.thickness_mm);
    std::cout << "synthetic floor: true height " << s.height_m << " m tilt " << s.tilt_deg
              << " deg -> " << height_above_m(Camera{}, floor.plane) << " m "
              << tilt_below_horizon_deg(Camera{}, floor.plane) << " deg (" << floor.corners
              << " corners, RMS " << floor.rms_px << " px)\n";
    // The plane is in the camera's frame: the camera at the origin.
    EXPECT_NEAR(height_above_m(Camera{}, floor.plane), s.height_m, 0.01);
    EXPECT_NEAR(tilt_below_horizon_deg(Camera{}, floor.plane), s.tilt_deg, 0.5);
    // The floor normal is the world's up, seen from the camera: (0, -cos, -sin).
    EXPECT_NEAR(floor.plane.normal[0], 0.0, 0.01);
    EXPECT_NEAR(floor.plane.normal[1], -std::cos(t), 0.01);
    EXPECT_GT(floor.corners, 12);
  }
}

TEST(GroundFromBoard, ErrorsNameTheImage) {
  test::TempDir dir;
  const Camera cam = Camera::from_fov(640, 480, 60.0);
  BoardSpec board;
  test::write_file(dir.file("bad.jpg"), "garbage");
  try {
    ground_from_board_image(dir.file("bad.jpg"), cam, board);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.jpg: unreadable image"), std::string::npos);
  }
  cv::imwrite(dir.file("small.png"), cv::Mat(cv::Size(320, 240), CV_8UC3, cv::Scalar::all(90)));
  try {
    ground_from_board_image(dir.file("small.png"), cam, board);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("small.png: the image is 320x240, the camera file is "
                                         "for 640x480"),
              std::string::npos)
        << e.what();
  }
  cv::imwrite(dir.file("blank.png"), cv::Mat(cv::Size(640, 480), CV_8UC3, cv::Scalar::all(90)));
  try {
    ground_from_board_image(dir.file("blank.png"), cam, board);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("blank.png: board not found (chessboard 9x6"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ground_from_board_image(dir.file("blank.png"), cam, board, -1.0),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::camera
