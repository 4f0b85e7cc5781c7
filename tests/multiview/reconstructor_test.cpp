// Association, triangulation and tracking on virtual scenes (CMU train clips in a room, a ring of
// cameras, degraded 2D): wrong associations, id switches, MPJPE and coverage bounds that a
// regression would break. The bounds sit above what the method gives today (the numbers are in
// docs/multiview.md), with room for the randomness of the scene, not for a broken method.

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "multiview/scene_fixture.hpp"

namespace mocap::test {
namespace {

using multiview::ReconstructionOptions;

TEST(MultiViewScene, ThreePeopleFourCamerasAtTheTargetCondition) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  const SceneRun run = run_scene(scene_people(3), 4, 150, target_degradation());
  const eval::SceneScore& s = run.score;
  SCOPED_TRACE(describe(s));
  RecordProperty("score", describe(s));
  EXPECT_GT(s.person_frames, 400);
  // A track is reported once confirmed (its third frame): 2 of 150 frames per person missing.
  EXPECT_GE(s.coverage(), 0.98);
  EXPECT_LE(s.wrong_associations, s.person_frames / 200);
  EXPECT_EQ(s.false_people, 0);
  EXPECT_EQ(s.duplicates, 0);
  EXPECT_EQ(s.id_switches, 0);
  EXPECT_LT(s.mpjpe_mm(), 40.0);
}

TEST(MultiViewScene, SixPeopleSixteenCameras) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  const SceneRun run = run_scene(scene_people(6, 60), 16, 60, target_degradation());
  const eval::SceneScore& s = run.score;
  SCOPED_TRACE(describe(s));
  EXPECT_GE(s.coverage(), 0.96);
  EXPECT_LE(s.wrong_associations, s.person_frames / 200);
  EXPECT_EQ(s.false_people, 0);
  EXPECT_EQ(s.id_switches, 0);
  EXPECT_LT(s.mpjpe_mm(), 25.0);
}

TEST(MultiViewScene, TwoCamerasTwoPeople) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  eval::SceneDegradation d;
  d.noise = 0.01f;
  d.dropout = 0.05f;
  const SceneRun run = run_scene(scene_people(2, 120), 2, 120, d);
  const eval::SceneScore& s = run.score;
  SCOPED_TRACE(describe(s));
  EXPECT_GE(s.coverage(), 0.9);
  EXPECT_LE(s.wrong_associations, s.person_frames / 100);
  EXPECT_EQ(s.id_switches, 0);
  EXPECT_LT(s.mpjpe_mm(), 60.0);
}

TEST(MultiViewScene, CleanInputIsExact) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  eval::SceneDegradation d;
  d.occlusion = false;
  const SceneRun run = run_scene(scene_people(4, 30), 4, 30, d);
  const eval::SceneScore& s = run.score;
  SCOPED_TRACE(describe(s));
  EXPECT_EQ(s.reconstructed, s.person_frames - 2 * 4);  // each track confirmed in its third frame
  EXPECT_EQ(s.wrong_associations, 0);
  EXPECT_LT(s.mpjpe_mm(), 0.5);
}

// People walking straight through each other's path: the tracks' predictions keep them apart.
TEST(MultiViewScene, PeopleCrossingKeepTheirIds) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/08_01.bvh");
  MOCAP_REQUIRE_SHARED("mocap/cmu31/08_02.bvh");
  std::vector<eval::ScenePerson> people(2);
  people[0].motion = &scene_clip("08_01");
  people[1].motion = &scene_clip("08_02");
  // Both walk about 3 m along their x; the second turned around and started 3 m further on,
  // 0.5 m to the side, so they pass each other halfway.
  const auto& walk = people[0].motion->world;
  const glm::vec3 travel = walk.back()[index(Joint::root)] - walk.front()[index(Joint::root)];
  const float heading = glm::degrees(std::atan2(travel.x, travel.z));
  people[0].yaw_deg = 90.0f - heading;
  people[0].place = {-1.5f, 0.0f};
  people[1].yaw_deg = 270.0f - heading;
  people[1].place = {1.5f, 0.5f};
  eval::SceneDegradation d = target_degradation();
  const SceneRun run = run_scene(people, 4, 65, d);
  const eval::SceneScore& s = run.score;
  SCOPED_TRACE(describe(s));
  EXPECT_EQ(s.id_switches, 0);
  EXPECT_LE(s.wrong_associations, 1);
  EXPECT_GE(s.coverage(), 0.95);
}

// A person away for 1 s gets their id back; one away for longer than forget_after_s (3 s) gets a
// new one.
TEST(MultiViewScene, ReturningPeople) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  auto people = scene_people(3, 220);
  people[0].leave = 40;
  people[0].back = 70;
  people[1].leave = 40;
  people[1].back = 180;
  eval::SceneDegradation d;
  d.noise = 0.01f;
  const SceneRun run = run_scene(people, 4, 220, d, {}, 7, true);
  std::vector<std::set<int>> ids(3);
  std::vector<int> last(3, -1);
  for (const auto& r : run.results) {
    for (std::size_t p = 0; p < r.people.size(); ++p) {
      // Which scene person: the nearest body centre at frame r.frame.
      const glm::vec3 centre = multiview::body_centre(r.body_of(p));
      int who = -1;
      float best = 0.5f;
      for (int i = 0; i < 3; ++i) {
        const auto body = people[i].at(static_cast<int>(r.frame));
        if (!body) continue;
        const float dist = glm::distance(centre, (*body)[index(Joint::root)]);
        if (dist < best) {
          best = dist;
          who = i;
        }
      }
      ASSERT_GE(who, 0) << "frame " << r.frame;
      ids[who].insert(r.people[p].id);
    }
  }
  EXPECT_EQ(ids[0].size(), 1u) << "back after 1 s: the same id";
  EXPECT_EQ(ids[1].size(), 2u) << "back after 4.7 s: a new id";
  EXPECT_EQ(ids[2].size(), 1u);
  EXPECT_EQ(run.score.id_switches, 1) << describe(run.score);
}

