#pragma once
// Calibration from people on a virtual scene (tests/calibration, tools/bench/people_rig_bench):
// mocap people in a room seen by a ring of cameras (eval/multiview_scene.hpp, detector-like 2D),
// their views as the sequences `calibrate_rig_from_people` reads; and how a calibrated rig
// compares with the truth once its world is aligned with the truth's (a similarity fitted to the
// camera centres: our world's origin, heading and scale are our own choice).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "camera/camera.hpp"
#include "camera/frame_offsets.hpp"
#include "eval/multiview_scene.hpp"
#include "eval/procrustes.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "multiview/triangulation.hpp"

namespace mocap::test {

using eval::Body;

struct PeopleRigScene {
  std::vector<camera::Camera> truth;                     // the cameras (world y up, metres)
  std::vector<camera::BodySequence> views;               // per camera, per frame, its detections
  std::vector<std::vector<std::optional<Body>>> people;  // per frame, per person: the truth
  std::vector<std::vector<std::vector<int>>> who;        // per camera, frame, detection: its person
};

// `frames` frames of `people` (placed already) seen by `cameras` cameras on a 4.5 m ring, 1.6 /
// 2.4 m high, looking at the room's centre, 1920x1080 at 60 degrees.
inline PeopleRigScene make_people_rig_scene(const std::vector<eval::ScenePerson>& people,
                                            int cameras, int frames,
                                            const eval::SceneDegradation& degradation,
                                            std::uint64_t seed) {
  const auto ring = eval::ring_rig(cameras, 4.5, 1.6, 0.8, {0.0, 1.0, 0.0}, eval::Image{});
  PeopleRigScene s;
  s.truth = ring;
  eval::SceneRenderer renderer(ring, seed);
  s.views.resize(ring.size());
  s.who.resize(ring.size());
  for (int f = 0; f < frames; ++f) {
    const eval::SceneFrame frame = renderer.render(people, f, degradation);
    s.people.push_back(frame.truth);
    for (std::size_t k = 0; k < ring.size(); ++k) {
      std::vector<camera::BodyKeypoints> detections;
      std::vector<int>& who = s.who[k].emplace_back();
      for (const eval::SceneDetection& d : frame.views[k]) {
        who.push_back(d.person);
        camera::BodyKeypoints& b = detections.emplace_back();
        for (int j = 0; j < kBodyJoints; ++j)
          b[static_cast<std::size_t>(j)] = {d.xyc[3 * j], d.xyc[3 * j + 1], d.xyc[3 * j + 2]};
      }
      s.views[k].push_back(std::move(detections));
    }
  }
  return s;
}

// A calibrated rig against the truth: the similarity from its camera centres to the true ones,
// and per camera the position error (m) and the angle (degrees) between the orientations.
struct RigComparison {
  eval::Similarity to_truth;
  std::vector<double> position_m, angle_deg;
  std::vector<camera::Camera> aligned;  // the calibrated cameras moved into the truth's world
};

inline RigComparison compare_rigs(const std::vector<camera::Camera>& found,
                                  const std::vector<camera::Camera>& truth) {
  RigComparison r;
  std::vector<glm::dvec3> from, to;
  for (std::size_t k = 0; k < found.size(); ++k) {
    from.push_back(found[k].centre());
    to.push_back(truth[k].centre());
  }
  r.to_truth = eval::procrustes(from, to);
  for (std::size_t k = 0; k < found.size(); ++k) {
    camera::Camera c = found[k];
    // p_truth = s Q p + T: the camera's rotation from the truth's world is R Qᵀ.
    const glm::dmat3 rotation = found[k].rotation * glm::transpose(r.to_truth.rotation);
    c.set_pose_from_centre(glm::transpose(rotation), r.to_truth.apply(found[k].centre()));
    r.aligned.push_back(c);
    r.position_m.push_back(glm::distance(c.centre(), truth[k].centre()));
    const glm::dmat3 d = glm::transpose(truth[k].rotation) * c.rotation;
    const double cosine = std::clamp((d[0][0] + d[1][1] + d[2][2] - 1.0) / 2.0, -1.0, 1.0);
    r.angle_deg.push_back(std::acos(cosine) * 180.0 / std::acos(-1.0));
  }
  return r;
}

// Each person's joints triangulated from every view's detection of them (the scene's association,
// least squares, undistorted pixels) with `cameras`; per frame and person, NaN where fewer than two
// views saw a joint.
inline std::vector<std::vector<Body>> triangulate_scene(const std::vector<camera::Camera>& cameras,
                                                        const PeopleRigScene& s) {
  std::vector<multiview::ViewGeometry> geometry;
  for (const camera::Camera& c : cameras) geometry.push_back(multiview::from_camera(c));
  const float nan = std::nanf("");
  std::vector<std::vector<Body>> out;
  for (std::size_t f = 0; f < s.people.size(); ++f) {
    std::vector<Body>& frame = out.emplace_back(s.people[f].size());
    for (std::size_t p = 0; p < s.people[f].size(); ++p)
      for (int j = 0; j < kBodyJoints; ++j) {
        std::vector<multiview::PointObservation> seen;
        for (std::size_t k = 0; k < cameras.size(); ++k)
          for (std::size_t d = 0; d < s.views[k][f].size(); ++d) {
            if (s.who[k][f][d] != static_cast<int>(p)) continue;
            const Keypoint2D& kp = s.views[k][f][d][static_cast<std::size_t>(j)];
            if (!(kp.confidence > 0)) continue;
            seen.push_back({static_cast<int>(k), kp.x, kp.y, kp.confidence});
          }
        const auto point =
            seen.size() >= 2 ? multiview::triangulate_least_squares(geometry, seen) : std::nullopt;
        frame[p][static_cast<std::size_t>(j)] =
            point ? glm::vec3(*point) : glm::vec3(nan, nan, nan);
      }
  }
  return out;
}

}  // namespace mocap::test
