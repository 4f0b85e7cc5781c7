#pragma once
// One person's 2D body over time in, a smooth 3D body per frame out: matcher, temporal choice,
// the chosen mocap pose turned into the camera's frame, smoothing. The whole chain as one call,
// for evaluation and offline work; the graph nodes run the same pieces one stage at a time.

#include <array>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "recon/layout_offsets.hpp"
#include "recon/matcher.hpp"
#include "recon/one_euro_filter.hpp"
#include "recon/ray_alignment.hpp"
#include "recon/temporal_selector.hpp"

namespace mocap::recon {

enum class Selection { nearest, greedy, path };
enum class Smoothing { none, one_euro, savitzky_golay };

std::string_view selection_name(Selection s);
std::string_view smoothing_name(Smoothing s);

struct SequenceOptions {
  Selection selection = Selection::greedy;
  SelectorOptions greedy;
  PathOptions path;
  Smoothing smoothing = Smoothing::none;
  OneEuroParams one_euro;
  int sg_order = 3;
  int sg_window = 11;
  double fps = 24.0;
  // With intrinsics, every pose is turned onto the ray through its root's pixel
  // (ray_alignment.hpp); the default camera has none.
  camera::Camera camera;
  // Search yaw and elevation around the matched view for the best fit (view_refinement.hpp).
  bool refine_view = false;
  // The input layout's keypoints moved onto the canonical joints before matching (the scaler's
  // step, layout_offsets.hpp); none: the keypoints are matched as they are. A matcher with a
  // layout (Matcher::set_layout) gets the keypoints as they are whatever this says, and the view
  // refinement and ray alignment then use them moved onto the canonical joints.
  std::optional<LayoutOffsets> layout_offsets;
};

using BodyXyc = std::array<float, kBodyJoints * 3>;  // 15 joints (x, y, confidence), image pixels

struct Pose3D {
  bool valid = false;
  Candidate chosen;
  // Root-relative joints in the camera's frame (x right, y down, z forward), metres.
  std::array<glm::vec3, kBodyJoints> joints{};
  // The body's orientation in the camera frame: the database's facing turned by the view.
  glm::quat body_to_camera{1.0f, 0.0f, 0.0f, 0.0f};
};

// The database pose of `chosen` as seen by its view's camera, or by another `view`.
Pose3D pose_in_camera(const posedb::Database& db, const Candidate& chosen);
Pose3D pose_in_camera(const posedb::Database& db, const Candidate& chosen,
                      const posedb::View& view);
// The same from the view refined against the person's normalised 2D pose `query`.
Pose3D refined_pose_in_camera(const posedb::Database& db, const Candidate& chosen,
                              const posedb::PoseVector& query);

std::vector<Pose3D> reconstruct_sequence(Matcher& matcher, const FrameBones& bones,
                                         std::span<const BodyXyc> frames,
                                         const SequenceOptions& options);

// Turns a database pose onto the ray through its root pixel as `camera` sees it (ray_alignment).
void turn_onto_ray(Pose3D& pose, const camera::Camera& camera, glm::vec2 root_pixel);

// Smooths the joints of valid poses in place (each run of consecutive valid frames on its own).
void smooth_sequence(std::vector<Pose3D>& poses, const SequenceOptions& options);

}  // namespace mocap::recon
