// Database poses as BVH channel values: read back through the motion code they give the
// database's own body joints, turned by the view; and the per-person file writer's policies.

#include "recon/bvh_frame.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "motion/body_mapping.hpp"
#include "motion/bvh.hpp"
#include "recon/people_bvh_writer.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::recon {
namespace {

// The body (metres, 15 joints) that the channel values describe, as the motion code reads them.
std::array<glm::vec3, kBodyJoints> body_of(const motion::Skeleton& skeleton,
                                           const std::vector<float>& values) {
  motion::Clip clip;
  clip.skeleton = skeleton;
  clip.frame_count = 1;
  clip.values = values;
  const motion::PoseSequence poses = motion::to_poses(clip);
  motion::GlobalPose global;
  motion::forward_kinematics(poses, 0, global);
  std::array<glm::vec3, kBodyJoints> body;
  motion::body_positions(motion::map_to_body(skeleton, "test"), global, body);
  return body;
}

// The database's body joints of `frame` as seen from view `view`'s camera standing on +Z.
std::array<glm::vec3, kBodyJoints> expected_body(const posedb::Database& db, DatabasePose pose) {
  const auto joints = db.joints(pose.frame);
  const glm::quat turn =
      glm::angleAxis(-glm::radians(db.views()[pose.view].yaw_deg), glm::vec3(0, 1, 0));
  std::array<glm::vec3, kBodyJoints> body;
  for (int j = 0; j < kBodyJoints; ++j)
    body[j] = turn * glm::vec3(joints[3 * j], joints[3 * j + 1], joints[3 * j + 2]);
  return body;
}

// Worst joint distance (metres) over every frame of clip `clip` through several views.
float worst_error_over_clip(const posedb::Database& db, std::uint32_t clip) {
  const posedb::ClipInfo& info = db.clips()[clip];
  BvhFrameMaker maker(info.skeleton, info.source);
  std::vector<float> values;
  float worst = 0.0f;
  for (std::uint32_t f = info.first_frame; f < info.first_frame + info.frame_count; ++f) {
    for (std::uint32_t v = 0; v < db.views().size(); v += 5) {
      maker.channels(db, {f, v}, values);
      EXPECT_EQ(values.size(), static_cast<size_t>(info.skeleton.channel_count));
      const auto got = body_of(maker.skeleton(), values);
      const auto want = expected_body(db, {f, v});
      const glm::vec3 root = got[index(Joint::root)];
      // The body root stands at the source height above the origin.
      EXPECT_NEAR(root.y, db.frames()[f].root_m[1], 1e-3f) << "frame " << f;
      EXPECT_NEAR(glm::length(glm::vec2(root.x, root.z)), 0.0f, 1e-3f) << "frame " << f;
      for (int j = 0; j < kBodyJoints; ++j)
        worst = std::max(worst, glm::distance(got[j] - root, want[j]));
    }
  }
  return worst;
}

TEST(BvhFrame, CmuFramesReadBackAsTheDatabaseBodyTurnedByTheView) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  for (std::uint32_t clip : {0u, 1u}) {
    EXPECT_EQ(db.clips()[clip].family, "cmu31");
    const float worst = worst_error_over_clip(db, clip);
    EXPECT_LT(worst, 1e-3f) << db.clips()[clip].name;
    std::cout << "[ note ] " << db.clips()[clip].name << ": worst joint error " << worst * 1e3f
              << " mm\n";
  }
}

// Bandai: another channel order (Z X Y), position channels on every joint, a floor-level root.
TEST(BvhFrame, BandaiFramesReadBackAsTheDatabaseBodyTurnedByTheView) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  ASSERT_EQ(db.clips()[2].family, "bandai");
  const float worst = worst_error_over_clip(db, 2);
  EXPECT_LT(worst, 1e-3f);
  std::cout << "[ note ] " << db.clips()[2].name << ": worst joint error " << worst * 1e3f
            << " mm\n";
}

// The turn itself: seen from the camera at yaw 90 (the person's left), a person facing that
// camera after the turn has the left shoulder on the image's right... i.e. +X in this frame.
TEST(BvhFrame, ViewYawTurnsThePersonToFaceTheCamera) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  const std::uint32_t frame = db.clips()[0].first_frame + 10;
  std::uint32_t side = 0;
  while (db.views()[side].yaw_deg != 90.0f) ++side;
  BvhFrameMaker maker(db.clips()[0].skeleton, "08_01");
  std::vector<float> values;
  maker.channels(db, {frame, side}, values);
  const auto body = body_of(maker.skeleton(), values);
  // The database body faces +Z with its left at +X; the camera at yaw 90 sees its left side, so
  // turned by -90 degrees the left (+X) goes to +Z: towards a camera on +Z.
  const glm::vec3 across = body[index(Joint::left_hip)] - body[index(Joint::right_hip)];
  EXPECT_GT(across.z, 0.8f * glm::length(across));
}

