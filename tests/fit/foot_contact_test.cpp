#include "fit/foot_contact.hpp"

#include <gtest/gtest.h>

#include "fit/fit_evaluation.hpp"
#include "fit/fit_fixture.hpp"
#include "posedb/database.hpp"
#include "support/small_pose_database.hpp"

namespace mocap {
namespace {

// The detector reads the database's frames of a clip; the same clip read as truth and judged
// by truth_contacts (same thresholds) must agree, and a walk has both feet down part of the time.
TEST(FootContact, DatabaseFramesAgreeWithTheClipsOwnMotion) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  const fit::ContactDetector detector(db);
  const auto& clips = db.clips();
  const auto it = std::find_if(clips.begin(), clips.end(),
                               [](const auto& c) { return c.name.find("08_01") == 0; });
  ASSERT_NE(it, clips.end());
  const auto file = test::shared_data() / "mocap" / "cmu31" / "08_01.bvh";
  const auto truth = eval::load_truth({file.string()}, db.build_info().fps).front().world;
  ASSERT_EQ(truth.size(), it->frame_count);
  const auto expected = fit::truth_contacts(truth, db.build_info().fps);
  std::array<int, 2> down{}, agree{};
  for (std::uint32_t f = 0; f < it->frame_count; ++f) {
    const auto c = detector.contact(it->first_frame + f);
    for (int s = 0; s < 2; ++s) {
      down[s] += c[s];
      agree[s] += c[s] == expected[f][s];
    }
  }
  const double n = it->frame_count;
  for (int s = 0; s < 2; ++s) {
    EXPECT_GT(agree[s] / n, 0.97) << "foot " << s;
    EXPECT_GT(down[s] / n, 0.15) << "foot " << s;
    EXPECT_LT(down[s] / n, 0.9) << "foot " << s;
  }
  EXPECT_EQ(detector.contact(static_cast<std::uint32_t>(db.frames().size())),
            (std::array<bool, 2>{}));  // out of range: no contact, no crash
}

TEST(FootContact, InvalidPosesHaveNoContact) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  const fit::ContactDetector detector(db);
  std::vector<recon::Pose3D> poses(3);
  poses[1].valid = true;
  poses[1].chosen.frame = 0;
  const auto c = detector.contacts(poses);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0], (std::array<bool, 2>{}));
  EXPECT_EQ(c[1], detector.contact(0));
}

}  // namespace
}  // namespace mocap
