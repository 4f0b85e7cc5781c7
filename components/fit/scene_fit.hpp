#pragma once
// The multi-view fit on a reconstructed virtual scene (eval/multiview_scene.hpp; its cameras are
// the one camera model, camera::Camera) and every track of a reconstruction
// fitted (fit_tracks, track_fit.hpp), its fitted bodies written over the triangulated ones so
// that eval::SceneScorer scores them as it scores the triangulation.

#include "eval/multiview_scene.hpp"
#include "fit/multiview_fit.hpp"
#include "fit/track_fit.hpp"

namespace mocap::fit {}  // namespace mocap::fit
