// Calibration from people (calibration/people_calibration.hpp) on a virtual scene: a walker of a
// CMU *train* clip seen by 4 cameras of a ring with detector-like 2D (noise, dropped joints,
// outliers) gives the rig back within tolerance once the worlds are aligned; the floor comes out
// level under the feet; one person standing still, views of different lengths and a camera that
// never sees the person are refused with the reason.

#include "calibration/people_calibration.hpp"

#include <gtest/gtest.h>

#include <iostream>

#include <glm/geometric.hpp>

#include "core/input_error.hpp"
#include "motion/body_mapping.hpp"
#include "motion/bvh.hpp"
#include "motion/canonical_body.hpp"
#include "support/people_rig_scene.hpp"
#include "support/shared_data.hpp"

namespace mocap::calibration {
namespace {

const std::string kWalkerFile = "08_01.bvh";
const std::string kSecondWalkerFile = "09_01.bvh";

const eval::TruthSequence& walker() {
  static const std::vector<eval::TruthSequence> truth =
      eval::load_truth({(test::shared_data() / "mocap" / "cmu31" / kWalkerFile).string()}, 30.0);
  return truth.front();
}

const eval::TruthSequence& second_walker() {
  static const std::vector<eval::TruthSequence> truth = eval::load_truth(
      {(test::shared_data() / "mocap" / "cmu31" / kSecondWalkerFile).string()}, 30.0);
  return truth.front();
}

// The walker's standing height, from the reference T-pose of its file.
double walker_stature_m() {
  const std::string file = (test::shared_data() / "mocap" / "cmu31" / kWalkerFile).string();
  const motion::Clip clip = motion::read_bvh(file);
  return motion::reference_stature_m(clip, motion::map_to_body(clip.skeleton, file));
}

eval::SceneDegradation detector_like() {
  eval::SceneDegradation d;
  d.noise = 0.01f;
  d.dropout = 0.1f;
  d.outliers = 0.02f;
  d.occlusion = false;
  return d;
}

std::vector<std::string> sources(std::size_t n) {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < n; ++k) out.push_back("view_" + std::to_string(k + 1));
  return out;
}

std::vector<camera::Camera> intrinsics_only(std::vector<camera::Camera> cameras) {
  for (camera::Camera& c : cameras) {
    c.rotation = glm::dmat3(1.0);
    c.translation = glm::dvec3(0.0);
  }
  return cameras;
}

// Placed to stay within 2 m of the room's centre for `frames` frames.
eval::ScenePerson walking_through_the_room(int frames) {
  std::vector<eval::ScenePerson> people(1);
  people[0].motion = &walker();
  eval::spread_people(people, frames, 2.0f, 1.0f, 1);
  return people[0];
}

std::string refusal(const std::vector<camera::Camera>& cameras,
                    const std::vector<camera::BodySequence>& views) {
  try {
    calibrate_rig_from_people(intrinsics_only(cameras), views, sources(views.size()));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PeopleCalibration, AVirtualRigIsRecoveredFromAWalker) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/08_01.bvh");
  const test::PeopleRigScene s =
      test::make_people_rig_scene({walking_through_the_room(90)}, 4, 90, detector_like(), 3);
  PeopleCalibrationOptions options;
  options.height_m = 0;  // the canonical body: the scale is checked separately below
  const PeopleCalibration found =
      calibrate_rig_from_people(intrinsics_only(s.truth), s.views, sources(4), options);
  ASSERT_EQ(found.rig.cameras.size(), 4u);
  const test::RigComparison c = test::compare_rigs(found.rig.cameras, s.truth);
  for (std::size_t k = 0; k < 4; ++k) {
    std::cout << "[ measured ] " << s.truth[k].name << ": " << 100 * c.position_m[k] << " cm, "
              << c.angle_deg[k] << " deg, " << found.cameras[k].rms_px << " px RMS\n";
    EXPECT_LT(c.position_m[k], 0.05) << s.truth[k].name;  // 4.5 m from the centre
    EXPECT_LT(c.angle_deg[k], 0.5) << s.truth[k].name;
    EXPECT_LT(found.cameras[k].rms_px, 15.0);  // noise σ 1 % of a ~500 px person, outliers
  }
  // Metres from the canonical body's standing height: CMU subject 8 is within 10 % of it.
  std::cout << "[ measured ] scale to the truth " << c.to_truth.scale << "\n";
  EXPECT_NEAR(c.to_truth.scale, 1.0, 0.1);
  // The world: z up, the cameras 1.6 and 2.4 m above the floor (scaled as the rig is).
  for (std::size_t k = 0; k < 4; ++k) {
    const double height = found.rig.cameras[k].centre().z * c.to_truth.scale;
    EXPECT_NEAR(height, k % 2 == 0 ? 1.6 : 2.4, 0.1) << s.truth[k].name;
  }
}

TEST(PeopleCalibration, OnePersonStandingStillIsRefused) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/08_01.bvh");
  eval::TruthSequence still;
  still.clip = "one pose of 08_01";
  still.world.assign(60, walker().world.front());
  eval::ScenePerson p;
  p.motion = &still;
  const test::PeopleRigScene s = test::make_people_rig_scene({p}, 4, 60, detector_like(), 5);
  const std::string why = refusal(s.truth, s.views);
  EXPECT_NE(why.find("hardly moves"), std::string::npos) << why;
}