// Bystanders seen by one view only are reported as single-view people, never triangulated.
TEST(MultiViewScene, BystandersInOneViewAreSingleViewPeople) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  eval::SceneDegradation d;
  d.noise = 0.01f;
  d.bystander_views = {0, 1};
  const SceneRun run = run_scene(scene_people(2, 60), 4, 60, d, {}, 3, true);
  SCOPED_TRACE(describe(run.score));
  EXPECT_EQ(run.score.false_people, 0);
  EXPECT_EQ(run.score.wrong_associations, 0);
  for (const auto& r : run.results) {
    int bystanders = 0;
    for (const auto& single : r.single_view) bystanders += single.view <= 1;
    EXPECT_GE(bystanders, 2) << "frame " << r.frame;
  }
}

// Without tracking every frame is associated from scratch: the same quality, ids -1.
TEST(MultiViewScene, WithoutTrackingEveryFrameStandsAlone) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  ReconstructionOptions options;
  options.tracking = false;
  const SceneRun run =
      run_scene(scene_people(3, 60), 4, 60, target_degradation(), options, 1, true);
  SCOPED_TRACE(describe(run.score));
  EXPECT_GE(run.score.coverage(), 0.97);
  EXPECT_LE(run.score.wrong_associations, run.score.person_frames / 100);
  for (const auto& r : run.results) {
    for (const auto& p : r.people) EXPECT_EQ(p.id, -1);
  }
}

// The baseline triangulation in the same pipeline: it works, and ours (with the tracks' prior) is
// more accurate at the target condition with more joints.
TEST(MultiViewScene, OursBeatsPose2SimRule) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  const auto people = scene_people(3, 100);
  ReconstructionOptions baseline;
  baseline.triangulation.method = multiview::TriangulationMethod::pose2sim;
  const SceneRun theirs = run_scene(people, 4, 100, target_degradation(), baseline);
  const SceneRun ours = run_scene(people, 4, 100, target_degradation());
  SCOPED_TRACE("baseline: " + describe(theirs.score) + "; ours: " + describe(ours.score));
  EXPECT_LT(theirs.score.mpjpe_mm(), 60.0);
  EXPECT_EQ(theirs.score.wrong_associations, 0);
  EXPECT_LT(ours.score.mpjpe_mm(), 0.9 * theirs.score.mpjpe_mm());
  EXPECT_GT(ours.score.joints, theirs.score.joints);
}

}  // namespace
}  // namespace mocap::test

namespace mocap::test {
namespace {

// Keypoints from the network or a broken detector: NaN, infinities, huge and negative values,
// people of one pixel, the same person twice in a view. Nothing throws, nothing non-finite comes
// out.
TEST(MultiViewGarbage, AnyKeypointValuesAreSurvived) {
  const auto rig = scene_rig(4);
  multiview::MultiViewReconstructor reconstructor(geometries(rig),
                                                  multiview::KeypointSet::body15());
  std::mt19937 rng(11);
  const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            1e30f,
                            -1e30f,
                            0.0f,
                            -1.0f,
                            5e5f};
  std::uniform_real_distribution<float> pixel(-100.0f, 2000.0f), unit(0.0f, 1.0f);
  multiview::FrameObservations frame;
  for (int f = 0; f < 60; ++f) {
    frame.reset(4, kBodyJoints);
    for (int v = 0; v < 4; ++v) {
      const int people = static_cast<int>(unit(rng) * 6);
      for (int p = 0; p < people; ++p) {
        const std::span<float> xyc = frame.add_person(v);
        const float x0 = pixel(rng), y0 = pixel(rng);
        for (std::size_t i = 0; i < xyc.size(); ++i) {
          const float u = unit(rng);
          xyc[i] = u < 0.1f   ? specials[static_cast<int>(unit(rng) * 8) % 8]
                   : u < 0.3f ? (i % 3 == 0 ? x0 : y0)  // a person of one pixel
                              : pixel(rng);
        }
        if (p == 1) frame.add_person(v, xyc);  // the same detection twice
      }
    }
    const multiview::FrameResult& r = reconstructor.process(frame, f);
    for (std::size_t p = 0; p < r.people.size(); ++p) {
      for (const auto& k : r.keypoints_of(p)) {
        if (!k.valid()) continue;
        EXPECT_TRUE(std::isfinite(k.position.x) && std::isfinite(k.position.y) &&
                    std::isfinite(k.position.z));
      }
    }
  }
  // Wrong shapes are refused with a message.
  multiview::FrameObservations wrong(3, kBodyJoints);
  EXPECT_THROW(reconstructor.process(wrong, 60), std::invalid_argument);
  multiview::FrameObservations other_layout(4, 25);
  EXPECT_THROW(reconstructor.process(other_layout, 60), std::invalid_argument);
}

}  // namespace
}  // namespace mocap::test
