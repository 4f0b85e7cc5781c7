// The matcher and the temporal choices on a real database: a database clip replayed as 2D input
// through one of the database's own views is found again, frame after frame.

#include <random>

#include <gtest/gtest.h>

#include "posedb/builder.hpp"
#include "posedb/projection.hpp"
#include "recon/people_selector.hpp"
#include "recon/sequence_reconstruction.hpp"
#include "support/shared_data.hpp"

namespace mocap::recon {
namespace {

class SelectionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto mocap = test::shared_data() / "mocap" / "cmu31";
    if (!std::filesystem::exists(mocap / "09_12.bvh")) return;
    dir_ = std::make_unique<test::TempDir>();
    posedb::BuildOptions options;
    options.clusters = 64;
    posedb::BuildReport report;
    const auto contents =
        posedb::build_database({(mocap / "08_01.bvh").string(), (mocap / "09_12.bvh").string(),
                                (mocap / "86_01.bvh").string()},
                               options, {}, report);
    posedb::write_database(contents, dir_->file("db.mdb"));
    db_ = std::make_unique<posedb::Database>(posedb::Database::open(dir_->file("db.mdb")));
    bones_ = std::make_unique<FrameBones>(*db_);
  }
  static void TearDownTestSuite() {
    bones_.reset();
    db_.reset();
    dir_.reset();
  }
  void SetUp() override {
    if (!db_) GTEST_SKIP() << "shared mocap data absent (../shared/data/mocap/cmu31)";
  }

  // Frames [first, first + count) of clip `clip` seen through view `view`, in pixels (focal 1000).
  static std::vector<BodyXyc> replay(std::uint32_t clip, std::uint32_t first, std::uint32_t count,
                                     std::uint32_t view) {
    const auto& info = db_->clips()[clip];
    const camera::Camera camera =
        posedb::view_camera(db_->views()[view], db_->build_info().views.root_height_m);
    std::vector<BodyXyc> frames;
    for (std::uint32_t f = info.first_frame + first; f < info.first_frame + first + count; ++f) {
      std::array<glm::vec3, kBodyJoints> body;
      const auto j = db_->joints(f);
      for (int b = 0; b < kBodyJoints; ++b) body[b] = {j[3 * b], j[3 * b + 1], j[3 * b + 2]};
      std::array<glm::vec2, kBodyJoints> image;
      posedb::project_body(body, camera, image);
      BodyXyc xyc;
      for (int b = 0; b < kBodyJoints; ++b)
        xyc[3 * b] = 960 + 1000 * image[b].x, xyc[3 * b + 1] = 540 + 1000 * image[b].y,
                xyc[3 * b + 2] = 1;
      frames.push_back(xyc);
    }
    return frames;
  }

  static inline std::unique_ptr<test::TempDir> dir_;
  static inline std::unique_ptr<posedb::Database> db_;
  static inline std::unique_ptr<FrameBones> bones_;
};

TEST_F(SelectionTest, ReplayedClipIsFoundAgainByEverySelection) {
  const std::uint32_t clip = 1, first = 40, count = 60, view = 37;  // 09_12 (walking), 2.5 m camera
  const auto input = replay(clip, first, count, view);
  Matcher matcher(*db_, MatchOptions{});
  for (Selection selection : {Selection::nearest, Selection::greedy, Selection::path}) {
    SequenceOptions options;
    options.selection = selection;
    const auto poses = reconstruct_sequence(matcher, *bones_, input, options);
    int exact = 0;
    for (std::uint32_t t = 0; t < count; ++t) {
      ASSERT_TRUE(poses[t].valid);
      const auto& chosen = db_->frames()[poses[t].chosen.frame];
      exact += chosen.clip == clip && chosen.clip_frame == first + t && poses[t].chosen.view == view
                   ? 1
                   : 0;
      // The 3D body is the truth seen by that camera: joints within a few millimetres.
      if (poses[t].chosen.frame == db_->clips()[clip].first_frame + first + t &&
          poses[t].chosen.view == view) {
        const Pose3D truth =
            pose_in_camera(*db_, {0, db_->clips()[clip].first_frame + first + t, view, 0.0f});
        for (int b = 0; b < kBodyJoints; ++b)
          EXPECT_LT(glm::distance(poses[t].joints[b], truth.joints[b]), 1e-4f);
      }
    }
    EXPECT_GE(exact, static_cast<int>(count) * 9 / 10) << selection_name(selection);
  }
}

