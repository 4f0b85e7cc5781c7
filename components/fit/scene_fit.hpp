#pragma once
// The multi-view fit on a reconstructed virtual scene (eval/multiview_scene.hpp; library
// mocap_fit_eval): the scene's cameras as the one camera model, and every track of a
// reconstruction fitted, its fitted bodies written over the triangulated ones so that
// eval::SceneScorer scores them as it scores the triangulation.

#include <span>
#include <vector>

#include "eval/multiview_scene.hpp"
#include "fit/multiview_fit.hpp"

namespace mocap::fit {

// The scene's cameras (no distortion), named cam_01, cam_02, ...
std::vector<camera::Camera> scene_cameras(std::span<const eval::SceneCamera> cameras);

struct TrackFits {
  long tracks = 0;
  long person_frames = 0;  // fitted bodies written
  FitStats stats;
};

// Fits every track of `results` (the reconstruction of `input` frame by frame, with tracking:
// people with id -1 are left as they are), live (MultiViewLiveFitter, one per track, frames
// pushed in order, a frame the track missed pushed empty) or full (fit_multiview_sequence per
// track), and replaces each fitted person's 15 body points by the fitted joints.
TrackFits fit_tracks(std::span<const multiview::FrameObservations> input,
                     std::vector<multiview::FrameResult>& results,
                     const MultiViewFitOptions& options, bool live);

}  // namespace mocap::fit