TEST(BvhFrame, ProvenanceIsCheckedAgainstTheDatabase) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  Person3D person;
  person.id = 7;
  EXPECT_FALSE(database_pose_of(db, person).has_value());  // frame -1: no provenance
  person.provenance = {db.clips()[1].name, db.clips()[1].first_frame + 2, 3};
  const auto pose = database_pose_of(db, person);
  ASSERT_TRUE(pose.has_value());
  EXPECT_EQ(pose->frame, db.clips()[1].first_frame + 2);
  EXPECT_EQ(pose->view, 3u);
  for (Provenance wrong :
       {Provenance{"", static_cast<std::int64_t>(db.frames().size()), 0},
        Provenance{"", 0, static_cast<int>(db.views().size())}, Provenance{"other.bvh", 0, 0}}) {
    person.provenance = wrong;
    try {
      database_pose_of(db, person);
      ADD_FAILURE() << "no error for clip '" << wrong.clip << "' frame " << wrong.frame;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("person 7"), std::string::npos) << e.what();
    }
  }
}

TEST(BvhFrame, HierarchiesCompareByJointsNotBoneLengths) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  motion::Skeleton longer = db.clips()[0].skeleton;
  longer.joints[3].offset *= 1.2f;
  EXPECT_TRUE(same_hierarchy(db.clips()[0].skeleton, db.clips()[1].skeleton));
  EXPECT_TRUE(same_hierarchy(db.clips()[0].skeleton, longer));
  motion::Skeleton renamed = db.clips()[0].skeleton;  // the 2008 release's finger names
  renamed.joints[renamed.find("LeftHandIndex1")].name = "LFingers";
  EXPECT_TRUE(same_hierarchy(db.clips()[0].skeleton, renamed));
  motion::Skeleton other_channels = db.clips()[0].skeleton;
  other_channels.joints[5].channels.pop_back();
  EXPECT_FALSE(same_hierarchy(db.clips()[0].skeleton, other_channels));
  EXPECT_FALSE(same_hierarchy(db.clips()[0].skeleton, db.clips()[2].skeleton));
  BvhFrameMaker maker(db.clips()[0].skeleton, "08_01");
  std::vector<float> values;
  EXPECT_THROW(maker.channels(db, {db.clips()[2].first_frame, 0}, values), std::invalid_argument);
  EXPECT_THROW(BvhFrameMaker(motion::Skeleton{}, "positions only"), InputError);
}

// Smoothing keeps a still pose as it is and softens a pose that jumps back and forth.
TEST(BvhFrame, SmoothingHoldsStillPosesAndDampsJumps) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  const std::uint32_t a = db.clips()[0].first_frame + 5, b = db.clips()[0].first_frame + 25;
  BvhFrameMaker plain(db.clips()[0].skeleton, "08_01"), smooth(db.clips()[0].skeleton, "08_01");
  smooth.enable_smoothing(OneEuroParams{});
  std::vector<float> expected, got;
  plain.channels(db, {a, 3}, expected);
  for (int t = 0; t < 30; ++t) smooth.channels(db, {a, 3}, t / 30.0, got);
  for (std::size_t c = 0; c < expected.size(); ++c) EXPECT_NEAR(got[c], expected[c], 1e-2) << c;
  // Alternating between two poses: the smoothed channels move less than the raw ones.
  std::vector<float> raw_a, raw_b, previous = got;
  plain.channels(db, {b, 3}, raw_b);
  raw_a = expected;
  double raw_motion = 0, smooth_motion = 0;
  for (int t = 30; t < 60; ++t) {
    smooth.channels(db, {t % 2 ? b : a, 3}, t / 30.0, got);
    for (std::size_t c = 3; c < got.size();
         ++c) {  // rotations (the first three are the root position)
      smooth_motion += std::abs(got[c] - previous[c]);
      raw_motion += std::abs(raw_b[c] - raw_a[c]);
    }
    previous = got;
  }
  EXPECT_LT(smooth_motion, 0.5 * raw_motion);
}

// --- the per-person file writer