TEST_F(SelectionTest, NoisyReplayStaysInTheClipWithTheTemporalChoice) {
  const std::uint32_t clip = 2, first = 100, count = 80, view = 5;  // 86_01 (kicks and punches)
  auto input = replay(clip, first, count, view);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 6.0f);  // pixels, on a ~450 px tall person
  for (auto& frame : input)
    for (int b = 0; b < kBodyJoints; ++b)
      frame[3 * b] += noise(rng), frame[3 * b + 1] += noise(rng);
  Matcher matcher(*db_, MatchOptions{});
  auto in_clip = [&](Selection selection) {
    SequenceOptions options;
    options.selection = selection;
    const auto poses = reconstruct_sequence(matcher, *bones_, input, options);
    int n = 0;
    for (const auto& p : poses) n += db_->frames()[p.chosen.frame].clip == clip ? 1 : 0;
    return n;
  };
  const int nearest = in_clip(Selection::nearest), path = in_clip(Selection::path);
  EXPECT_GE(path, nearest);
  EXPECT_GE(path, static_cast<int>(count) * 8 / 10);
}

TEST_F(SelectionTest, MissingJointsStillGiveFullBodies) {
  auto input = replay(1, 40, 30, 37);
  for (auto& frame : input) {
    for (Joint j : {Joint::left_wrist, Joint::left_elbow, Joint::left_ankle, Joint::right_ankle})
      frame[3 * index(j) + 2] = 0.0f;
  }
  Matcher matcher(*db_, MatchOptions{});
  SequenceOptions options;
  options.selection = Selection::path;
  const auto poses = reconstruct_sequence(matcher, *bones_, input, options);
  int in_clip = 0;
  for (const auto& p : poses) {
    ASSERT_TRUE(p.valid);
    in_clip += db_->frames()[p.chosen.frame].clip == 1 ? 1 : 0;
    for (const auto& joint : p.joints) ASSERT_TRUE(std::isfinite(joint.x));
  }
  EXPECT_GE(in_clip, 24);
}

TEST_F(SelectionTest, LaggedPathDecidesEveryFrameOnceInOrder) {
  const auto input = replay(1, 0, 40, 3);
  Matcher matcher(*db_, MatchOptions{});
  LaggedPathSelector lagged(*bones_, PathOptions{}, 5);
  std::vector<std::size_t> decided;
  for (std::size_t t = 0; t < input.size(); ++t) {
    std::vector<Candidate> candidates;
    if (t != 20) matcher.match(input[t], candidates);  // frame 20: nobody
    for (const auto& [frame, choice] : lagged.push(candidates)) {
      decided.push_back(frame);
      EXPECT_EQ(choice.has_value(), frame != 20) << frame;
    }
    if (t >= 25) {
      EXPECT_EQ(decided.size(), t - 4);  // the lag holds five frames back
    }
  }
  for (const auto& [frame, choice] : lagged.flush()) decided.push_back(frame);
  ASSERT_EQ(decided.size(), input.size());
  for (std::size_t t = 0; t < decided.size(); ++t) EXPECT_EQ(decided[t], t);
}

TEST_F(SelectionTest, PeopleSelectorGivesOneFrameOutPerFrameInOrderAfterTheLag) {
  // Person 1 in every frame, person 2 missing in frames 10-12, untracked people (id -1) ignored.
  const auto walk = replay(1, 0, 40, 3), other = replay(2, 100, 40, 5);
  Matcher matcher(*db_, MatchOptions{});
  PeopleSelectorOptions options;
  options.mode = SelectionMode::path;
  options.lag = 5;
  PeopleSelector selector(*db_, *bones_, options);
  std::vector<People3D> out;
  for (std::size_t t = 0; t < walk.size(); ++t) {
    PoseMatches in;
    in.header.seq = t;
    for (const auto& [id, input] :
         {std::pair{2, &other}, std::pair{1, &walk}, std::pair{-1, &walk}}) {
      if (id == 2 && t >= 10 && t <= 12) continue;
      PersonMatch person;
      person.id = id;
      for (int j = 0; j < kBodyJoints; ++j)
        person.body[j] = {(*input)[t][3 * j], (*input)[t][3 * j + 1], (*input)[t][3 * j + 2]};
      matcher.match((*input)[t], person.candidates);
      in.people.push_back(person);
    }
    for (auto& f : selector.push(in)) out.push_back(std::move(f));
    EXPECT_EQ(out.size(), t >= 5 ? t - 4 : 0) << "frame " << t;  // decided 5 frames late
  }
  for (auto& f : selector.finish()) out.push_back(std::move(f));
  ASSERT_EQ(out.size(), walk.size());
  for (std::size_t t = 0; t < out.size(); ++t) {
    EXPECT_EQ(out[t].header.seq, t);
    const std::size_t people = t >= 10 && t <= 12 ? 1 : 2;
    ASSERT_EQ(out[t].people.size(), people) << "frame " << t;
    EXPECT_EQ(out[t].people[0].id, 1);  // sorted by id
    EXPECT_EQ(out[t].people[0].keypoints[index(Joint::neck)].x, walk[t][3 * index(Joint::neck)]);
    if (people == 2) {
      EXPECT_EQ(out[t].people[1].id, 2);
    }
  }
}

}  // namespace
}  // namespace mocap::recon
