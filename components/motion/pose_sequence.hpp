#pragma once
// Motion as local joint transforms (translation + quaternion per joint per frame): the form that
// forward kinematics, resampling and the pose database work with.

#include <array>
#include <span>
#include <vector>

#include <glm/common.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "motion/skeleton.hpp"

namespace mocap::motion {

struct PoseSequence {
  Skeleton skeleton;
  double fps = 0.0;
  int frame_count = 0;
  // frame_count * joint_count each, row-major by frame. Translation is the joint's position in
  // its parent's frame: the OFFSET, with any position channels replacing the matching component
  // (the convention of MotionBuilder and of every multi-position-channel file seen here).
  std::vector<glm::vec3> translation;
  std::vector<glm::quat> rotation;

  int joint_count() const { return skeleton.joint_count(); }
  size_t at(int frame, int joint) const {
    return static_cast<size_t>(frame) * static_cast<size_t>(joint_count()) +
           static_cast<size_t>(joint);
  }
};

// Rotation channels apply in the order listed: R = R(first) * R(second) * R(third), column vectors.
PoseSequence to_poses(const Clip& clip);
// Back to channel values in the skeleton's own channel order (angles in degrees, in (-180, 180]).
// Joints must have 0 or 3 rotation channels.
Clip to_clip(const PoseSequence& poses);

// Keeps frames [first, first + count) only.
PoseSequence slice(const PoseSequence& poses, int first, int count);

// Resamples to `fps`: frame k is at time k / fps; rotations are slerped along the shorter arc,
// translations interpolated linearly. Keeps the first frame; the last output frame is the last
// one at or before the end of the input.
PoseSequence resample(const PoseSequence& poses, double fps);

// Where output frame k of a resampling lies in the input: `weight` of the way from input frame
// `before` to `after`. The one rule of every resampling in the project (`resample` above).
struct ResampleStep {
  int before = 0;
  int after = 0;
  float weight = 0.0f;
};
std::vector<ResampleStep> resample_steps(int frame_count, double from_fps, double to_fps);

// Resamples frames of points (joint positions, 2D keypoints) by linear interpolation, with the
// same frame times as `resample`.
template <typename Point, std::size_t N>
std::vector<std::array<Point, N>> resample_points(std::span<const std::array<Point, N>> frames,
                                                  double from_fps, double to_fps) {
  std::vector<std::array<Point, N>> out;
  for (const ResampleStep& step :
       resample_steps(static_cast<int>(frames.size()), from_fps, to_fps)) {
    std::array<Point, N>& frame = out.emplace_back();
    for (std::size_t j = 0; j < N; ++j)
      frame[j] = glm::mix(frames[step.before][j], frames[step.after][j], step.weight);
  }
  return out;
}

// Global transforms of every joint (End Sites included) in one frame.
struct GlobalPose {
  std::vector<glm::vec3> position;
  std::vector<glm::quat> rotation;
};
void forward_kinematics(const PoseSequence& poses, int frame, GlobalPose& out);

}  // namespace mocap::motion
