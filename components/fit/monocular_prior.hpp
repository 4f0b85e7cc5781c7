#pragma once
// The monocular retrieval pose as a prior of the multi-view skeleton fit (issue 19: "the
// monocular retrieval pose as a prior where views are few"). For a person-frame, the person's 2D
// keypoints in the view that sees them best go through the monocular pipeline's matcher (same
// database, recon::Matcher); the nearest database pose, seen by that view's camera
// (recon::pose_in_camera) and turned onto the ray through the person's root pixel, is rotated
// into the world. Its bone *directions* become residuals of the fit (scale-free: the retrieved
// skeleton's size does not matter), each weighted by how well the views fix that bone: strong
// where an end joint was triangulated from fewer than two views, or its depth is uncertain (its
// reprojection error magnified by views whose rays meet at a small angle: cameras facing each
// other do not see depth along their common axis); weak where two views fix it; weakest where
// three or more views agree. docs/multiview.md "The monocular prior".

#include <array>
#include <span>
#include <vector>

#include "camera/camera.hpp"
#include "fit/multiview_fit.hpp"
#include "multiview/triangulation.hpp"
#include "posedb/database.hpp"
#include "recon/matcher.hpp"

namespace mocap::fit {

struct MonocularPriorOptions {
  // One sigma (radians, about: the residual is the chord between unit directions) of a fitted
  // bone direction away from the retrieved one, by how well the views fix the bone's two joints.
  // Chosen on HumanEva-I Train (docs/multiview.md "The monocular prior").
  double few_views_rad = 0.1;   // an end from < 2 views, or its depth uncertain
  double two_views_rad = 1.0;   // both ends from two views at a good angle
  double many_views_rad = 3.0;  // both ends from 3+ views that agree; <= 0: no term
  // A point from two views or more is trusted when its depth is known to this (metres): its mean
  // reprojection error in metres at the point (the 2D noise there) over the sine of the largest
  // angle between the rays of the views used (two cameras facing each other, whose rays are
  // nearly parallel, do not see depth along their axis: the noise is magnified). Exact
  // keypoints are trusted at any angle.
  double max_depth_error_m = 0.1;
  // The strong weight needs a run of frames: a bone is weighted few_views_rad only where its
  // ends lacked two good views for at least this many consecutive frames of the track (full
  // mode: the whole run, both sides of the frame; live: the run up to the frame). A shorter run
  // (a joint dropped in a frame or two, which the neighbouring frames and the other views fill)
  // takes two_views_rad. 1: per frame. Chosen on HumanEva-I Train and the virtual scenes of CMU
  // train clips (docs/multiview.md "The monocular prior").
  int few_views_frames = 8;
  // A Cauchy loss on each bone's term, its scale in radians of chord (set in DirectionPrior):
  // beyond it a retrieval facing or bending the wrong way pulls less and less. <= 0: squared.
  double robust_rad = 1.0;
  // Bones of the first kind also start from the retrieved direction instead of the triangulated
  // one (worse on HumanEva Train: off).
  bool few_views_reference = false;
  recon::MatchOptions match;  // the monocular pipeline's defaults
};

// One matcher over `db` (which must outlive this); not thread-safe: one per thread.
class MonocularPrior {
 public:
  MonocularPrior(const posedb::Database& db, MonocularPriorOptions options = {});

  // Sets `frame.prior` (world directions and weights per bone) from the retrieval of the view of
  // `frame.views` that sees the person best (most joints, then the largest 2D box), given the
  // person's triangulated points (`body`, the 15 body joints: views used and errors) and the rig
  // (`cameras`, the views' order). False, and the prior cleared, when no view's keypoints can be
  // matched. Allocates nothing after the first call.
  bool add(MultiViewFrameInput& frame, std::span<const multiview::TriangulatedPoint> body,
           std::span<const camera::Camera> cameras);

  // The inverse sigma of a bone whose two end joints are `parent` and `child` (exposed for tests).
  double bone_weight(const multiview::TriangulatedPoint& parent,
                     const multiview::TriangulatedPoint& child,
                     std::span<const camera::Camera> cameras) const;

  const MonocularPriorOptions& options() const { return options_; }

  // The run rule over one track's consecutive frames (after add() on each; a frame without a
  // prior, e.g. the person unseen, counts as lacking views): a bone marked few
  // (DirectionPrior::few, left as it is) keeps the strong weight only within a run of at least
  // few_views_frames frames, else it takes the two-views weight. past_only (live): a run counts
  // only its frames up to the frame weighed. Settling again (e.g. a longer span of the same track)
  // gives the same weights.
  void settle_runs(std::span<MultiViewFrameInput> track, bool past_only) const;

  // The same, past only, one frame at a time (a stream): `run` holds each bone's frames lacking
  // views up to the frame before (zeros for a new track); `prior` is the newest frame's, or none
  // when the person was not seen.
  using Runs = std::array<int, kBodyJoints - 1>;
  void settle_newest(DirectionPrior* prior, Runs& run) const;

 private:
  float run_weight(std::size_t run) const;  // inverse sigma of a few bone in a run this long

  const posedb::Database& db_;
  MonocularPriorOptions options_;
  recon::Matcher matcher_;
  std::vector<recon::Candidate> candidates_;
};

}  // namespace mocap::fit
