// camera::Camera against OpenCV's own functions (projectPoints, undistortPoints, Rodrigues,
// cv::fisheye) on real calibrations: Pose2Sim's demo rig, OpenCV's sample calibration (a strongly
// distorted lens) and HumanEva's cameras.

#include "camera/camera.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/matrix.hpp>
#include <opencv2/calib3d.hpp>

#include "camera/rig_file.hpp"
#include "io/humaneva.hpp"
#include "support/shared_data.hpp"

namespace mocap::camera {
namespace {

// OpenCV's sample calibration (samples/data/left*.jpg, 640x480): k1 = -0.27 moves the corners by
// tens of pixels.
Camera opencv_sample() {
  Camera c;
  c.name = "left";
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 5.3591573396163199e+02;
  c.cx = 3.4228315473308373e+02;
  c.cy = 2.3557082909788173e+02;
  c.distortion = {-2.6637260909660682e-01, -3.8588898922304653e-02, 1.7831947042852964e-03,
                  -2.8122100441115472e-04, 2.3839153080878486e-01};
  return c;
}

cv::Matx33d K_of(const Camera& c) { return {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1}; }

// Points in front of `c` spread over its image (and a little beyond), depth 1-6 m.
std::vector<glm::dvec3> points_in_view(const Camera& c, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.1, 1.1), depth(1.0, 6.0);
  std::vector<glm::dvec3> out;
  for (int i = 0; i < count; ++i) {
    const double z = depth(rng);
    const glm::dvec3 in_camera((u(rng) * c.width - c.cx) / c.fx * z,
                               (u(rng) * c.height - c.cy) / c.fy * z, z);
    out.push_back(c.to_world(in_camera));
  }
  return out;
}

std::vector<cv::Point3d> cv_points(const std::vector<glm::dvec3>& points) {
  std::vector<cv::Point3d> out;
  for (const glm::dvec3& p : points) out.emplace_back(p.x, p.y, p.z);
  return out;
}

// Projection through OpenCV with the pose given as OpenCV takes it: the Rodrigues vector and the
// translation, world -> camera.
std::vector<cv::Point2d> opencv_project(const Camera& c, const std::vector<glm::dvec3>& world,
                                        const cv::Vec3d& rvec) {
  std::vector<cv::Point2d> out;
  const cv::Vec3d tvec(c.translation.x, c.translation.y, c.translation.z);
  cv::projectPoints(cv_points(world), rvec, tvec, K_of(c), c.distortion, out);
  return out;
}

TEST(Camera, ProjectsAsOpenCvOnPose2SimsRig) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/calibration/Calib_qualisys.toml");
  const auto file = test::shared_data() / "eval/pose2sim_demo/calibration/Calib_qualisys.toml";
  // The file's own Rodrigues vectors, read by a line scan, go to OpenCV untouched: our reading of
  // them (rotation_from_rodrigues) is checked too.
  std::vector<cv::Vec3d> rotations;
  std::istringstream text(read_rig_text(file));
  for (std::string line; std::getline(text, line);) {
    cv::Vec3d r;
    if (std::sscanf(line.c_str(), "rotation = [ %lf, %lf, %lf]", &r[0], &r[1], &r[2]) == 3)
      rotations.push_back(r);
  }
  const Rig rig = read_rig(file);
  ASSERT_EQ(rig.cameras.size(), 4u);
  ASSERT_EQ(rotations.size(), 4u);
  for (std::size_t k = 0; k < rig.cameras.size(); ++k) {
    const Camera& c = rig.cameras[k];
    ASSERT_TRUE(c.has_distortion()) << c.name;
    const std::vector<glm::dvec3> world = points_in_view(c, 200, 1);
    const auto expected = opencv_project(c, world, rotations[k]);
    for (std::size_t i = 0; i < world.size(); ++i) {
      const glm::dvec2 p = c.project(world[i]);
      EXPECT_NEAR(p.x, expected[i].x, 1e-6) << c.name;
      EXPECT_NEAR(p.y, expected[i].y, 1e-6) << c.name;
    }
  }
}

