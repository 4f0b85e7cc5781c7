// The database builder's position-only entry point (build_database_from_bodies).

#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

#include "core/input_error.hpp"
#include "posedb/builder.hpp"
#include "posedb/database.hpp"
#include "posedb/exact_search.hpp"
#include "support/shared_data.hpp"

namespace mocap::posedb {
namespace {

using Body = std::array<glm::vec3, kBodyJoints>;

// A standing body facing +Z with its left on +X, root 0.95 m above the floor.
Body standing() {
  Body b;
  b[index(Joint::head)] = {0.0f, 1.70f, 0.0f};
  b[index(Joint::neck)] = {0.0f, 1.50f, 0.0f};
  b[index(Joint::right_shoulder)] = {-0.20f, 1.45f, 0.0f};
  b[index(Joint::right_elbow)] = {-0.25f, 1.18f, 0.0f};
  b[index(Joint::right_wrist)] = {-0.27f, 0.93f, 0.05f};
  b[index(Joint::left_shoulder)] = {0.20f, 1.45f, 0.0f};
  b[index(Joint::left_elbow)] = {0.25f, 1.18f, 0.0f};
  b[index(Joint::left_wrist)] = {0.27f, 0.93f, 0.05f};
  b[index(Joint::right_hip)] = {-0.10f, 0.95f, 0.0f};
  b[index(Joint::right_knee)] = {-0.10f, 0.52f, 0.03f};
  b[index(Joint::right_ankle)] = {-0.10f, 0.10f, 0.0f};
  b[index(Joint::left_hip)] = {0.10f, 0.95f, 0.0f};
  b[index(Joint::left_knee)] = {0.10f, 0.52f, 0.03f};
  b[index(Joint::left_ankle)] = {0.10f, 0.10f, 0.0f};
  b[index(Joint::root)] = {0.0f, 0.95f, 0.0f};
  return b;
}

constexpr double kSourceFps = 60.0;
constexpr float kTurnRate = 0.5f;  // rad/s

// The body swinging its arms while it walks along a circle, turning with it.
BodySequence circling(int frames, float extra_yaw = 0.0f, glm::vec3 offset = glm::vec3(0.0f)) {
  BodySequence s;
  s.name = "synthetic circle";
  s.source = "test";
  s.family = "synthetic";
  s.mapping = "Body15 as given";
  s.fps = kSourceFps;
  for (int f = 0; f < frames; ++f) {
    const float t = static_cast<float>(f / kSourceFps);
    Body b = standing();
    const float swing = 0.2f * std::sin(4.0f * t);
    b[index(Joint::left_wrist)].z += swing;
    b[index(Joint::right_wrist)].z -= swing;
    const float heading = kTurnRate * t + extra_yaw;
    const glm::quat turn = glm::angleAxis(heading, glm::vec3(0, 1, 0));
    const glm::vec3 place = turn * glm::vec3(3.0f, 0.0f, 0.0f) + offset;
    for (auto& p : b) p = turn * p + place;
    s.frames.push_back(b);
  }
  return s;
}

BuildOptions small_options() {
  BuildOptions options;
  options.views.yaw_steps = 6;
  options.views.heights_m = {1.5f, 2.5f};
  options.clusters = 4;
  options.threads = 1;
  return options;
}

float wrapped(float angle) { return std::atan2(std::sin(angle), std::cos(angle)); }

TEST(BodyBuilder, ResamplesFacesAndKeepsNoRotations) {
  BuildReport report;
  const DatabaseContents db =
      build_database_from_bodies({circling(120)}, small_options(), {}, report);
  EXPECT_TRUE(report.skipped.empty());
  ASSERT_EQ(db.clips.size(), 1u);
  EXPECT_EQ(db.clips[0].frame_count, 48u);  // 2 s at 60 Hz -> frames 0, 2.5, ..., 117.5 at 24 fps
  EXPECT_EQ(db.clips[0].family, "synthetic");
  EXPECT_EQ(db.clips[0].skeleton.joint_count(), 0);
  EXPECT_TRUE(db.rotations.empty());
  EXPECT_EQ(db.projection_records.size(), 48u * 12u);
  for (std::size_t f = 0; f < db.frames.size(); ++f) {
    const float t = static_cast<float>(f) / 24.0f;
    EXPECT_NEAR(wrapped(db.frames[f].heading_rad - kTurnRate * t), 0.0f, 1e-4f) << f;
    const float* j = &db.joints[f * kBodyJoints * 3];
    EXPECT_NEAR(j[3 * index(Joint::root)], 0.0f, 1e-6f);
    EXPECT_NEAR(j[3 * index(Joint::left_hip)], 0.10f, 1e-4f);  // faces +Z, left on +X
    EXPECT_NEAR(j[3 * index(Joint::head) + 1], 0.75f, 1e-4f);
  }
}

TEST(BodyBuilder, JointsDoNotDependOnWhereTheBodyStandsOrFaces) {
  BuildReport a, b;
  const DatabaseContents plain = build_database_from_bodies({circling(90)}, small_options(), {}, a);
  const DatabaseContents moved = build_database_from_bodies(
      {circling(90, 2.0f, glm::vec3(5.0f, 0.0f, -7.0f))}, small_options(), {}, b);
  ASSERT_EQ(plain.joints.size(), moved.joints.size());
  for (std::size_t i = 0; i < plain.joints.size(); ++i)
    EXPECT_NEAR(plain.joints[i], moved.joints[i], 1e-4f) << i;
}

TEST(BodyBuilder, OpensAndEveryProjectionFindsItself) {
  test::TempDir dir;
  BuildReport report;
  write_database(build_database_from_bodies({circling(150)}, small_options(), {}, report),
                 dir.file("bodies.mdb"));
  const Database db = Database::open(dir.file("bodies.mdb"));
  ASSERT_EQ(db.clips().size(), 1u);
  EXPECT_EQ(db.clips()[0].skeleton.joint_count(), 0);
  EXPECT_EQ(db.rotations(0).size(), 0u);
  EXPECT_EQ(db.views().size(), 12u);
  const ExactSearch exact(db.projections());
  std::vector<Neighbor> found;
  for (std::size_t i = 0; i < db.projections().rows; i += 7) {
    exact.search(db.projections().row(i), nullptr, 1, found);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].distance, 0.0f);
  }
}

TEST(BodyBuilder, UnusableSequencesAreSkippedAndReported) {
  BodySequence broken = circling(30);
  broken.name = "broken";
  broken.frames[10][3].y = std::numeric_limits<float>::quiet_NaN();
  BodySequence empty;
  empty.name = "empty";
  empty.fps = 60.0;
  BuildReport report;
  const DatabaseContents db =
      build_database_from_bodies({broken, empty, circling(30)}, small_options(), {}, report);
  EXPECT_EQ(db.clips.size(), 1u);
  ASSERT_EQ(report.skipped.size(), 2u);
  EXPECT_EQ(report.skipped[0], "broken: non-finite joint position in frame 10");
  EXPECT_EQ(report.skipped[1], "empty: no frames");
  BuildReport none;
  EXPECT_THROW(build_database_from_bodies({broken}, small_options(), {}, none), InputError);
}

}  // namespace
}  // namespace mocap::posedb
