#include "camera/camera_file.hpp"

#include <cmath>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "camera/rig.hpp"
#include "core/input_error.hpp"
#include "support/files.hpp"

namespace mocap::camera {
namespace {

// A camera file as OpenCV's calibration sample writes it.
const char* kOpenCvFile = R"(%YAML:1.0
---
calibration_time: "Sun 22 Nov 2026"
nframes: 13
image_width: 640
image_height: 480
board_width: 9
board_height: 6
square_size: 1.
flags: 0
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 5.3591573396163199e+02, 0., 3.4228315473308373e+02, 0.,
       5.3591573396163199e+02, 2.3557082909788173e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ -2.6637260909660682e-01, -3.8588898922304653e-02,
       1.7831947042852964e-03, -2.8122100441115472e-04,
       2.3839153080878486e-01 ]
avg_reprojection_error: 3.9259098975581364e-01
)";

std::string error_of(const std::string& path) {
  try {
    read_camera_file(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CameraFile, ReadsOpenCvCalibrationOutput) {
  test::TempDir dir;
  test::write_file(dir.file("cam.yml"), kOpenCvFile);
  const Camera c = read_camera_file(dir.file("cam.yml"));
  EXPECT_EQ(c.name, "cam_01");  // the single-camera file is a one-camera rig
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_DOUBLE_EQ(c.fx, 5.3591573396163199e+02);
  EXPECT_DOUBLE_EQ(c.cx, 3.4228315473308373e+02);
  EXPECT_DOUBLE_EQ(c.cy, 2.3557082909788173e+02);
  EXPECT_EQ(c.rotation, glm::dmat3(1.0));  // its frame is the world
  EXPECT_EQ(c.translation, glm::dvec3(0.0));
  ASSERT_EQ(c.distortion.size(), 5u);
  EXPECT_DOUBLE_EQ(c.distortion[0], -2.6637260909660682e-01);
  EXPECT_DOUBLE_EQ(c.distortion[4], 2.3839153080878486e-01);
}

TEST(CameraFile, WriteThenReadIsEqual) {
  test::TempDir dir;
  Camera c;
  c.name = "cam_01";
  c.width = 1920;
  c.height = 1080;
  c.fx = 1401.25;
  c.fy = 1399.75;
  c.cx = 961.5;
  c.cy = 540.125;
  c.distortion = {-0.1, 0.02, 0.001, -0.0005, 0.003};
  write_camera_file(dir.file("c.yaml"), c, 0.25);
  EXPECT_EQ(read_camera_file(dir.file("c.yaml")), c);
  EXPECT_NE(test::read_file(dir.file("c.yaml")).find("avg_reprojection_error"), std::string::npos);
}

TEST(CameraFile, FromFovRoundTrips) {
  test::TempDir dir;
  const Camera c = Camera::from_fov(1280, 720, 70.0);
  write_camera_file(dir.file("f.yml"), c);
  EXPECT_EQ(read_camera_file(dir.file("f.yml")), c);
}

TEST(CameraFile, MissingAndEmptyFilesNameTheFile) {
  test::TempDir dir;
  EXPECT_NE(error_of(dir.file("nope.yml")).find("nope.yml: no such file"), std::string::npos);
  test::write_file(dir.file("empty.yml"), "");
  EXPECT_NE(error_of(dir.file("empty.yml")).find("empty.yml: empty file"), std::string::npos);
}

TEST(CameraFile, MissingKeysAreNamed) {
  test::TempDir dir;
  const std::string full = kOpenCvFile;
  for (const std::string key :
       {"image_width", "image_height", "camera_matrix", "distortion_coefficients"}) {
    std::string text = full;
    const size_t at = text.find(key + ":");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, key.size(), "renamed_" + key);
    const std::string path = dir.file("no_" + key + ".yml");
    test::write_file(path, text);
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("missing key '" + key + "'"), std::string::npos) << error;
  }
}

TEST(CameraFile, WrongShapesAreNamed) {
  test::TempDir dir;
  // camera_matrix 3x2 with six values.
  std::string text = std::string(kOpenCvFile);
  const size_t k = text.find("camera_matrix");
  const size_t d = text.find("distortion_coefficients");
  text.replace(k, d - k,
               "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 2\n   dt: d\n"
               "   data: [ 500., 0., 0., 500., 0., 0. ]\n");
  test::write_file(dir.file("k.yml"), text);
  std::string error = error_of(dir.file("k.yml"));
  EXPECT_NE(error.find("k.yml: key 'camera_matrix' must be 3x3, not 3x2"), std::string::npos)
      << error;

  // A 2x3 distortion matrix.
  text = kOpenCvFile;
  const size_t d2 = text.find("distortion_coefficients");
  const size_t e = text.find("avg_reprojection_error");
  text.replace(d2, e - d2,
               "distortion_coefficients: !!opencv-matrix\n   rows: 2\n   cols: 3\n   dt: d\n"
               "   data: [ 0., 0., 0., 0., 0., 0. ]\n");
  test::write_file(dir.file("d.yml"), text);
  error = error_of(dir.file("d.yml"));
  EXPECT_NE(error.find("d.yml: key 'distortion_coefficients' must be a vector"), std::string::npos)
      << error;

  // A scalar where a matrix belongs, and a string where a size belongs.
  text = kOpenCvFile;
  text.replace(text.find("image_width: 640"), 16, "image_width: wide");
  test::write_file(dir.file("w.yml"), text);
  error = error_of(dir.file("w.yml"));
  EXPECT_NE(error.find("w.yml: key 'image_width' is not an integer"), std::string::npos) << error;
  test::write_file(dir.file("s.yml"),
                   "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: 3\n"
                   "distortion_coefficients: 0\n");
  error = error_of(dir.file("s.yml"));
  EXPECT_NE(error.find("s.yml: key 'camera_matrix'"), std::string::npos) << error;
}

