// The layout offsets in a controlled experiment (docs/keypoint-layouts.md): mocap rendered in a
// layout's keypoint definition (eval::render with an input layout) and reconstructed with the
// offsets off, applied to the 2D input (SequenceOptions::layout_offsets) and applied to the
// matcher's candidates (Matcher::set_layout). The clip is one of the database's, so with the
// canonical joints as input the matcher finds its own poses; a layout moves the keypoints away
// from them and a correct correction must win that back. A wrong sign, basis vector, order of
// application or inverse makes the corrected runs no better (or worse) than the uncorrected one.

#include <gtest/gtest.h>

#include "eval/virtual_protocol.hpp"
#include "recon/layout_offsets.hpp"
#include "recon/sequence_reconstruction.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::eval {
namespace {

using recon::JointOffset;
using recon::LayoutOffsets;
using recon::OffsetBasis;

// Offsets in the plane of the trunk and along the limbs only: the 2D correction is exact for
// them (up to perspective). Large, so that the layout clearly costs accuracy uncorrected.
LayoutOffsets in_plane_layout() {
  LayoutOffsets o;
  o.layout = LayoutId::body25b;
  o.source = "test: in-plane";
  o.joints[index(Joint::root)] = {OffsetBasis::hips, 0.12f, 0.0f, 0.0f};
  o.joints[index(Joint::head)] = {OffsetBasis::shoulders, -0.15f, 0.0f, 0.0f};
  o.joints[index(Joint::neck)] = {OffsetBasis::shoulders, 0.10f, 0.0f, 0.0f};
  o.joints[index(Joint::right_shoulder)] = {OffsetBasis::shoulders, 0.08f, 0.10f, 0.0f};
  o.joints[index(Joint::left_shoulder)] = {OffsetBasis::shoulders, 0.08f, -0.10f, 0.0f};
  o.joints[index(Joint::right_hip)] = {OffsetBasis::hips, -0.10f, -0.15f, 0.0f};
  o.joints[index(Joint::left_hip)] = {OffsetBasis::hips, -0.10f, 0.15f, 0.0f};
  for (Joint j : {Joint::right_elbow, Joint::left_elbow, Joint::right_knee, Joint::left_knee})
    o.joints[index(j)] = {OffsetBasis::bone, 0.12f, 0.0f, 0.0f};
  return o;
}

// Mostly towards the front or back of the body (as HumanEva-15's pelvis and head): the 2D
// correction cannot express it, the candidates' 3D correction can.
LayoutOffsets forward_layout() {
  LayoutOffsets o;
  o.layout = LayoutId::humaneva15;
  o.source = "test: forward";
  o.joints[index(Joint::root)] = {OffsetBasis::hips, -0.03f, 0.0f, 0.20f};
  o.joints[index(Joint::head)] = {OffsetBasis::shoulders, -0.03f, 0.0f, -0.40f};
  o.joints[index(Joint::neck)] = {OffsetBasis::shoulders, 0.03f, 0.0f, -0.15f};
  return o;
}

enum class Correction { none, input_2d, candidates };

struct Experiment {
  const posedb::Database& db;
  TruthSequence truth;
  std::unique_ptr<recon::FrameBones> bones = std::make_unique<recon::FrameBones>(db);

  // Mean PA-MPJPE (mm) of per-frame nearest-neighbour reconstructions from three cameras.
  double pa_mpjpe(const LayoutOffsets* layout, Correction correction) const {
    recon::MatchOptions match;
    match.exact = true;

    recon::Matcher matcher(db, match);
    recon::SequenceOptions options;
    options.selection = recon::Selection::nearest;
    if (correction == Correction::input_2d) options.layout_offsets = *layout;
    if (correction == Correction::candidates) matcher.set_layout(*layout);
    Scores total;
    for (const float yaw : {20.0f, 100.0f, 230.0f}) {
      const VirtualCamera camera{"level", yaw, 1.5f, 0.0f, 4.5f};
      const RenderedSequence rendered = render(truth, camera, {}, {}, 7, layout);
      total.add(score(recon::reconstruct_sequence(matcher, *bones, rendered.input, options),
                      rendered.truth_camera));
    }
    EXPECT_EQ(total.coverage(), 1.0);
    return total.pa_mpjpe();
  }
};

class LayoutVirtual : public ::testing::Test {
 protected:
  static std::unique_ptr<posedb::Database> db;
  static std::unique_ptr<Experiment> experiment;
  static void SetUpTestSuite() {
    const std::string path = test::small_pose_database();
    if (path.empty()) return;
    db = std::make_unique<posedb::Database>(posedb::Database::open(path));
    auto truth = load_truth({(test::shared_data() / "mocap" / "cmu31" / "08_01.bvh").string()},
                            db->build_info().fps);
    if (truth.empty()) return;
    truth.front().world.resize(std::min<std::size_t>(truth.front().world.size(), 120));
    experiment = std::make_unique<Experiment>(Experiment{*db, std::move(truth.front())});
  }
  static void TearDownTestSuite() {
    experiment.reset();
    db.reset();
  }
  void SetUp() override {
    if (!experiment) GTEST_SKIP() << "shared mocap clips absent (../shared/data/mocap): no test";
  }
};

std::unique_ptr<posedb::Database> LayoutVirtual::db;
std::unique_ptr<Experiment> LayoutVirtual::experiment;

// In-plane offsets: both corrections win back most of what the layout costs.
TEST_F(LayoutVirtual, CorrectionsUndoAnInPlaneLayout) {
  const LayoutOffsets layout = in_plane_layout();
  const double canonical = experiment->pa_mpjpe(nullptr, Correction::none);
  const double off = experiment->pa_mpjpe(&layout, Correction::none);
  const double input_2d = experiment->pa_mpjpe(&layout, Correction::input_2d);
  const double candidates = experiment->pa_mpjpe(&layout, Correction::candidates);
  ASSERT_GT(off, canonical + 8.0) << "the layout must cost accuracy for the test to mean anything";
  EXPECT_LT(input_2d, canonical + 0.25 * (off - canonical))
      << "canonical " << canonical << " off " << off << " 2D " << input_2d;
  EXPECT_LT(candidates, canonical + 0.25 * (off - canonical))
      << "canonical " << canonical << " off " << off << " candidates " << candidates;
}

// Forward offsets: the 2D correction cannot undo them, the candidates' 3D correction does.
TEST_F(LayoutVirtual, CandidateOffsetsUndoAForwardLayout) {
  const LayoutOffsets layout = forward_layout();
  const double canonical = experiment->pa_mpjpe(nullptr, Correction::none);
  const double off = experiment->pa_mpjpe(&layout, Correction::none);
  const double candidates = experiment->pa_mpjpe(&layout, Correction::candidates);
  ASSERT_GT(off, canonical + 5.0) << "the layout must cost accuracy for the test to mean anything";
  EXPECT_LT(candidates, canonical + 0.25 * (off - canonical))
      << "canonical " << canonical << " off " << off << " candidates " << candidates;
}

}  // namespace
}  // namespace mocap::eval
