#include "camera/pose2sim_calibration.hpp"

#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/input_error.hpp"
#include "support/files.hpp"
#include "support/shared_data.hpp"

namespace mocap::camera {
namespace {

const char* kTwoCameras = R"([cam_01]
name = "cam_01"
size = [ 1088.0, 1920.0]
matrix = [ [ 1681.244873046875, 0.0, 532.97369384375], [ 0.0, 1681.075439453125, 948.137390140625], [ 0.0, 0.0, 1.0]]
distortions = [ -0.000721609375, 0.002187234375, 9.5e-06, 1.078125e-05]
rotation = [ 1.6882754799999993, 1.0483220499999997, -0.41955852000000016]
translation = [ 0.3211048899999996, 0.9563320600000009, 2.8907130499999996]
fisheye = false

# a comment, and an array over several lines
[cam_02]
name = "cam_02"   # trailing comment
size = [ 640, 480 ]
matrix = [
  [ 500.0, 0.0, 320.0],
  [ 0.0, 510.0, 240.0],
  [ 0.0, 0.0, 1.0],
]
distortions = [ 0.0, 0.0, 0.0, 0.0]
rotation = [ 0.0, 0.0, 0.0]
translation = [ 0.0, 0.0, 2.0]
fisheye = false

[metadata]
adjusted = false
error = 0.0
)";

std::string error_of(const std::string& text, const std::string& name = "calib.toml") {
  try {
    parse_pose2sim_calibration(text, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Pose2SimCalibration, ParsesEveryKey) {
  const auto cams = parse_pose2sim_calibration(kTwoCameras, "calib.toml");
  ASSERT_EQ(cams.size(), 2u);
  EXPECT_EQ(cams[0].section, "cam_01");
  EXPECT_EQ(cams[0].name, "cam_01");
  EXPECT_EQ(cams[0].intrinsics.width, 1088);
  EXPECT_EQ(cams[0].intrinsics.height, 1920);
  EXPECT_DOUBLE_EQ(cams[0].intrinsics.fx(), 1681.244873046875);
  EXPECT_DOUBLE_EQ(cams[0].intrinsics.cy(), 948.137390140625);
  ASSERT_EQ(cams[0].intrinsics.distortion.size(), 4u);
  EXPECT_DOUBLE_EQ(cams[0].intrinsics.distortion[2], 9.5e-06);
  EXPECT_DOUBLE_EQ(cams[0].rotation.y, 1.0483220499999997);
  EXPECT_DOUBLE_EQ(cams[0].translation.z, 2.8907130499999996);
  EXPECT_FALSE(cams[0].fisheye);
  EXPECT_EQ(cams[1].intrinsics.width, 640);
  EXPECT_DOUBLE_EQ(cams[1].intrinsics.fy(), 510.0);
}

TEST(Pose2SimCalibration, ProjectsThroughKRt) {
  const auto cams = parse_pose2sim_calibration(kTwoCameras, "calib.toml");
  // cam_02: identity rotation, 2 m in front: a point at (0.2, -0.1, 0) world is at depth 2.
  const glm::dvec2 p = cams[1].project({0.2, -0.1, 0.0});
  EXPECT_NEAR(p.x, 500.0 * 0.1 + 320.0, 1e-9);
  EXPECT_NEAR(p.y, 510.0 * -0.05 + 240.0, 1e-9);
  // The centre projects nowhere: it is -R^T t, at depth 0.
  EXPECT_NEAR(cams[0].to_camera(cams[0].centre()).z, 0.0, 1e-12);
  // Rodrigues gives a proper rotation: R R^T = I.
  const glm::dmat3 r = cams[0].rotation_matrix();
  const glm::dmat3 i = r * glm::transpose(r);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(i[a][b], a == b ? 1.0 : 0.0, 1e-12);
  // A rotation of 90 degrees about z turns x into y.
  const glm::dvec3 y = rodrigues({0.0, 0.0, std::acos(-1.0) / 2}) * glm::dvec3(1, 0, 0);
  EXPECT_NEAR(y.y, 1.0, 1e-12);
}

TEST(Pose2SimCalibration, MissingKeyNamesFileTableAndKey) {
  std::string text = kTwoCameras;
  const auto at = text.find("rotation = [ 0.0");
  text.erase(at, text.find('\n', at) - at + 1);
  const std::string e = error_of(text, "my_calib.toml");
  EXPECT_NE(e.find("my_calib.toml"), std::string::npos) << e;
  EXPECT_NE(e.find("[cam_02]"), std::string::npos) << e;
  EXPECT_NE(e.find("rotation"), std::string::npos) << e;
}

TEST(Pose2SimCalibration, BadValuesNameTheKey) {
  std::string text = kTwoCameras;
  const std::string translation = "translation = [ 0.0, 0.0, 2.0]";
  text.replace(text.find(translation), translation.size(), "translation = [ 0.0, 2.0]");
  std::string e = error_of(text);
  EXPECT_NE(e.find("[cam_02] translation"), std::string::npos) << e;
  EXPECT_NE(e.find("expected 3 numbers"), std::string::npos) << e;
  text = kTwoCameras;
  const std::string last_row = "[ 0.0, 0.0, 1.0],\n]";
  text.replace(text.find(last_row), last_row.size(), "[ 0.0, 0.0, 2.0],\n]");
  e = error_of(text);
  EXPECT_NE(e.find("[cam_02] matrix"), std::string::npos) << e;
  EXPECT_NE(error_of(std::string(kTwoCameras) + "[cam_01]\n").find("twice"), std::string::npos);
}

TEST(Pose2SimCalibration, EmptyAndNoCamerasAreErrors) {
  EXPECT_NE(error_of("").find("no camera table"), std::string::npos);
  EXPECT_NE(error_of("[metadata]\nadjusted = false\n").find("no camera table"), std::string::npos);
  test::TempDir dir;
  test::write_file(dir.file("empty.toml"), "");
  try {
    read_pose2sim_calibration(dir.file("empty.toml"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty.toml"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_pose2sim_calibration(dir.file("absent.toml")), InputError);
}

// Every prefix of a valid file either parses (cut inside [metadata]) or is an InputError naming
// the file; never a crash or another exception.
TEST(Pose2SimCalibration, EveryTruncationIsHandled) {
  const std::string text = kTwoCameras;
  int errors = 0;
  for (std::size_t n = 0; n < text.size(); ++n) {
    try {
      const auto cams = parse_pose2sim_calibration(text.substr(0, n), "cut.toml");
      EXPECT_GE(cams.size(), 1u);
    } catch (const InputError& e) {
      ++errors;
      EXPECT_NE(std::string(e.what()).find("cut.toml"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(errors, static_cast<int>(text.size() * 3 / 4));
}

TEST(Pose2SimCalibration, RandomBytesAreInputErrors) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    std::string bytes(1 + rng() % 400, '\0');
    for (char& c : bytes) c = static_cast<char>(rng() % 256);
    if (trial % 3 == 0) bytes = "[cam_01]\nname = " + bytes;  // garbage after a valid start
    if (trial % 3 == 1) bytes = "[cam_01]\nmatrix = [[[[[[[[[[[[[[[[[[" + bytes;
    EXPECT_THROW(parse_pose2sim_calibration(bytes, "random.toml"), InputError);
  }
}

TEST(Pose2SimCalibration, ReadsTheSharedFile) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/calibration/Calib_qualisys.toml");
  const auto cams = read_pose2sim_calibration(test::shared_data() /
                                              "eval/pose2sim_demo/calibration/Calib_qualisys.toml");
  ASSERT_EQ(cams.size(), 4u);
  for (std::size_t i = 0; i < cams.size(); ++i) {
    EXPECT_EQ(cams[i].name, "cam_0" + std::to_string(i + 1));
    EXPECT_EQ(cams[i].intrinsics.width, 1088);
    EXPECT_EQ(cams[i].intrinsics.height, 1920);
    EXPECT_GT(cams[i].intrinsics.fx(), 1670);  // README: f = 1673-1682 px
    EXPECT_LT(cams[i].intrinsics.fx(), 1685);
    // Every camera is 3-5 m from the world origin, where the person stands.
    const double d = glm::length(cams[i].centre());
    EXPECT_GT(d, 2.5);
    EXPECT_LT(d, 6.0);
    EXPECT_GT(cams[i].to_camera({0, 0, 1}).z, 0.0) << "the origin must be in front";
  }
}

}  // namespace
}  // namespace mocap::camera
