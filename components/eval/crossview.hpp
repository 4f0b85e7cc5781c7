#pragma once
// Cross-view consistency (the paper's §5.3, ../shared/docs/EVALUATION.md): the same instant
// reconstructed independently from several calibrated views, each view's root-relative pose
// brought into the common world frame with its camera's rotation, and the mean per-joint distance
// between every pair of views, per frame, averaged.
//
// Two alignments are reported. `none`: the camera rotations alone put the poses in one frame, so
// any error in a view's estimate of the body's orientation counts. `vertical_axis`, as
// EVALUATION.md defines the metric: root translation removed, then the rotation about the world's
// vertical axis that best aligns the first pose onto the second (least squares over the joints,
// closed form) is removed too, so only the pose and its lean remain. The root is excluded from
// the mean (it is 0 in both).

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "eval/virtual_protocol.hpp"

namespace mocap::eval {

enum class CrossViewAlignment { none, vertical_axis };

// `camera_root_relative` (camera frame, root-relative) turned into the world frame:
// camera_to_world · joint, root subtracted again.
Body to_world_root_relative(const Body& camera_root_relative, const glm::dmat3& camera_to_world);

// The angle (radians) of the rotation about `up` (unit) that best maps root-relative `from` onto
// `to` in the least-squares sense over the non-root joints.
double vertical_alignment_angle(const Body& from, const Body& to, const glm::dvec3& up);

// Mean distance in metres over the 14 non-root joints between two world-frame poses, both first
// made root-relative and, with `vertical_axis`, `a` turned about `up` onto `b`.
double crossview_distance(const Body& a, const Body& b, const glm::dvec3& up,
                          CrossViewAlignment alignment);

// One pair of views: the sum of per-frame distances (metres) and the frames both had a pose.
struct CrossViewPair {
  std::size_t first = 0, second = 0;
  double sum_m = 0.0;
  double frames = 0.0;
  double mean_cm() const { return 100.0 * sum_m / frames; }
};

// Every pair (i < j) of `views` ([view][frame], world frame; nullopt: no pose that frame),
// scored over the frames both have. Views may differ in length (the shorter one limits a pair).
std::vector<CrossViewPair> crossview_pairs(std::span<const std::vector<std::optional<Body>>> views,
                                           const glm::dvec3& up, CrossViewAlignment alignment);

// Sums pairs of several sequences (same view count) pair by pair, and the mean of all pairs'
// frames together.
void add_pairs(std::vector<CrossViewPair>& total, std::span<const CrossViewPair> more);
double mean_cm(std::span<const CrossViewPair> pairs);

}  // namespace mocap::eval
