#pragma once
// From components/multiview's result to the multi-view fit's input (multiview_fit.hpp): what a
// multi-view node calls per frame set and reconstructed person.

#include <cstddef>

#include "fit/multiview_fit.hpp"
#include "multiview/observations.hpp"
#include "multiview/reconstructor.hpp"

namespace mocap::fit {

// Person `person` of `result`: its detection's keypoints in every view that has one (the 15 body
// joints made from the keypoint set as `set` says: a keypoint, or the midpoint of two) and its
// triangulated body. Camera indices are the views' (the rig's order). Contacts are left false.
// Reuses `out`'s memory.
void multiview_input(const multiview::FrameObservations& frame,
                     const multiview::FrameResult& result, std::size_t person,
                     const multiview::KeypointSet& set, MultiViewFrameInput& out);

}  // namespace mocap::fit
