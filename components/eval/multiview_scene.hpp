#pragma once
// A virtual multi-view scene for testing and measuring the multi-view library
// (components/multiview, ../shared/docs/EVALUATION.md "Multi-view"): mocap people placed together
// in one room, seen by a ring of calibrated cameras, their 2D keypoints degraded like a detector's
// (noise, dropped joints, outlier keypoints, people hiding each other, false detections), and the
// scoring of a reconstruction against the truth (MPJPE, wrong associations, id switches,
// coverage).
//
// World frame: y up, metres (as eval::load_truth gives mocap). Cameras follow OpenCV (x right,
// y down, z forward; x_c = R x_w + t). Keypoints are the 15 body joints (core/body15.hpp).

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camera/camera.hpp"
#include "eval/virtual_protocol.hpp"
#include "multiview/reconstructor.hpp"
#include "multiview/view_geometry.hpp"

namespace mocap::eval {

// `count` cameras evenly spaced on a circle of `radius_m` around the vertical axis through
// `target`, at heights alternating between height_m and height_m + height_step_m, each looking at
// `target`, with `image`'s size and horizontal field of view: pinholes (no distortion) named
// cam_01, cam_02, ... (multiview::from_camera gives a camera's ViewGeometry).
std::vector<camera::Camera> ring_rig(int count, double radius_m, double height_m,
                                     double height_step_m, const glm::dvec3& target,
                                     const Image& image);

// One person of the scene: a mocap motion moved to a place in the room.
struct ScenePerson {
  const TruthSequence* motion = nullptr;
  int first_frame = 0;    // motion frame shown at scene frame 0
  float yaw_deg = 0.0f;   // turn about the vertical through the motion's first root
  glm::vec2 place{0.0f};  // where the motion's first root (x, z) goes on the floor
  // Scene frames during which the person is away (not in the room at all): [leave, back).
  int leave = std::numeric_limits<int>::max();
  int back = std::numeric_limits<int>::max();

  // World joints at a scene frame; nullopt while away or past the motion's end.
  std::optional<Body> at(int frame) const;
};

// Places people (each one's `place` and `yaw_deg`; motions and first frames as given) so that
// during scene frames [0, frames) their roots stay inside the square |x|, |z| <= room_half_m and
// at least min_distance_m apart (horizontally): people share the room and pass each other, as
// people do, without walking through each other. Greedy over a 0.25 m grid of places and eight
// yaws in a seeded order; a person for whom nothing fits gets the placement that keeps the
// largest distance (the return value is then false).
bool spread_people(std::vector<ScenePerson>& people, int frames, float room_half_m,
                   float min_distance_m, std::uint64_t seed);

struct SceneDegradation {
  float noise = 0.0f;     // Gaussian σ as a fraction of the detection's box height
  float dropout = 0.0f;   // chance that a joint is missing
  float outliers = 0.0f;  // chance that a joint is an outlier: half left/right swaps, half jumps
  float jump = 0.25f;     // a jump moves a joint by up to this fraction of the box height
  // Chance per view and frame of a false detection (another person's 2D pose pasted elsewhere).
  float false_detections = 0.0f;
  // People hide each other: a joint behind another person's limb or torso (0.12 m radius) is
  // missing; a person with fewer than min_visible joints in view is not detected.
  bool occlusion = true;
  int min_visible = 6;
  // Views with one bystander each: a person only that view sees, at a fixed place in its image.
  std::vector<int> bystander_views;
};

struct SceneDetection {
  int person = -1;  // index of the scene person shown, -1: false detection or bystander
  std::array<float, kBodyJoints * 3> xyc{};  // pixels, confidence (0: missing)
};

struct SceneFrame {
  std::vector<std::vector<SceneDetection>> views;  // per camera, in a shuffled order
  std::vector<std::optional<Body>> truth;          // per scene person
};

class SceneRenderer {
 public:
  SceneRenderer(std::vector<camera::Camera> cameras, std::uint64_t seed);

  const std::vector<camera::Camera>& cameras() const { return cameras_; }
  SceneFrame render(const std::vector<ScenePerson>& people, int frame,
                    const SceneDegradation& degradation);
  // The frame's detections as the library's input.
  static void to_observations(const SceneFrame& frame, multiview::FrameObservations& out);

 private:
  struct Projected {
    std::array<glm::vec2, kBodyJoints> pixel{};
    std::array<float, kBodyJoints> depth{};
    std::array<bool, kBodyJoints> in_view{};
  };
  Projected project(const camera::Camera& camera, const Body& body) const;
  bool hidden(const camera::Camera& camera, const Projected& who, int joint,
              const std::vector<Projected>& others, std::size_t self) const;
  void degrade(SceneDetection& d, const SceneDegradation& degradation);
  SceneDetection false_detection(const SceneFrame& frame, const camera::Camera& camera);

  std::vector<camera::Camera> cameras_;
  std::mt19937_64 rng_;
  std::normal_distribution<float> gauss_{0.0f, 1.0f};
  std::uniform_real_distribution<float> uniform_{0.0f, 1.0f};
  std::vector<SceneDetection> bystanders_;  // per camera, made on first use
};

// How a reconstruction compares with the scene's truth, summed over frames.
struct SceneScore {
  long person_frames = 0;  // truth people in the room and detected in two views or more
  long reconstructed = 0;  // of those, reconstructed (coverage = reconstructed / person_frames)
  long wrong_associations =
      0;                  // reconstructed people with a detection of another person or a false one
  long false_people = 0;  // reconstructed people made mostly of false detections
  long duplicates = 0;    // truth people reconstructed twice in one frame
  long id_switches = 0;   // a truth person's id changed from one reconstruction to the next
  double joint_error_sum = 0.0;  // metres, over the 15 joints of reconstructed people
  long joints = 0;
  long single_view = 0;  // detections reported as single-view people

  double mpjpe_mm() const { return joints > 0 ? 1000.0 * joint_error_sum / joints : 0.0; }
  double coverage() const {
    return person_frames > 0 ? static_cast<double>(reconstructed) / person_frames : 0.0;
  }
};

// One truth person over the scene's frames (SceneScorer with keep_tracks): the truth where the
// person is in the room, and the joints of the reconstruction matched with them (NaN where none
// was, or a joint was not triangulated), for metrics over time (acceleration, bone lengths).
struct ScenePersonTrack {
  std::vector<std::optional<Body>> truth;
  std::vector<Body> reconstructed;
};

class SceneScorer {
 public:
  explicit SceneScorer(int people, bool keep_tracks = false)
      : last_id_(static_cast<std::size_t>(people), -1),
        keep_tracks_(keep_tracks),
        tracks_(keep_tracks ? static_cast<std::size_t>(people) : 0u) {}
  void add(const SceneFrame& frame, const multiview::FrameResult& result);
  const SceneScore& score() const { return score_; }
  const std::vector<ScenePersonTrack>& tracks() const { return tracks_; }

 private:
  SceneScore score_;
  std::vector<int> last_id_;
  bool keep_tracks_ = false;
  std::vector<ScenePersonTrack> tracks_;  // per truth person, with keep_tracks
};

}  // namespace mocap::eval
