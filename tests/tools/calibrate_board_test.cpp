// `mocap calibrate intrinsics --board charuco` (on SYNTHETIC renders: no real ChArUco photo is
// on the machine) and `mocap calibrate ground` (opencv-doc's left01.jpg as a board on a floor),
// driven as a user would: the built binary in a child process.

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "camera/camera_file.hpp"
#include "support/board_render.hpp"
#include "support/mocap_process.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;
const std::string kDataDir = "/usr/share/doc/opencv-doc/examples/data";

TEST(CalibrateCharuco, SyntheticViewsThroughTheBinary) {
  test::TempDir dir;
  const cv::Matx33d K(700.0, 0.0, 330.0, 0.0, 700.0, 235.0, 0.0, 0.0, 1.0);
  const test::CharucoTexture texture =
      test::charuco_texture(6, 4, 35.0, 26.0, cv::aruco::DICT_6X6_250);
  std::filesystem::create_directories(dir.file("views"));
  const double tilt[][3] = {{0, 0, 0},   {0.5, 0, 0},  {-0.5, 0, 0.1},
                            {0, 0.5, 0}, {0, -0.5, 0}, {0.35, 0.35, 0.3}};
  int i = 0;
  for (const auto& r : tilt) {
    const cv::Vec3d rvec(r[0], r[1], r[2]);
    const cv::Vec3d t = test::translation_for_centre(rvec, 210.0, 140.0, {0.0, 0.0, 450.0});
    cv::imwrite(dir.file("views/v" + std::to_string(i) + ".png"),
                test::render_board(texture, K, cv::Size(640, 480), rvec, t, 10 + i));
    ++i;
  }
  const std::vector<std::string> base = {
      "calibrate", "intrinsics", dir.file("views"), "--board",     "charuco", "--squares", "6x4",
      "--square",  "35",         "--dictionary",    "DICT_6X6_250"};
  // Without --marker: a clear error.
  test::Mocap no_marker(dir, "no_marker", base);
  EXPECT_EQ(no_marker.wait(60s), 1);
  EXPECT_NE(no_marker.err().find("--marker: a ChArUco board needs its marker size"),
            std::string::npos)
      << no_marker.err();

  std::vector<std::string> args = base;
  args.insert(args.end(), {"--marker", "26", "--out", dir.file("cam.yml")});
  test::Mocap run(dir, "run", args);
  ASSERT_EQ(run.wait(120s), 0) << run.err();
  EXPECT_NE(run.out().find("board ChArUco 6x4 squares of 35 mm, markers 26 mm, DICT_6X6_250"),
            std::string::npos)
      << run.out();
  EXPECT_NE(run.out().find("used 6 views"), std::string::npos) << run.out();
  EXPECT_NE(run.out().find("RMS reprojection error 0."), std::string::npos) << run.out();
  const camera::Camera c = camera::read_camera_file(dir.file("cam.yml"));
  EXPECT_NEAR(c.fx, 700.0, 0.03 * 700.0);
  EXPECT_NEAR(c.fy, 700.0, 0.03 * 700.0);

  std::vector<std::string> bad = base;
  bad.back() = "DICT_3X3_9";
  bad.insert(bad.end(), {"--marker", "26"});
  test::Mocap unknown(dir, "unknown", bad);
  EXPECT_EQ(unknown.wait(60s), 1);
  EXPECT_NE(unknown.err().find("unknown ArUco dictionary 'DICT_3X3_9'"), std::string::npos)
      << unknown.err();
}

TEST(CalibrateGround, BoardOnTheFloorGoesIntoTheCameraFile) {
  std::vector<std::string> calibrate = {"calibrate", "intrinsics"};
  for (int i = 1; i <= 14; ++i) {
    const std::string name = kDataDir + "/left" + (i < 10 ? "0" : "") + std::to_string(i) + ".jpg";
    if (std::filesystem::exists(name)) calibrate.push_back(name);
  }
  if (calibrate.size() != 15)
    GTEST_SKIP() << "needs " << kDataDir << "/left01..14.jpg (opencv-doc)";
  test::TempDir dir;
  const std::string cam = dir.file("left.yml");
  calibrate.insert(calibrate.end(), {"--board", "9x6", "--square", "25", "--out", cam});
  test::Mocap intrinsics(dir, "intrinsics", calibrate);
  ASSERT_EQ(intrinsics.wait(120s), 0) << intrinsics.err();
  const std::string left01 = kDataDir + "/left01.jpg";

  // --out: a copy with the plane; the camera file itself is left as it was.
  test::Mocap copy(dir, "copy",
                   {"calibrate", "ground", "--camera", cam, left01, "--board", "chessboard",
                    "--corners", "9x6", "--square", "25", "--out", dir.file("out/floor.yml")});
  ASSERT_EQ(copy.wait(60s), 0) << copy.err();
  EXPECT_NE(copy.out().find("camera height above the floor 0."), std::string::npos) << copy.out();
  EXPECT_NE(copy.out().find("degrees below the horizon"), std::string::npos) << copy.out();
  EXPECT_FALSE(camera::read_ground_plane(cam).has_value());
  const auto plane = camera::read_ground_plane(dir.file("out/floor.yml"));
  ASSERT_TRUE(plane.has_value());
  EXPECT_EQ(camera::read_camera_file(dir.file("out/floor.yml")), camera::read_camera_file(cam));

  // In place, with a 10 mm board: 10 mm more height.
  test::Mocap in_place(
      dir, "in_place",
      {"calibrate", "ground", "--camera", cam, left01, "--square", "25", "--thickness", "10"});
  ASSERT_EQ(in_place.wait(60s), 0) << in_place.err();
  const auto thick = camera::read_ground_plane(cam);
  ASSERT_TRUE(thick.has_value());
  EXPECT_NEAR(thick->offset - plane->offset, 0.010, 1e-9);

  // --help says where the ground comes from without a board.
  test::Mocap help(dir, "help", {"calibrate", "ground", "--help"});
  EXPECT_EQ(help.wait(30s), 0);
  EXPECT_NE(help.out().find("feet of the people"), std::string::npos) << help.out();

  // A corrupt camera file and a board that is not in the image: errors naming them.
  test::write_file(dir.file("bad.yml"), test::read_file(cam).substr(0, 200));
  test::Mocap corrupt(dir, "corrupt",
                      {"calibrate", "ground", "--camera", dir.file("bad.yml"), left01});
  EXPECT_EQ(corrupt.wait(30s), 1);
  EXPECT_NE(corrupt.err().find(dir.file("bad.yml") + ": "), std::string::npos) << corrupt.err();
  test::Mocap wrong(dir, "wrong",
                    {"calibrate", "ground", "--camera", cam, left01, "--board", "8x5"});
  EXPECT_EQ(wrong.wait(30s), 1);
  EXPECT_NE(wrong.err().find("left01.jpg: board not found (chessboard 8x5"), std::string::npos)
      << wrong.err();
  test::Mocap no_camera(dir, "no_camera", {"calibrate", "ground", left01});
  EXPECT_EQ(no_camera.wait(30s), 1);
  EXPECT_NE(no_camera.err().find("--camera"), std::string::npos) << no_camera.err();
}

}  // namespace
}  // namespace mocap
