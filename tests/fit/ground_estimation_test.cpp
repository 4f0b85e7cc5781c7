// The floor from people's feet (fit/ground_estimation) on a real walk (CMU 07_01) seen by a static,
// tilted camera: the upright cue alone along one line, the contact plane once the feet cover an
// area, and no estimate from too little.

#include "fit/ground_estimation.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "fit/fit_evaluation.hpp"
#include "fit/fit_fixture.hpp"

namespace mocap {
namespace {

constexpr double kClearance = 0.07;

// A static camera at `centre` (world, y up, metres) looking at `target`.
struct StaticCamera {
  glm::dmat3 camera_from_world;  // rows: right, down, forward
  glm::dvec3 centre;
  glm::dvec3 to_camera(const glm::dvec3& world) const {
    return camera_from_world * (world - centre);
  }
};

StaticCamera look_at(const glm::dvec3& centre, const glm::dvec3& target) {
  const glm::dvec3 forward = glm::normalize(target - centre);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  const glm::dvec3 down = glm::cross(forward, right);
  return {glm::transpose(glm::dmat3(right, down, forward)), centre};
}

// The clip's bodies in the camera frame, turned by `yaw_rad` and shifted by `shift` in the world.
void add_walk(fit::GroundEstimator& estimator, const StaticCamera& camera, double yaw_rad,
              const glm::dvec3& shift) {
  const auto& world = test::fit_clip_world();
  const auto contacts = fit::truth_contacts(world, test::kFitFps);
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  for (std::size_t t = 0; t < world.size(); ++t) {
    fit::Body body;
    for (int j = 0; j < kBodyJoints; ++j) {
      const glm::dvec3 p(world[t][static_cast<std::size_t>(j)]);
      const glm::dvec3 turned(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);
      body[static_cast<std::size_t>(j)] = glm::vec3(camera.to_camera(turned + shift));
    }
    estimator.add(body, contacts[t]);
  }
}

// The walk's floor: contact ankles sit `clearance` above it (their median height).
double floor_height() {
  const auto& world = test::fit_clip_world();
  const auto contacts = fit::truth_contacts(world, test::kFitFps);
  std::vector<double> heights;
  for (std::size_t t = 0; t < world.size(); ++t) {
    for (std::size_t f = 0; f < 2; ++f)
      if (contacts[t][f]) heights.push_back(world[t][static_cast<std::size_t>(fit::kFeet[f])].y);
  }
  std::nth_element(heights.begin(),
                   heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2),
                   heights.end());
  return heights[heights.size() / 2] - kClearance;
}

glm::dvec3 walk_centre() {
  glm::dvec3 sum(0.0);
  const auto& world = test::fit_clip_world();
  for (const auto& body : world) sum += glm::dvec3(body[index(Joint::root)]);
  return sum / static_cast<double>(world.size());
}

// The median error of the heights over the estimated floor of the walk's ankles (in contact or
// not) against their true heights: the plane where the people are. (The camera's own height
// over the plane moves by its distance times the normal's error: 6 m x 1 degree = 10 cm.)
double median_height_error_m(const GroundPlane& plane, const StaticCamera& camera) {
  std::vector<double> errors;
  for (const auto& body : test::fit_clip_world()) {
    for (int a : fit::kFeet) {
      const glm::dvec3 ankle(body[static_cast<std::size_t>(a)]);
      const double estimated = glm::dot(plane.normal, camera.to_camera(ankle)) + plane.offset;
      errors.push_back(std::abs(estimated - (ankle.y - floor_height())));
    }
  }
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2),
                   errors.end());
  return errors[errors.size() / 2];
}

double angle_deg(const glm::dvec3& a, const glm::dvec3& b) {
  return glm::degrees(
      std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)));
}

TEST(GroundEstimation, ContactFeetAndHipLinesGiveTheFloorOfAWalkAlongALine) {
  MOCAP_REQUIRE_FIT_CLIP();
  const glm::dvec3 centre = walk_centre();
  // 1.8 m high, 6 m to the side of the walk, looking 25 degrees down at it.
  const glm::dvec3 eye = centre + glm::dvec3(6.0, 0.0, 0.0);
  const StaticCamera camera =
      look_at({eye.x, 1.8, eye.z}, {centre.x, 1.8 - 6.0 * std::tan(glm::radians(25.0)), centre.z});
  fit::GroundEstimator estimator({kClearance});
  add_walk(estimator, camera, 0.0, {});
  const auto estimate = estimator.estimate();
  ASSERT_TRUE(estimate);
  const glm::dvec3 up_in_camera = camera.camera_from_world * glm::dvec3(0, 1, 0);
  EXPECT_LT(angle_deg(estimate->plane.normal, up_in_camera), 3.0);
  EXPECT_LT(median_height_error_m(estimate->plane, camera), 0.02);
  EXPECT_NEAR(estimate->plane.offset, 1.8 - floor_height(), 0.2);  // the camera's height
  EXPECT_TRUE(estimate->normal_from_contacts);  // the strides and the hip lines span the floor
}

TEST(GroundEstimation, TwoCrossingWalksSeenFromAboveGiveTheFloor) {
  MOCAP_REQUIRE_FIT_CLIP();
  const glm::dvec3 centre = walk_centre();
  const StaticCamera camera = look_at({centre.x + 3.0, 2.5, centre.z + 7.0}, centre);
  fit::GroundEstimator estimator({kClearance});
  add_walk(estimator, camera, 0.0, {});
  // The same walk turned by 90 degrees about the centre, crossing the first one.
  const double c = 0.0, s = 1.0;
  const glm::dvec3 turned_centre(c * centre.x + s * centre.z, 0.0, -s * centre.x + c * centre.z);
  add_walk(estimator, camera, M_PI / 2, glm::dvec3(centre.x, 0.0, centre.z) - turned_centre);
  const auto estimate = estimator.estimate();
  ASSERT_TRUE(estimate);
  EXPECT_TRUE(estimate->normal_from_contacts);
  const glm::dvec3 up_in_camera = camera.camera_from_world * glm::dvec3(0, 1, 0);
  EXPECT_LT(angle_deg(estimate->plane.normal, up_in_camera), 1.5);
  EXPECT_LT(median_height_error_m(estimate->plane, camera), 0.02);
  EXPECT_NEAR(estimate->plane.offset, 2.5 - floor_height(), 0.25);
}

TEST(GroundEstimation, NoEstimateFromTooFewBodiesOrWithoutContacts) {
  MOCAP_REQUIRE_FIT_CLIP();
  const auto& world = test::fit_clip_world();
  fit::GroundEstimator few({kClearance});
  for (std::size_t t = 0; t < 5; ++t) few.add(world[t], {true, true});
  EXPECT_FALSE(few.estimate());
  fit::GroundEstimator airborne({kClearance});
  for (const auto& body : world) airborne.add(body, {false, false});
  EXPECT_FALSE(airborne.estimate());
  EXPECT_EQ(airborne.contacts(), 0u);
  fit::Body broken{};  // every joint at the origin: no trunk, ignored
  airborne.add(broken, {true, true});
  EXPECT_EQ(airborne.bodies(), world.size());
}

}  // namespace
}  // namespace mocap