TEST(CameraFile, TruncatedFilesGiveAnErrorNamingTheFile) {
  test::TempDir dir;
  // Every cut before the optional last key loses some required data.
  const std::string full = kOpenCvFile;
  const size_t last = full.find("avg_reprojection_error");
  for (size_t n = 1; n < last; n += 7) {
    const std::string path = dir.file("t.yml");
    test::write_file(path, full.substr(0, n));
    try {
      read_camera_file(path);
      ADD_FAILURE() << "no error for the first " << n << " bytes";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(CameraFile, RandomBytesGiveAnErrorNamingTheFile) {
  test::TempDir dir;
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    std::string bytes(1 + rng() % 600, '\0');
    for (char& c : bytes) c = static_cast<char>(rng() % 256);
    std::string name = std::to_string(trial);
    name += ".yml";
    const std::string path = dir.file(name);
    test::write_file(path, bytes);
    try {
      read_camera_file(path);
      ADD_FAILURE() << "no error for random file " << trial;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

// The OpenCV sample file with a ground plane: the camera 1.5 m above the floor, tilted 30 degrees
// down (normal (0, -cos 30, -sin 30)).
std::string with_ground(const std::string& normal_data = "0., -8.6602540378443860e-01, -0.5",
                        const std::string& offset = "1.5", int rows = 3, int cols = 1) {
  return std::string(kOpenCvFile) +
         "ground_normal: !!opencv-matrix\n   rows: " + std::to_string(rows) +
         "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ " + normal_data +
         " ]\nground_offset: " + offset + "\n";
}

std::string ground_error_of(const std::string& path) {
  try {
    read_ground_plane(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CameraFileGround, AbsentKeysGiveNoPlane) {
  test::TempDir dir;
  test::write_file(dir.file("cam.yml"), kOpenCvFile);
  EXPECT_FALSE(read_ground_plane(dir.file("cam.yml")).has_value());
}

TEST(CameraFileGround, ReadsHeightAndTilt) {
  test::TempDir dir;
  test::write_file(dir.file("g.yml"), with_ground());
  const std::optional<GroundPlane> plane = read_ground_plane(dir.file("g.yml"));
  ASSERT_TRUE(plane.has_value());
  EXPECT_DOUBLE_EQ(plane->offset, 1.5);
  const Camera at_origin;  // the plane is in the camera's frame
  EXPECT_DOUBLE_EQ(height_above_m(at_origin, *plane), 1.5);
  EXPECT_NEAR(tilt_below_horizon_deg(at_origin, *plane), 30.0, 1e-9);
  EXPECT_NEAR(tilt_below_horizon_deg(at_origin, {{0.0, -1.0, 0.0}, 2.0}), 0.0, 1e-12);   // level
  EXPECT_NEAR(tilt_below_horizon_deg(at_origin, {{0.0, 0.0, -1.0}, 2.0}), 90.0, 1e-12);  // down
  // The intrinsics read as before.
  EXPECT_DOUBLE_EQ(read_camera_file(dir.file("g.yml")).fx, 5.3591573396163199e+02);
}

TEST(CameraFileGround, WriteKeepsIntrinsicsAndError) {
  test::TempDir dir;
  Camera c = Camera::from_fov(1280, 720, 70.0);
  c.distortion = {-0.1, 0.02, 0.001, -0.0005, 0.003};
  write_camera_file(dir.file("c.yml"), c, 0.375);
  EXPECT_FALSE(read_ground_plane(dir.file("c.yml")).has_value());
  const double s = std::sqrt(0.5);
  const GroundPlane plane{{0.0, -s, -s}, 2.25};
  write_ground_plane(dir.file("c.yml"), plane);
  EXPECT_EQ(read_camera_file(dir.file("c.yml")), c);
  EXPECT_EQ(read_ground_plane(dir.file("c.yml")), plane);
  const std::string text = test::read_file(dir.file("c.yml"));
  EXPECT_NE(text.find("avg_reprojection_error: 3.75"), std::string::npos) << text;
  EXPECT_NE(text.find("ground_normal: !!opencv-matrix"), std::string::npos) << text;
  EXPECT_NE(text.find("ground_offset: 2.25"), std::string::npos) << text;
  // A second write replaces the plane; no temporary file is left behind.
  const GroundPlane level{{0.0, -1.0, 0.0}, 1.0};
  write_ground_plane(dir.file("c.yml"), level);
  EXPECT_EQ(read_ground_plane(dir.file("c.yml")), level);
  EXPECT_FALSE(std::filesystem::exists(dir.file("c.yml.tmp")));
  // Planes that could not be read back are refused, and the file stays as it was.
  EXPECT_THROW(write_ground_plane(dir.file("c.yml"), {{0.0, 0.0, 0.0}, 1.0}),
               std::invalid_argument);
  EXPECT_THROW(write_ground_plane(dir.file("c.yml"), {{0.0, -2.0, 0.0}, 1.0}),
               std::invalid_argument);
  EXPECT_THROW(write_ground_plane(dir.file("c.yml"), {{0.0, -1.0, 0.0}, std::nan("")}),
               std::invalid_argument);
  EXPECT_EQ(read_ground_plane(dir.file("c.yml")), level);
  // Writing into a file that is not a camera file names it.
  test::write_file(dir.file("junk.yml"), "%YAML:1.0\n---\nfoo: 1\n");
  try {
    write_ground_plane(dir.file("junk.yml"), level);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.yml: missing key 'image_width'"), std::string::npos)
        << e.what();
  }
}

TEST(CameraFileGround, MalformedPlanesNameFileAndKey) {
  test::TempDir dir;
  struct Case {
    std::string name, text, expected;
  };
  const std::string nan = ".Nan";
  const Case cases[] = {
      {"shape2", with_ground("0., -1.", "1.5", 2, 1),
       "key 'ground_normal' must be a 3x1 matrix, not 2x1"},
      {"shape9", with_ground("1., 0., 0., 0., 1., 0., 0., 0., 1.", "1.5", 3, 3),
       "key 'ground_normal' must be a 3x1 matrix, not 3x3"},
      {"nan", with_ground("0., " + nan + ", 0.", "1.5"),
       "key 'ground_normal' has a non-finite value"},
      {"inf", with_ground("0., -1., 0.", ".Inf"), "key 'ground_offset' is not finite"},
      {"zero", with_ground("0., 0., 0."), "key 'ground_normal' is the zero vector"},
      {"long", with_ground("0., -2., 0."), "key 'ground_normal' must be a unit vector"},
      {"text", with_ground("0., -1., 0.", "high"), "key 'ground_offset' is not a number"},
      {"scalar", std::string(kOpenCvFile) + "ground_normal: 3\nground_offset: 1.5\n",
       "key 'ground_normal'"},
      {"no_offset",
       std::string(kOpenCvFile) + "ground_normal: !!opencv-matrix\n   rows: 3\n"
                                  "   cols: 1\n   dt: d\n   data: [ 0., -1., 0. ]\n",
       "missing key 'ground_offset'"},
      {"no_normal", std::string(kOpenCvFile) + "ground_offset: 1.5\n",
       "missing key 'ground_normal'"},
  };
  for (const Case& c : cases) {
    const std::string path = dir.file(c.name + ".yml");
    test::write_file(path, c.text);
    const std::string error = ground_error_of(path);
    EXPECT_NE(error.find(path + ": "), std::string::npos) << c.name << ": " << error;
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.name << ": " << error;
  }
}

TEST(CameraFileGround, TruncatedPlanesGiveAnErrorNamingTheFile) {
  test::TempDir dir;
  const std::string full = with_ground();
  // Every cut from the start of ground_normal until the offset's value begins loses data.
  const size_t first = full.find("ground_normal");
  const size_t value = full.find("ground_offset: ") + 15;
  for (size_t n = first + 1; n < value; n += 3) {
    const std::string path = dir.file("t.yml");
    test::write_file(path, full.substr(0, n));
    try {
      read_ground_plane(path);
      ADD_FAILURE() << "no error for the first " << n
                    << " bytes: " << full.substr(first, n - first);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  // Cut before the ground keys, the file simply has no plane.
  test::write_file(dir.file("before.yml"), full.substr(0, first));
  EXPECT_FALSE(read_ground_plane(dir.file("before.yml")).has_value());
  // A missing file is named.
  EXPECT_NE(ground_error_of(dir.file("nope.yml")).find("nope.yml: no such file"),
            std::string::npos);
  // Random bytes after a valid camera file: an error naming the file or no plane, never a crash.
  std::mt19937 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    std::string bytes = full.substr(0, first + rng() % (full.size() - first));
    for (int i = 0; i < 40; ++i) bytes += static_cast<char>(rng() % 256);
    std::string name = std::to_string(trial);
    name += "r.yml";
    const std::string path = dir.file(name);
    test::write_file(path, bytes);
    try {
      read_ground_plane(path);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mocap::camera
