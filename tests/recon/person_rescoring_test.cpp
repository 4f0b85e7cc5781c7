// The matcher's optional re-scoring on the person's own proportions (Matcher::set_person).

#include <gtest/gtest.h>

#include "motion/canonical_body.hpp"
#include "posedb/projection.hpp"
#include "recon/matcher.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::recon {
namespace {

// Bandai-like proportions: narrow, low shoulders, short upper arms, long forearms.
motion::BodyProportions narrow_person() {
  motion::BodyProportions p = motion::canonical_proportions();
  for (Joint j : {Joint::right_shoulder, Joint::left_shoulder}) p.bone_m[index(j)] = 0.109f;
  for (Joint j : {Joint::right_elbow, Joint::left_elbow}) p.bone_m[index(j)] = 0.243f;
  for (Joint j : {Joint::right_wrist, Joint::left_wrist}) p.bone_m[index(j)] = 0.223f;
  for (Joint j : {Joint::right_hip, Joint::left_hip}) p.bone_m[index(j)] = 0.065f;
  p.shoulder_angle_rad = 1.9f;  // 109 degrees
  return p;
}

// A person of other proportions performs a database pose: with the person's proportions known,
// that pose (frame and view) comes out first with distance 0; without, it does not fit exactly.
TEST(PersonRescoring, ThePersonsOwnPoseComesFirstOnTheirProportions) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  const motion::BodyProportions person = narrow_person();
  MatchOptions options;
  options.exact = true;
  Matcher matcher(db, options);
  int promoted = 0, tried = 0;
  for (std::uint32_t frame = 10; frame < db.frames().size(); frame += 13) {
    const std::uint32_t view = (frame * 7) % db.views().size();
    const auto j = db.joints(frame);
    motion::Body15 body;
    for (int b = 0; b < kBodyJoints; ++b) body[b] = {j[3 * b], j[3 * b + 1], j[3 * b + 2]};
    std::array<glm::vec2, kBodyJoints> image;
    posedb::project_body(motion::retarget(body, person),
                         posedb::view_camera(db.views()[view], db.build_info().views.root_height_m),
                         image);
    posedb::PoseVector query;
    ASSERT_TRUE(posedb::normalize_pose(image, db.build_info().scaling, query));

    std::vector<Candidate> plain, rescored;
    matcher.set_person(std::nullopt);
    matcher.search(query, plain);
    matcher.set_person(person);
    matcher.search(query, rescored);
    ASSERT_EQ(plain.size(), rescored.size());
    for (std::size_t i = 1; i < rescored.size(); ++i)
      ASSERT_LE(rescored[i - 1].distance, rescored[i].distance);
    const bool listed = std::any_of(plain.begin(), plain.end(), [&](const Candidate& c) {
      return c.frame == frame && c.view == view;
    });
    if (!listed) continue;  // re-scoring only re-orders the k candidates found
    ++tried;
    EXPECT_GT(plain.front().distance, 1e-6f);
    EXPECT_LT(rescored.front().distance, 1e-8f);
    if (rescored.front().frame == frame && rescored.front().view == view) ++promoted;
  }
  ASSERT_GE(tried, 5);
  EXPECT_EQ(promoted, tried);
  matcher.set_person(std::nullopt);
  EXPECT_FALSE(matcher.person().has_value());
}

}  // namespace
}  // namespace mocap::recon
