#pragma once
// Views of one moving person that started at different instants: the virtual scenes on which
// frame offsets (camera/frame_offsets.hpp) are tested and measured. The motion is read at
// `steps` x the views' frame rate, so a view can start a fraction of a frame after another.

#include <vector>

#include "camera/camera.hpp"
#include "camera/frame_offsets.hpp"
#include "eval/multiview_scene.hpp"

namespace mocap::eval {

struct ShiftedViews {
  std::vector<camera::Camera> cameras;      // one per scene camera
  std::vector<camera::BodySequence> views;  // one per start
};

// `frames` frames per view of `person` (its motion read at steps x the views' rate) seen by
// `cameras` (one view per entry of `starts`, which must not outnumber them): view v's frame i is
// scene step (i + starts[v]) * steps + phases[v], so view v starts (starts[v] - starts[0]) +
// (phases[v] - phases[0]) / steps frames after view 0. Degraded as `degradation` says.
ShiftedViews shifted_views(const ScenePerson& person, const std::vector<camera::Camera>& cameras,
                           const std::vector<int>& starts, const std::vector<int>& phases,
                           int steps, int frames, const SceneDegradation& degradation,
                           std::uint64_t seed);

}  // namespace mocap::eval
