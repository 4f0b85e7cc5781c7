// Rig files: the Pose2Sim/anipose TOML layout and OpenCV YAML, read, written, converted, and
// garbage refused naming the file, the line and the key; Pose2Sim's demo calibration re-projects
// its triangulated markers onto its detections.

#include "camera/rig_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "camera/camera_file.hpp"
#include "camera/rig_report.hpp"
#include "core/input_error.hpp"
#include "io/openpose_json.hpp"
#include "io/trc.hpp"
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

// anipose's layout (aniposelib CameraGroup.dump): tables cam_0.., integer sizes, five
// distortion coefficients, trailing commas, no fisheye key; names other than the tables'.
const char* kAnipose = R"([cam_0]
name = "A"
size = [ 1280, 1024,]
matrix = [ [ 1500.5, 0.0, 639.5,], [ 0.0, 1500.5, 511.5,], [ 0.0, 0.0, 1.0,],]
distortions = [ -0.12, 0.0, 0.0, 0.0, 0.0,]
rotation = [ 0.01, -0.02, 0.03,]
translation = [ 0.5, -0.25, 3.0,]

[cam_1]
name = "B"
size = [ 1280, 1024,]
matrix = [ [ 1490.0, 0.0, 640.0,], [ 0.0, 1490.0, 512.0,], [ 0.0, 0.0, 1.0,],]
distortions = [ 0.0, 0.0, 0.0, 0.0, 0.0,]
rotation = [ -0.2, 1.5, 0.1,]
translation = [ -1.0, 0.2, 2.5,]

[metadata]
adjusted = true
error = 0.81
)";