TEST(Camera, RodriguesAgreesWithOpenCv) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<cv::Vec3d> vectors = {
      {0, 0, 0}, {1e-9, 0, 0}, {0, 0, std::numbers::pi}, {0, std::numbers::pi - 1e-7, 0}};
  for (int i = 0; i < 50; ++i) vectors.push_back(cv::Vec3d(u(rng), u(rng), u(rng)) * 3.0);
  for (const cv::Vec3d& v : vectors) {
    cv::Matx33d R;
    cv::Rodrigues(v, R);
    const glm::dmat3 ours = rotation_from_rodrigues({v[0], v[1], v[2]});
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) EXPECT_NEAR(ours[col][row], R(row, col), 1e-12);
    // Back: the same rotation (the vector itself may flip at pi).
    const glm::dmat3 again = rotation_from_rodrigues(rodrigues_from_rotation(ours));
    for (int col = 0; col < 3; ++col)
      for (int row = 0; row < 3; ++row) EXPECT_NEAR(again[col][row], ours[col][row], 1e-9);
    if (cv::norm(v) < std::numbers::pi - 1e-3) {
      const glm::dvec3 r = rodrigues_from_rotation(ours);
      EXPECT_NEAR(glm::length(r - glm::dvec3(v[0], v[1], v[2])), 0.0, 1e-9);
    }
  }
}

TEST(Camera, DistortsAndUndistortsAsOpenCvOnAStrongLens) {
  Camera c = opencv_sample();
  c.set_rodrigues({0.1, -0.4, 0.05});
  c.translation = {0.2, -0.1, 1.5};
  const std::vector<glm::dvec3> world = points_in_view(c, 300, 2);
  const glm::dvec3 r = c.rodrigues();
  const auto expected = opencv_project(c, world, {r.x, r.y, r.z});
  double moved = 0;
  for (std::size_t i = 0; i < world.size(); ++i) {
    const glm::dvec2 distorted = c.project(world[i]);
    EXPECT_NEAR(distorted.x, expected[i].x, 1e-6);
    EXPECT_NEAR(distorted.y, expected[i].y, 1e-6);
    // Undistorting the pixel gives the pinhole projection of the same point.
    const glm::dvec2 ideal = c.project_pinhole(world[i]);
    moved = std::max(moved, glm::length(distorted - ideal));
    const glm::dvec2 back = c.undistort_pixel(distorted);
    EXPECT_NEAR(back.x, ideal.x, 1e-4) << "point " << i;
    EXPECT_NEAR(back.y, ideal.y, 1e-4) << "point " << i;
    const glm::dvec2 forth = c.distort_pixel(ideal);
    EXPECT_NEAR(forth.x, distorted.x, 1e-6);
    EXPECT_NEAR(forth.y, distorted.y, 1e-6);
  }
  EXPECT_GT(moved, 20.0);  // the lens really moves the points
  // A wider lens (77 px of distortion in the corners): OpenCV's undistortPoints with its default
  // five steps stops a fifth of a pixel short in the corner, ours does not.
  Camera wide = c;
  wide.distortion = {-0.4, 0.2, 0.0, 0.0, -0.05};
  const glm::dvec2 corner = wide.distort_pixel({0.0, 0.0});
  ASSERT_GT(glm::length(corner), 40.0);
  std::vector<cv::Point2d> five;
  cv::undistortPoints(std::vector<cv::Point2d>{{corner.x, corner.y}}, five, K_of(wide),
                      wide.distortion, cv::noArray(), K_of(wide));
  EXPECT_NEAR(glm::length(wide.undistort_pixel(corner)), 0.0, 1e-4);
  EXPECT_GT(cv::norm(five[0]), 0.1);
}