TEST(PeopleCalibration, ViewsOfDifferentLengthsAndACameraWithoutThePersonAreRefused) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/08_01.bvh");
  test::PeopleRigScene s =
      test::make_people_rig_scene({walking_through_the_room(40)}, 3, 40, detector_like(), 7);
  std::vector<camera::BodySequence> shorter = s.views;
  shorter[2].resize(30);
  const std::string length = refusal(s.truth, shorter);
  EXPECT_NE(length.find("view_3: has 30 frames, view_1 has 40"), std::string::npos) << length;

  std::vector<camera::BodySequence> blind = s.views;
  for (auto& frame : blind[1]) frame.clear();
  const std::string nobody = refusal(s.truth, blind);
  EXPECT_NE(nobody.find("cam_02"), std::string::npos) << nobody;
  EXPECT_NE(nobody.find("no person"), std::string::npos) << nobody;

  std::vector<camera::BodySequence> rarely = s.views;
  for (std::size_t f = 5; f < rarely[1].size(); ++f) rarely[1][f].clear();
  const std::string few = refusal(s.truth, rarely);
  EXPECT_NE(few.find("cam_02"), std::string::npos) << few;
  EXPECT_NE(few.find("shares 5 frames"), std::string::npos) << few;
}

// --height is the standing height (floor to top of head): a walker of known height gives the rig at
// its true scale, within the spread of the subjects' stature / joint span ratios (the walker's own
// against the train median, plus the noise in its bones).
TEST(PeopleCalibration, TheWalkersStandingHeightGivesTheTrueScale) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/08_01.bvh");
  const double stature = walker_stature_m();
  ASSERT_GT(stature, 1.3);  // subject 8's T-pose: 1.43 m
  const test::PeopleRigScene s =
      test::make_people_rig_scene({walking_through_the_room(60)}, 3, 60, detector_like(), 13);
  PeopleCalibrationOptions options;
  options.height_m = stature;
  options.max_frames = 30;     // of the 60 in each bundle adjustment: a fast test
  options.outlier_rounds = 1;  // one re-solve after dropping outliers: a fast test
  const PeopleCalibration found =
      calibrate_rig_from_people(intrinsics_only(s.truth), s.views, sources(3), options);
  const test::RigComparison c = test::compare_rigs(found.rig.cameras, s.truth);
  std::cout << "[ measured ] standing height " << stature << " m: scale to the truth "
            << c.to_truth.scale << "\n";
  EXPECT_NEAR(c.to_truth.scale, 1.0, 0.03);
  EXPECT_DOUBLE_EQ(found.height_m, stature);
  // In metres as calibrated (no rescaling): the distance between two cameras.
  const double baseline = glm::distance(s.truth[0].centre(), s.truth[1].centre());
  EXPECT_NEAR(glm::distance(found.rig.cameras[0].centre(), found.rig.cameras[1].centre()), baseline,
              0.03 * baseline);
}

// Two people walking in the room at once: each frame's person is associated across the views by
// epipolar consistency (a view's most visible detection is often the other person), and the rig
// comes out as well as from one walker.
TEST(PeopleCalibration, TwoPeopleInViewAreAssociatedAcrossTheViews) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/08_01.bvh");
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_01.bvh");
  std::vector<eval::ScenePerson> people(2);
  people[0].motion = &walker();
  people[1].motion = &second_walker();
  eval::spread_people(people, 60, 2.0f, 1.0f, 1);
  eval::SceneDegradation d = detector_like();
  d.occlusion = true;  // people hide each other
  const test::PeopleRigScene s = test::make_people_rig_scene(people, 3, 60, d, 17);
  // Both people are seen in most views' frames: several detections per frame to choose from.
  int frames_with_two = 0;
  for (const auto& frame : s.views[0]) frames_with_two += frame.size() >= 2;
  EXPECT_GT(frames_with_two, 30);
  PeopleCalibrationOptions options;
  options.max_frames = 30;     // of the 60 in each bundle adjustment: a fast test
  options.outlier_rounds = 1;  // one re-solve after dropping outliers: a fast test
  const PeopleCalibration found =
      calibrate_rig_from_people(intrinsics_only(s.truth), s.views, sources(3), options);
  bool associated = false;
  for (const std::string& note : found.notes)
    associated = associated || note.find("associated across the views") != std::string::npos;
  EXPECT_TRUE(associated);
  const test::RigComparison c = test::compare_rigs(found.rig.cameras, s.truth);
  for (std::size_t k = 0; k < 3; ++k) {
    std::cout << "[ measured ] two people, " << s.truth[k].name << ": " << 100 * c.position_m[k]
              << " cm, " << c.angle_deg[k] << " deg, " << found.cameras[k].rms_px << " px RMS\n";
    EXPECT_LT(c.position_m[k], 0.05) << s.truth[k].name;
    EXPECT_LT(c.angle_deg[k], 0.5) << s.truth[k].name;
  }
}

// The same view given twice (no baseline): refused naming both views, before any solve.
TEST(PeopleCalibration, TheSameViewTwiceIsRefused) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/08_01.bvh");
  test::PeopleRigScene s =
      test::make_people_rig_scene({walking_through_the_room(30)}, 3, 30, detector_like(), 19);
  s.views[2] = s.views[0];
  const std::string why = refusal(s.truth, s.views);
  EXPECT_NE(why.find("view_3"), std::string::npos) << why;
  EXPECT_NE(why.find("same pixels as camera cam_01 (view_1)"), std::string::npos) << why;
  EXPECT_NE(why.find("no baseline"), std::string::npos) << why;
}

}  // namespace
}  // namespace mocap::calibration