std::string toml_error(const std::string& text, const std::string& name = "calib.toml") {
  try {
    parse_rig_toml(text, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string yaml_error(const std::string& text, const std::string& name = "rig.yml") {
  try {
    parse_rig_yaml(text, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(RigToml, ParsesPose2SimsKeys) {
  const Rig rig = parse_rig_toml(kTwoCameras, "calib.toml");
  ASSERT_EQ(rig.cameras.size(), 2u);
  const Camera& c = rig.cameras[0];
  EXPECT_EQ(c.name, "cam_01");
  EXPECT_EQ(c.width, 1088);
  EXPECT_EQ(c.height, 1920);
  EXPECT_DOUBLE_EQ(c.fx, 1681.244873046875);
  EXPECT_DOUBLE_EQ(c.cy, 948.137390140625);
  ASSERT_EQ(c.distortion.size(), 4u);
  EXPECT_DOUBLE_EQ(c.distortion[2], 9.5e-06);
  EXPECT_NEAR(glm::length(c.rodrigues() -
                          glm::dvec3(1.6882754799999993, 1.0483220499999997, -0.41955852000000016)),
              0.0, 1e-14);
  EXPECT_DOUBLE_EQ(c.translation.z, 2.8907130499999996);
  EXPECT_FALSE(c.fisheye);
  EXPECT_EQ(rig.cameras[1].width, 640);
  EXPECT_DOUBLE_EQ(rig.cameras[1].fy, 510.0);
  EXPECT_TRUE(rig.cameras[1].distortion.empty());  // all zero: none
  EXPECT_FALSE(rig.floor.has_value());
  // cam_02: identity rotation, 2 m in front: a point at (0.2, -0.1, 0) world is at depth 2.
  const glm::dvec2 p = rig.cameras[1].project({0.2, -0.1, 0.0});
  EXPECT_NEAR(p.x, 500.0 * 0.1 + 320.0, 1e-9);
  EXPECT_NEAR(p.y, 510.0 * -0.05 + 240.0, 1e-9);
}

TEST(RigToml, ReadsAniposeAndCaliscopeVariants) {
  const Rig anipose = parse_rig_toml(kAnipose, "calibration.toml");
  ASSERT_EQ(anipose.cameras.size(), 2u);
  EXPECT_EQ(anipose.cameras[0].name, "A");
  EXPECT_EQ(anipose.cameras[1].name, "B");
  EXPECT_EQ(anipose.cameras[0].width, 1280);
  EXPECT_EQ(anipose.cameras[0].distortion.size(), 5u);
  EXPECT_TRUE(anipose.cameras[1].distortion.empty());
  // A rotation given as a 3x3 matrix (Caliscope's camera_array.toml), tables without a name, and
  // tables Pose2Sim skips too.
  const std::string matrix_rotation = R"([cameras.0]
size = [640, 480]
matrix = [[500.0, 0.0, 320.0], [0.0, 500.0, 240.0], [0.0, 0.0, 1.0]]
distortions = [0.1, -0.05, 0.0, 0.0, 0.01]
translation = [0.1, 0.2, 1.5]
rotation = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]

[charuco]
columns = 4

[capture_volume]
stage = 'origin set'
)";
  const Rig caliscope = parse_rig_toml(matrix_rotation, "camera_array.toml");
  ASSERT_EQ(caliscope.cameras.size(), 1u);
  EXPECT_EQ(caliscope.cameras[0].name, "cameras.0");
  // Row-major in the file: the world's x axis becomes the camera's y.
  const glm::dvec3 x = caliscope.cameras[0].rotation * glm::dvec3(1, 0, 0);
  EXPECT_NEAR(x.y, 1.0, 1e-12);
  EXPECT_NEAR(glm::length(caliscope.cameras[0].rodrigues()), std::acos(-1.0) / 2, 1e-12);
  EXPECT_NE(toml_error("[c]\nsize = [1, 1]\nmatrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, "
                       "1.0]]\ndistortions = []\ntranslation = [0.0, 0.0, 0.0]\nrotation = [[1.0, "
                       "0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]\n")
                .find("[c] rotation: the matrix is a reflection"),
            std::string::npos);
}

TEST(RigToml, FloorIsAMetadataTableTheOthersSkip) {
  const std::string text =
      std::string(kTwoCameras) + "\n[metadata.floor]\nnormal = [0.0, 0.0, 1.0]\noffset = -0.05\n";
  const Rig rig = parse_rig_toml(text, "calib.toml");
  ASSERT_EQ(rig.cameras.size(), 2u);  // [metadata.floor] is not a camera
  ASSERT_TRUE(rig.floor.has_value());
  EXPECT_EQ(rig.floor->normal, glm::dvec3(0, 0, 1));
  EXPECT_DOUBLE_EQ(rig.floor->offset, -0.05);
  // cam_02 (identity rotation, 2 m along z) in its own frame: the floor's normal is the camera's
  // z axis, and the camera is 2.05 m "above" it.
  const auto in_camera = rig.floor_in_camera(1);
  ASSERT_TRUE(in_camera.has_value());
  EXPECT_NEAR(in_camera->offset, rig.floor->height_of(rig.cameras[1].centre()), 1e-12);
  EXPECT_NEAR(in_camera->offset, -2.05, 1e-12);
  const std::string bad =
      std::string(kTwoCameras) + "\n[metadata.floor]\nnormal = [0.0, 0.0, 2.0]\noffset = 0.0\n";
  const std::string e = toml_error(bad);
  EXPECT_NE(e.find("calib.toml:29: [metadata.floor] normal: must be a unit vector"),
            std::string::npos)
      << e;
}

TEST(RigToml, MissingKeyNamesFileLineTableAndKey) {
  std::string text = kTwoCameras;
  const auto at = text.find("rotation = [ 0.0");
  text.erase(at, text.find('\n', at) - at + 1);
  const std::string e = toml_error(text, "my_calib.toml");
  EXPECT_NE(e.find("my_calib.toml:11: [cam_02]: missing key 'rotation'"), std::string::npos) << e;
}

TEST(RigToml, BadValuesNameTheKey) {
  struct Case {
    std::string from, to, expected;
  };
  const Case cases[] = {
      {"translation = [ 0.0, 0.0, 2.0]", "translation = [ 0.0, 2.0]",
       "calib.toml:21: [cam_02] translation: expected 3 numbers, found 2"},
      {"[ 0.0, 0.0, 1.0],\n]", "[ 0.0, 0.0, 2.0],\n]", "[cam_02] matrix: expected [[fx, 0, cx]"},
      {"[ 500.0, 0.0, 320.0]", "[ 500.0, 0.5, 320.0]", "[cam_02] matrix: a skew"},
      {"size = [ 640, 480 ]", "size = [ 640.5, 480 ]", "[cam_02] size: expected two positive"},
      {"distortions = [ 0.0, 0.0, 0.0, 0.0]", "distortions = [ 0.1, 0.0, 0.0]",
       "calib.toml:11: [cam_02]: the camera has 3 distortion coefficients"},
      {"fisheye = false\n\n[metadata]", "fisheye = 0\n\n[metadata]",
       "[cam_02] fisheye: expected true or false"},
      {"name = \"cam_02\"", "name = \"cam_01\"",
       "calib.toml:11: [cam_02]: camera name 'cam_01' is also the camera of line 1"},
      {"rotation = [ 0.0, 0.0, 0.0]", "rotation = [ 0.0, nan, 0.0]", "[cam_02] rotation:"},
  };
  for (const Case& c : cases) {
    std::string text = kTwoCameras;
    const auto at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    const std::string e = toml_error(text);
    EXPECT_NE(e.find(c.expected), std::string::npos) << c.to << "\n -> " << e;
  }
  EXPECT_NE(toml_error(std::string(kTwoCameras) + "[cam_01]\n").find("twice"), std::string::npos);
}

TEST(RigToml, EmptyAndNoCamerasAreErrors) {
  EXPECT_NE(toml_error("").find("no camera table"), std::string::npos);
  EXPECT_NE(toml_error("[metadata]\nadjusted = false\n").find("no camera table"),
            std::string::npos);
  test::TempDir dir;
  test::write_file(dir.file("empty.toml"), "");
  try {
    read_rig(dir.file("empty.toml"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty.toml: empty file"), std::string::npos) << e.what();
  }
  try {
    read_rig(dir.file("absent.toml"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.toml: no such file"), std::string::npos);
  }
}

// Every prefix of a valid file either parses (cut inside [metadata]) or is an InputError naming
// the file; never a crash or another exception.
TEST(RigToml, EveryTruncationIsHandled) {
  const std::string text = kTwoCameras;
  int errors = 0;
  for (std::size_t n = 0; n < text.size(); ++n) {
    try {
      const Rig rig = parse_rig_toml(text.substr(0, n), "cut.toml");
      EXPECT_GE(rig.cameras.size(), 1u);
    } catch (const InputError& e) {
      ++errors;
      EXPECT_NE(std::string(e.what()).find("cut.toml"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(errors, static_cast<int>(text.size() * 3 / 4));
}

TEST(RigToml, RandomBytesAreInputErrors) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    std::string bytes(1 + rng() % 400, '\0');
    for (char& c : bytes) c = static_cast<char>(rng() % 256);
    if (trial % 3 == 0) bytes = "[cam_01]\nname = " + bytes;  // garbage after a valid start
    if (trial % 3 == 1) bytes = "[cam_01]\nmatrix = [[[[[[[[[[[[[[[[[[" + bytes;
    EXPECT_THROW(parse_rig_toml(bytes, "random.toml"), InputError);
  }
}

// A rig of three cameras with every kind of value: distortion of 4, 5, 8 and none, fisheye, a
// pose, the floor.
Rig sample_rig() {
  Rig rig;
  Camera a = Camera::from_fov(1920, 1080, 62.5, "left");
  a.distortion = {-0.21, 0.05, 0.0012, -0.0003, 0.01};
  a.set_rodrigues({0.3, -1.2, 0.05});
  a.translation = {0.12, 1.4, 3.3};
  Camera b = Camera::from_fov(1280, 720, 90.0, "right 2");  // a name with a space
  b.fisheye = true;
  b.distortion = {0.01, -0.002, 0.0003, -0.00004};
  b.set_rodrigues({-2.0, 0.4, 1.1});
  b.translation = {-0.5, 0.25, 4.0};
  Camera c = Camera::from_fov(640, 480, 50.0, "1e5");  // a name that looks like a number
  c.distortion = {0.1, 0.01, 0.0, 0.0, 0.001, 0.002, 0.0003, 0.00004};
  c.set_rodrigues({0.0, 3.1, 0.0});
  c.translation = {1e-7, -3.0, 12.5};
  rig.cameras = {a, b, c};
  rig.floor = GroundPlane{glm::normalize(glm::dvec3(0.01, -0.02, 1.0)), 0.035};
  return rig;
}

TEST(RigFiles, RoundTripsThroughBothFormats) {
  const Rig rig = sample_rig();
  ASSERT_EQ(rig_problem(rig), "");
  test::TempDir dir;
  write_rig(dir.file("rig.toml"), rig);
  write_rig(dir.file("rig.yml"), rig);
  const Rig from_toml = read_rig(dir.file("rig.toml"));
  const Rig from_yaml = read_rig(dir.file("rig.yml"));
  EXPECT_TRUE(rigs_match(from_toml, rig, 1e-12)) << test::read_file(dir.file("rig.toml"));
  EXPECT_TRUE(rigs_match(from_yaml, rig, 1e-12)) << test::read_file(dir.file("rig.yml"));
  // TOML -> YAML -> TOML keeps every number (the rotation up to its Rodrigues round trips).
  write_rig(dir.file("again.yml"), from_toml);
  write_rig(dir.file("again.toml"), read_rig(dir.file("again.yml")));
  EXPECT_TRUE(rigs_match(read_rig(dir.file("again.toml")), from_toml, 1e-12));
  EXPECT_FALSE(std::filesystem::exists(dir.file("rig.toml.part")));
  // What Pose2Sim and anipose look for is there, in their layout; the floor is in [metadata.floor].
  const std::string toml = test::read_file(dir.file("rig.toml"));
  for (const char* key : {"[cam_01]", "[cam_02]", "[cam_03]", "name = \"right 2\"",
                          "size = [ 1920, 1080]", "fisheye = true", "[metadata.floor]"})
    EXPECT_NE(toml.find(key), std::string::npos) << key << "\n" << toml;
  // A rig that cannot be used is not written; an unknown extension is named.
  Rig bad = rig;
  bad.cameras[1].name = "left";
  EXPECT_THROW(write_rig(dir.file("bad.toml"), bad), std::invalid_argument);
  try {
    write_rig(dir.file("rig.txt"), rig);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rig.txt: cannot tell the rig format"), std::string::npos);
  }
}

TEST(RigFiles, Pose2SimsDemoCalibrationConvertsBothWays) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/calibration/Calib_qualisys.toml");
  const auto file = test::shared_data() / "eval/pose2sim_demo/calibration/Calib_qualisys.toml";
  const Rig rig = read_rig(file);
  ASSERT_EQ(rig.cameras.size(), 4u);
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    const Camera& c = rig.cameras[i];
    EXPECT_EQ(c.name, "cam_0" + std::to_string(i + 1));
    EXPECT_EQ(c.width, 1088);
    EXPECT_EQ(c.height, 1920);
    EXPECT_GT(c.fx, 1670);  // README: f = 1673-1682 px
    EXPECT_LT(c.fx, 1685);
    // Every camera is 3-5 m from the world origin, where the person stands, and sees it.
    const double d = glm::length(c.centre());
    EXPECT_GT(d, 2.5);
    EXPECT_LT(d, 6.0);
    EXPECT_GT(c.to_camera({0, 0, 1}).z, 0.0) << "the origin must be in front";
  }
  test::TempDir dir;
  write_rig(dir.file("demo.yml"), rig);
  EXPECT_TRUE(rigs_match(read_rig(dir.file("demo.yml")), rig, 1e-12));
}

// Pose2Sim triangulated its TRC from these very JSON detections with this calibration: each
// marker projects within a few pixels of its keypoint (the README measured a median of about
// 10 px against the raw triangulation). A wrong convention (R transposed) is hundreds off.
TEST(RigFiles, Pose2SimsMarkersReprojectOntoItsDetections) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/S00_P00_T01_BalancingTrial/pose/cam01_json");
  const auto demo = test::shared_data() / "eval/pose2sim_demo";
  const Rig rig = read_rig(demo / "calibration/Calib_qualisys.toml");
  const auto trial = demo / "S00_P00_T01_BalancingTrial";
  std::filesystem::path trc_file;
  for (const auto& entry : std::filesystem::directory_iterator(trial / "pose-3d"))
    if (entry.path().filename().string().ends_with("_filt_butterworth.trc"))
      trc_file = entry.path();
  ASSERT_FALSE(trc_file.empty());
  const io::TrcFile trc = io::read_trc(trc_file);
  // TRC markers and the BODY_25B keypoints of the same name (README).
  const std::vector<std::pair<std::string, int>> markers = {
      {"RShoulder", 6}, {"LShoulder", 5}, {"RElbow", 8}, {"LElbow", 7}, {"RWrist", 10},
      {"LWrist", 9},    {"RHip", 12},     {"LHip", 11},  {"RKnee", 14}, {"LKnee", 13},
      {"RAnkle", 16},   {"LAnkle", 15},   {"Neck", 17},  {"Nose", 0}};
  io::OpenPoseOptions options;
  options.body25 = io::Body25Choice::body25b;
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 1e9 : v[v.size() / 2];
  };
  for (const bool transposed : {false, true}) {
    std::vector<double> per_view_frame;  // the best detection's median distance
    for (std::size_t k = 0; k < rig.cameras.size(); ++k) {
      Camera c = rig.cameras[k];
      if (transposed) c.rotation = glm::transpose(c.rotation);
      const auto json = io::read_openpose_folder(
          trial / "pose" / ("cam0" + std::to_string(k + 1) + "_json"), options);
      for (std::size_t t = 0; t < 100; t += 9) {  // TRC Frame# t + 1 is JSON index t
        double best = 1e9;
        for (const Person2D& person : json.frames.at(t).people) {
          std::vector<double> d;
          for (const auto& [name, keypoint] : markers) {
            const Keypoint2D& kp = person.joints.at(static_cast<std::size_t>(keypoint));
            const glm::vec3 p = trc.frames.at(t).at(trc.marker(name).value());
            if (!(kp.confidence > 0.3)) continue;
            const glm::dvec2 pixel = c.project({p.z, p.x, p.y});  // TRC Y up -> the Z-up world
            d.push_back(glm::length(pixel - glm::dvec2(kp.x, kp.y)));
          }
          if (d.size() >= 6) best = std::min(best, median(d));
        }
        per_view_frame.push_back(best);
      }
    }
    if (transposed) {
      EXPECT_GT(median(per_view_frame), 100.0);
    } else {
      EXPECT_LT(median(per_view_frame), 15.0);
      std::sort(per_view_frame.begin(), per_view_frame.end());
      EXPECT_LT(per_view_frame[per_view_frame.size() * 9 / 10], 30.0);
    }
  }
}

// A YAML rig as OpenCV writes matrices, with a 3x3 rotation and the floor.
const char* kYamlRig = R"(%YAML:1.0
---
cameras:
   - name: front
     image_width: 640
     image_height: 480
     camera_matrix: !!opencv-matrix
        rows: 3
        cols: 3
        dt: d
        data: [ 500., 0., 319.5, 0., 500., 239.5, 0., 0., 1. ]
     distortion_coefficients: !!opencv-matrix
        rows: 1
        cols: 5
        dt: d
        data: [ -0.1, 0.01, 0., 0., 0. ]
     rotation: !!opencv-matrix
        rows: 3
        cols: 3
        dt: d
        data: [ 1., 0., 0., 0., 0., -1., 0., 1., 0. ]
     translation: !!opencv-matrix
        rows: 3
        cols: 1
        dt: d
        data: [ 0., 1.5, 3. ]
   - image_width: 800
     image_height: 600
     camera_matrix: !!opencv-matrix
        rows: 3
        cols: 3
        dt: d
        data: [ 700., 0., 400., 0., 700., 300., 0., 0., 1. ]
     distortion_coefficients: !!opencv-matrix
        rows: 4
        cols: 1
        dt: d
        data: [ 0., 0., 0., 0. ]
ground_normal: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ 0., 0., 1. ]
ground_offset: 0.
)";

TEST(RigYaml, ReadsACameraListWithPosesAndTheFloor) {
  const Rig rig = parse_rig_yaml(kYamlRig, "rig.yml");
  ASSERT_EQ(rig.cameras.size(), 2u);
  EXPECT_EQ(rig.cameras[0].name, "front");
  EXPECT_EQ(rig.cameras[1].name, "cam_02");  // unnamed: by its place in the list
  EXPECT_TRUE(rig.cameras[1].distortion.empty());
  EXPECT_EQ(rig.cameras[1].rotation, glm::dmat3(1.0));  // no pose: at the world origin
  // front: the camera's y axis is the world's -Z (down), its z axis the world's +Y; the centre is
  // 3 m behind the origin along -Y, 1.5 m up.
  const Camera& front = rig.cameras[0];
  EXPECT_NEAR(glm::length(front.centre() - glm::dvec3(0.0, -3.0, 1.5)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(front.optical_axis() - glm::dvec3(0.0, 1.0, 0.0)), 0.0, 1e-12);
  ASSERT_TRUE(rig.floor.has_value());
  EXPECT_NEAR(height_above_m(front, *rig.floor), 1.5, 1e-12);
  EXPECT_NEAR(tilt_below_horizon_deg(front, *rig.floor), 0.0, 1e-9);
  // The floor in front's frame: 1.5 m below it, normal up (-y).
  const auto in_front = rig.floor_in_camera(0);
  EXPECT_NEAR(in_front->offset, 1.5, 1e-12);
  EXPECT_NEAR(glm::length(in_front->normal - glm::dvec3(0, -1, 0)), 0.0, 1e-12);
}

TEST(RigYaml, ErrorsNameTheCameraAndTheKey) {
  struct Case {
    std::string from, to, expected;
  };
  const Case cases[] = {
      {"image_width: 800", "image_width: -800",
       "rig.yml: cameras[1] (cam_02): key 'image_width' must be positive"},
      {"     image_width: 640\n", "", "rig.yml: cameras[0] (front): missing key 'image_width'"},
      {"data: [ 0., 1.5, 3. ]", "data: [ 0., 1.5 ]",
       "cameras[0] (front): key 'translation' has a shape (3x1)"},
      {"data: [ 1., 0., 0., 0., 0., -1., 0., 1., 0. ]",
       "data: [ 1., 0., 0., 0., 0., -1., 0., 2., 0. ]",
       "cameras[0] (front): key 'rotation' (a 3x3 matrix) is not orthonormal"},
      {"   - image_width: 800", "   - name: front\n     image_width: 800",
       "cameras[1] (front): a second camera named 'front'"},
      {"ground_offset: 0.", "ground_offset: .Inf", "rig.yml: key 'ground_offset' is not finite"},
      {"cameras:", "cameras: 3\nold:", "rig.yml: key 'cameras' must be a list"},
  };
  for (const Case& c : cases) {
    std::string text = kYamlRig;
    const auto at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    const std::string e = yaml_error(text);
    EXPECT_NE(e.find(c.expected), std::string::npos) << c.to << "\n -> " << e;
  }
  // Every truncation of the file is an error naming it or a smaller rig; never a crash.
  const std::string text = kYamlRig;
  for (std::size_t n = 0; n < text.size(); n += 5) {
    try {
      parse_rig_yaml(text.substr(0, n), "cut.yml");
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cut.yml"), std::string::npos) << e.what();
    }
  }
}

TEST(RigFiles, TheSingleCameraFileIsAOneCameraRig) {
  test::TempDir dir;
  const Camera lens = [] {
    Camera c = Camera::from_fov(1280, 720, 75.0);
    c.distortion = {-0.2, 0.04, 0.0, 0.0, 0.0};
    return c;
  }();
  const GroundPlane plane{glm::normalize(glm::dvec3(0.0, -0.9, -0.3)), 1.7};
  write_camera_file(dir.file("cam.yml"), lens, 0.3, plane);
  const Rig rig = read_rig(dir.file("cam.yml"));
  ASSERT_EQ(rig.cameras.size(), 1u);
  EXPECT_EQ(rig.cameras[0], lens);
  ASSERT_TRUE(rig.floor.has_value());
  EXPECT_NEAR(glm::length(rig.floor->normal - plane.normal), 0.0, 1e-15);
  // Converted to TOML and back, then the floor seen from the camera is the file's ground plane.
  write_rig(dir.file("cam.toml"), rig);
  EXPECT_EQ(read_camera_file(dir.file("cam.toml")), lens);
  const auto again = read_ground_plane(dir.file("cam.toml"));
  ASSERT_TRUE(again.has_value());
  EXPECT_NEAR(again->offset, 1.7, 1e-12);
  // A rig of several cameras is not a single camera.
  write_rig(dir.file("two.toml"), sample_rig());
  try {
    read_camera_file(dir.file("two.toml"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("two.toml: is a rig of 3 cameras"), std::string::npos)
        << e.what();
  }
  // The floor of a posed one-camera rig goes into its world when written from the camera's
  // frame, and comes back the same.
  Rig posed;
  posed.cameras = {sample_rig().cameras[0]};
  write_rig(dir.file("posed.toml"), posed);
  write_ground_plane(dir.file("posed.toml"), plane);
  const auto seen = read_ground_plane(dir.file("posed.toml"));
  ASSERT_TRUE(seen.has_value());
  EXPECT_NEAR(seen->offset, plane.offset, 1e-12);
  EXPECT_NEAR(glm::length(seen->normal - plane.normal), 0.0, 1e-12);
}

TEST(RigReport, SaysCamerasPositionsBaselinesAnglesAndFloor) {
  const std::string report = rig_report(sample_rig());
  for (const char* text : {"3 cameras", "left", "right 2", "1920x1080", "fisheye k1 0.010000",
                           "k6 0.000040", "baselines", "angles between optical axes",
                           "floor: dot(normal, x) + offset = 0", "height (m)"})
    EXPECT_NE(report.find(text), std::string::npos) << text << "\n" << report;
  // The baseline between left and right 2 is in the table.
  const Rig rig = sample_rig();
  char baseline[32];
  std::snprintf(baseline, sizeof baseline, "%.3f", baseline_m(rig.cameras[0], rig.cameras[1]));
  EXPECT_NE(report.find(baseline), std::string::npos) << baseline << "\n" << report;
  // anipose's millimetres are pointed out.
  Rig mm = rig;
  for (Camera& c : mm.cameras) c.translation *= 1000.0;
  EXPECT_NE(rig_report(mm).find("millimetres"), std::string::npos);
  EXPECT_EQ(rig_report(rig).find("millimetres"), std::string::npos);
}

}  // namespace
}  // namespace mocap::camera