TEST(Camera, UndistortsManyPixelsInPlaceAndLeavesMissingOnes) {
  const Camera c = opencv_sample();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<std::array<float, 2>> pixels = {{100.5f, 50.25f}, {nan, nan}, {600.0f, 420.0f}};
  c.undistort_pixels(pixels);
  for (std::size_t i : {0u, 2u}) {
    const glm::dvec2 one = c.undistort_pixel({i == 0 ? 100.5 : 600.0, i == 0 ? 50.25 : 420.0});
    EXPECT_NEAR(pixels[i][0], one.x, 1e-3);
    EXPECT_NEAR(pixels[i][1], one.y, 1e-3);
  }
  EXPECT_TRUE(std::isnan(pixels[1][0]));
  // No distortion: nothing moves.
  const Camera ideal = Camera::from_fov(640, 480, 60.0);
  std::vector<std::array<float, 2>> same = {{100.5f, 200.25f}};
  ideal.undistort_pixels(same);
  EXPECT_EQ(same[0][0], 100.5f);
  EXPECT_EQ(ideal.undistort_pixel({3.5, 4.5}), glm::dvec2(3.5, 4.5));
}

TEST(Camera, FisheyeAsOpenCvFisheye) {
  Camera c = opencv_sample();
  c.fisheye = true;
  c.distortion = {-0.02, 0.004, -0.001, 0.0002};
  c.set_rodrigues({0.2, 0.1, -0.3});
  c.translation = {0.1, 0.3, 2.0};
  const std::vector<glm::dvec3> world = points_in_view(c, 100, 4);
  std::vector<cv::Point2d> expected;
  const glm::dvec3 r = c.rodrigues();
  cv::fisheye::projectPoints(
      cv::Mat(cv_points(world)).reshape(3, 1), expected, cv::Vec3d(r.x, r.y, r.z),
      cv::Vec3d(c.translation.x, c.translation.y, c.translation.z), K_of(c), c.distortion);
  for (std::size_t i = 0; i < world.size(); ++i) {
    const glm::dvec2 p = c.project(world[i]);
    EXPECT_NEAR(p.x, expected[i].x, 1e-6);
    EXPECT_NEAR(p.y, expected[i].y, 1e-6);
    const glm::dvec2 back = c.undistort_pixel(p);
    const glm::dvec2 ideal = c.project_pinhole(world[i]);
    EXPECT_NEAR(back.x, ideal.x, 1e-3);
    EXPECT_NEAR(back.y, ideal.y, 1e-3);
  }
}

TEST(Camera, HumanEvaCamerasProjectAsOpenCvAndAsVideoPose3D) {
  MOCAP_REQUIRE_SHARED("eval/humaneva_i_videopose3d/humaneva_cameras.json");
  const auto rigs = io::humaneva::load_cameras(test::shared_data() / "eval/humaneva_i_videopose3d" /
                                               io::humaneva::kCamerasFile);
  ASSERT_EQ(rigs.size(), 3u);
  for (const auto& [subject, rig] : rigs) {
    ASSERT_EQ(rig.cameras.size(), 3u);
    ASSERT_TRUE(rig.floor.has_value());
    for (const Camera& c : rig.cameras) {
      EXPECT_EQ(rotation_problem(c.rotation), "") << subject << " " << c.name;
      cv::Vec3d rvec;
      cv::Rodrigues(cv::Matx33d(c.rotation[0][0], c.rotation[1][0], c.rotation[2][0],
                                c.rotation[0][1], c.rotation[1][1], c.rotation[2][1],
                                c.rotation[0][2], c.rotation[1][2], c.rotation[2][2]),
                    rvec);
      const std::vector<glm::dvec3> world = points_in_view(c, 50, 5);
      const auto expected = opencv_project(c, world, rvec);
      // VideoPose3D's convention: X_cam = R(q)ᵀ (X − centre), q rotating camera -> world.
      const glm::dquat q = glm::quat_cast(glm::transpose(c.rotation));
      const glm::dvec3 centre = c.centre();
      for (std::size_t i = 0; i < world.size(); ++i) {
        const glm::dvec2 p = c.project(world[i]);
        EXPECT_NEAR(p.x, expected[i].x, 1e-6);
        EXPECT_NEAR(p.y, expected[i].y, 1e-6);
        const glm::dvec3 v = glm::inverse(q) * (world[i] - centre);
        EXPECT_NEAR(p.x, c.fx * v.x / v.z + c.cx, 1e-6);
      }
      // The cameras stand 3-6 m from the capture area, above the floor (Z = 0, Z up).
      EXPECT_GT(glm::length(glm::dvec2(centre)), 2.0) << c.name;
      EXPECT_GT(rig.floor->height_of(centre), 0.5) << c.name;
    }
  }
}

