#pragma once
// The multi-view fit over a whole reconstruction (offline): every track of a sequence of
// MultiViewReconstructor results fitted, live or full, its fitted bodies written over the
// triangulated ones, so that whatever scores or compares the triangulation (eval::SceneScorer,
// the Pose2Sim comparison) scores the fit the same way. Streams use MultiViewPeopleFitter
// (multiview_people_fitter.hpp) instead.

#include <span>
#include <vector>

#include "fit/monocular_prior.hpp"
#include "fit/multiview_fit.hpp"
#include "multiview/observations.hpp"
#include "multiview/reconstructor.hpp"

namespace mocap::fit {

struct TrackFits {
  long tracks = 0;
  long person_frames = 0;  // fitted bodies written
  long prior_frames = 0;   // person-frames with a monocular prior
  FitStats stats;
};

// Fits every track of `results` (the reconstruction of `input` frame by frame, with tracking:
// people with id -1 are left as they are), live (MultiViewLiveFitter, one per track, frames
// pushed in order, a frame the track missed pushed empty) or full (fit_multiview_sequence per
// track), and replaces each fitted person's 15 body points by the fitted joints. `set`: how the
// input's keypoints make the 15 body joints. `prior` (optional): each person-frame also gets the
// monocular retrieval's bone directions (monocular_prior.hpp), weighted by how well the views fix
// each bone; `options.cameras` must then be the views' cameras.
TrackFits fit_tracks(std::span<const multiview::FrameObservations> input,
                     std::vector<multiview::FrameResult>& results,
                     const MultiViewFitOptions& options, bool live,
                     const multiview::KeypointSet& set = multiview::KeypointSet::body15(),
                     MonocularPrior* prior = nullptr);

}  // namespace mocap::fit