PeopleBvhOptions writer_options(std::string dir, std::string prefix, double fps,
                                int max_open_files) {
  PeopleBvhOptions options;
  options.dir = std::move(dir);
  options.prefix = std::move(prefix);
  options.fps = fps;
  options.max_open_files = max_open_files;
  return options;
}

Person3D person_at(const posedb::Database& db, int id, std::uint32_t clip, std::uint32_t offset,
                   int view = 0) {
  Person3D p;
  p.id = id;
  const posedb::ClipInfo& info = db.clips()[clip];
  p.provenance = {info.name, info.first_frame + offset % info.frame_count, view};
  return p;
}

People3D frame_of(std::int64_t frame, std::vector<Person3D> people) {
  People3D m;
  m.header.frame = frame;
  m.people = std::move(people);
  return m;
}

std::vector<float> row(const motion::Clip& clip, int f) {
  return {clip.frame(f), clip.frame(f) + clip.skeleton.channel_count};
}

TEST(PeopleBvhWriter, OneFilePerIdHeldOverGapsAndOverOtherSkeletons) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  test::TempDir dir;
  PeopleBvhWriter writer(db, writer_options((dir.path() / "out").string(), "p", 25.0, 64));
  // Person 1 in frames 0-1, missing in 2-3, back in 4 with a Bandai pose (other skeleton), then
  // a CMU pose from the other CMU clip in 5. Person 2 only in frame 3. Untracked people ignored.
  writer.write(frame_of(0, {person_at(db, 1, 0, 0), person_at(db, -1, 0, 3)}));
  writer.write(frame_of(1, {person_at(db, 1, 0, 1)}));
  writer.write(frame_of(2, {}));
  writer.write(frame_of(3, {person_at(db, 2, 1, 4, 6)}));
  writer.write(frame_of(4, {person_at(db, 1, 2, 0)}));
  writer.write(frame_of(5, {person_at(db, 1, 1, 7)}));
  writer.close();
  const PeopleBvhSummary& s = writer.summary();
  EXPECT_EQ(s.files, 2);
  EXPECT_EQ(s.frames, 7);
  EXPECT_EQ(s.held_over_gaps, 2);
  EXPECT_EQ(s.skeleton_mismatch, 1);
  const motion::Clip one = motion::read_bvh(writer.path_for(1));
  EXPECT_EQ(writer.path_for(1), (dir.path() / "out" / "p1.bvh").string());
  ASSERT_EQ(one.frame_count, 6);
  EXPECT_NEAR(one.frame_time, 0.04, 1e-6);
  EXPECT_EQ(row(one, 2), row(one, 1));  // missing: held
  EXPECT_EQ(row(one, 3), row(one, 1));
  EXPECT_EQ(row(one, 4), row(one, 1));  // Bandai pose on a CMU file: held
  EXPECT_NE(row(one, 5), row(one, 1));  // the other CMU clip: written
  EXPECT_EQ(motion::read_bvh(writer.path_for(2)).frame_count, 1);
  EXPECT_FALSE(std::filesystem::exists(writer.path_for(-1)));
}

TEST(PeopleBvhWriter, ManyPeopleStayUnderTheOpenFileLimit) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  test::TempDir dir;
  auto open_files = [] {
    return std::distance(std::filesystem::directory_iterator("/proc/self/fd"), {});
  };
  const auto open_before = open_files();
  PeopleBvhWriter writer(db, writer_options(dir.path().string(), "person_", 30.0, 3));
  for (std::int64_t f = 0; f < 20; ++f) {
    std::vector<Person3D> people;
    for (int id = 0; id < 8; ++id) {
      if ((id + f) % 3 != 0) people.push_back(person_at(db, id, 0, static_cast<std::uint32_t>(f)));
    }
    writer.write(frame_of(f, people));
    EXPECT_LE(open_files() - open_before, 3) << "frame " << f;
  }
  writer.close();
  for (int id = 0; id < 8; ++id) {
    const motion::Clip clip = motion::read_bvh(writer.path_for(id));
    const int first = (id % 3 == 0) ? 1 : 0;  // absent in frame 0 when (id + 0) % 3 == 0
    const int last = ((id + 19) % 3 == 0) ? 18 : 19;
    EXPECT_EQ(clip.frame_count, last - first + 1) << "person " << id;
  }
}

TEST(PeopleBvhWriter, FolderThatCannotBeMadeIsNamed) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  test::TempDir dir;
  std::ofstream(dir.file("file")) << "x";
  const std::string bad = dir.file("file") + "/sub";
  try {
    PeopleBvhWriter writer(db, writer_options(bad, "p", 30.0, 4));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mocap::recon