TEST(Camera, PoseConventions) {
  Camera c = Camera::from_fov(1280, 720, 70.0);
  EXPECT_EQ(c.name, "cam_01");
  EXPECT_DOUBLE_EQ(c.cx, 640.0);  // the monocular pipeline's assumption: w/2, h/2
  EXPECT_DOUBLE_EQ(c.cy, 360.0);
  EXPECT_NEAR(c.fx, 640.0 / std::tan(35.0 * std::numbers::pi / 180.0), 1e-9);
  EXPECT_FALSE(c.has_distortion());
  // A camera 2 m behind the origin on -Y of a Z-up world, level, looking along +Y.
  const glm::dmat3 camera_to_world(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
  c.set_pose_from_centre(camera_to_world, {0.0, -2.0, 1.5});
  EXPECT_NEAR(glm::length(c.centre() - glm::dvec3(0.0, -2.0, 1.5)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(c.optical_axis() - glm::dvec3(0, 1, 0)), 0.0, 1e-12);
  // The origin is 2 m ahead, 1.5 m below the centre: in the lower half of the image.
  const glm::dvec2 p = c.project({0.0, 0.0, 0.0});
  EXPECT_NEAR(p.x, c.cx, 1e-9);
  EXPECT_NEAR(p.y, c.cy + c.fy * 1.5 / 2.0, 1e-9);
  const glm::dvec3 x(0.3, 1.0, 0.2);
  EXPECT_NEAR(glm::length(c.to_world(c.to_camera(x)) - x), 0.0, 1e-12);
  // The ray through a point's pixel passes through the point.
  const glm::dvec3 ray = c.ray(c.project(x));
  EXPECT_NEAR(glm::length(glm::cross(ray, glm::normalize(x - c.centre()))), 0.0, 1e-9);
  // Behind the camera: no pixel.
  EXPECT_TRUE(std::isnan(c.project({0.0, -3.0, 1.5}).x));
  EXPECT_THROW(Camera::from_fov(0, 480, 60.0), std::invalid_argument);
  EXPECT_THROW(Camera::from_fov(640, 480, 180.0), std::invalid_argument);
}

TEST(Camera, ProblemsAreNamed) {
  Camera c = Camera::from_fov(640, 480, 60.0);
  EXPECT_EQ(camera_problem(c), "");
  Camera bad = c;
  bad.name = "";
  EXPECT_NE(camera_problem(bad).find("name"), std::string::npos);
  bad = c;
  bad.fx = 0;
  EXPECT_NE(camera_problem(bad).find("focal"), std::string::npos);
  bad = c;
  bad.distortion = {0.1, 0.2, 0.3};
  EXPECT_NE(camera_problem(bad).find("3 distortion coefficients"), std::string::npos);
  bad = c;
  bad.rotation[0][0] = -1.0;  // a reflection
  EXPECT_NE(camera_problem(bad).find("rotation"), std::string::npos);
  bad = c;
  bad.rotation[1][0] = 0.5;
  EXPECT_NE(camera_problem(bad).find("not orthonormal"), std::string::npos);
}

}  // namespace
}  // namespace mocap::camera
