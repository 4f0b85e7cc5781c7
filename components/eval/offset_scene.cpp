#include "eval/offset_scene.hpp"

#include <stdexcept>

namespace mocap::eval {

ShiftedViews shifted_views(const ScenePerson& person, const std::vector<camera::Camera>& cameras,
                           const std::vector<int>& starts, const std::vector<int>& phases,
                           int steps, int frames, const SceneDegradation& degradation,
                           std::uint64_t seed) {
  if (starts.size() != phases.size() || starts.size() > cameras.size())
    throw std::invalid_argument("shifted_views: one start and phase per view, a camera each");
  ShiftedViews out;
  out.cameras = cameras;
  SceneRenderer renderer(cameras, seed);
  out.views.resize(starts.size());
  for (std::size_t v = 0; v < starts.size(); ++v) {
    for (int i = 0; i < frames; ++i) {
      const SceneFrame f =
          renderer.render({person}, (i + starts[v]) * steps + phases[v], degradation);
      std::vector<camera::BodyKeypoints>& frame = out.views[v].emplace_back();
      for (const SceneDetection& d : f.views[v]) {
        camera::BodyKeypoints& b = frame.emplace_back();
        for (int k = 0; k < kBodyJoints; ++k)
          b[k] = {d.xyc[3 * k], d.xyc[3 * k + 1], d.xyc[3 * k + 2]};
      }
    }
  }
  return out;
}

}  // namespace mocap::eval
