#include "motion/pose_sequence.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/gtx/euler_angles.hpp>

namespace mocap::motion {
namespace {

glm::quat axis_rotation(Channel c, float degrees) {
  const float r = glm::radians(degrees);
  switch (c) {
    case Channel::Xrotation:
      return glm::angleAxis(r, glm::vec3(1, 0, 0));
    case Channel::Yrotation:
      return glm::angleAxis(r, glm::vec3(0, 1, 0));
    case Channel::Zrotation:
      return glm::angleAxis(r, glm::vec3(0, 0, 1));
    default:
      return glm::quat(1, 0, 0, 0);
  }
}

// Euler angles (radians) of `q` for the rotation order of the joint's three rotation channels.
glm::vec3 euler_for_order(const glm::quat& q, const Channel order[3]) {
  const glm::mat4 m = glm::mat4_cast(q);
  float a = 0, b = 0, c = 0;
  auto is = [&](Channel x, Channel y, Channel z) {
    return order[0] == x && order[1] == y && order[2] == z;
  };
  using enum Channel;
  if (is(Xrotation, Yrotation, Zrotation))
    glm::extractEulerAngleXYZ(m, a, b, c);
  else if (is(Xrotation, Zrotation, Yrotation))
    glm::extractEulerAngleXZY(m, a, b, c);
  else if (is(Yrotation, Xrotation, Zrotation))
    glm::extractEulerAngleYXZ(m, a, b, c);
  else if (is(Yrotation, Zrotation, Xrotation))
    glm::extractEulerAngleYZX(m, a, b, c);
  else if (is(Zrotation, Xrotation, Yrotation))
    glm::extractEulerAngleZXY(m, a, b, c);
  else if (is(Zrotation, Yrotation, Xrotation))
    glm::extractEulerAngleZYX(m, a, b, c);
  else
    throw std::invalid_argument("to_clip: rotation channels must name three different axes");
  return {a, b, c};
}

// Frame times are written with few digits (cgspeed: ".0083333"); 120.0005 fps is meant as 120.
// Snapping keeps integer resampling ratios exact. Rates like 29.97 are kept as they are.
double snap_frame_rate(double fps) {
  const double nearest = std::round(fps);
  return std::abs(fps - nearest) < 1e-4 * fps ? nearest : fps;
}

}  // namespace

PoseSequence to_poses(const Clip& clip) {
  PoseSequence out;
  out.skeleton = clip.skeleton;
  out.fps = snap_frame_rate(clip.fps());
  out.frame_count = clip.frame_count;
  const int joints = clip.skeleton.joint_count();
  out.translation.resize(static_cast<size_t>(clip.frame_count) * joints);
  out.rotation.resize(static_cast<size_t>(clip.frame_count) * joints);
  for (int f = 0; f < clip.frame_count; ++f) {
    const float* row = clip.frame(f);
    for (int j = 0; j < joints; ++j) {
      const SkeletonJoint& joint = clip.skeleton.joints[j];
      glm::vec3 t = joint.offset;
      glm::quat r(1, 0, 0, 0);
      for (size_t c = 0; c < joint.channels.size(); ++c) {
        const float v = row[joint.first_channel + c];
        switch (joint.channels[c]) {
          case Channel::Xposition:
            t.x = v;
            break;
          case Channel::Yposition:
            t.y = v;
            break;
          case Channel::Zposition:
            t.z = v;
            break;
          default:
            r = r * axis_rotation(joint.channels[c], v);
            break;
        }
      }
      out.translation[out.at(f, j)] = t;
      out.rotation[out.at(f, j)] = glm::normalize(r);
    }
  }
  return out;
}

Clip to_clip(const PoseSequence& poses) {
  Clip clip;
  clip.skeleton = poses.skeleton;
  clip.skeleton.assign_channel_slots();
  clip.frame_time = 1.0 / poses.fps;
  clip.frame_count = poses.frame_count;
  clip.values.assign(static_cast<size_t>(poses.frame_count) * clip.skeleton.channel_count, 0.0f);
  for (int f = 0; f < poses.frame_count; ++f) {
    float* row = clip.frame(f);
    for (int j = 0; j < poses.joint_count(); ++j) {
      const SkeletonJoint& joint = clip.skeleton.joints[j];
      Channel order[3];
      int rotations = 0;
      for (Channel c : joint.channels) {
        if (is_rotation(c)) {
          if (rotations == 3)
            throw std::invalid_argument("to_clip: joint " + joint.name +
                                        " has more than three rotation channels");
          order[rotations++] = c;
        }
      }
      if (rotations != 0 && rotations != 3) {
        throw std::invalid_argument("to_clip: joint " + joint.name +
                                    " needs 0 or 3 rotation channels");
      }
      const glm::vec3 t = poses.translation[poses.at(f, j)];
      glm::vec3 angles(0.0f);
      if (rotations == 3)
        angles = glm::degrees(euler_for_order(poses.rotation[poses.at(f, j)], order));
      int next_angle = 0;
      for (size_t c = 0; c < joint.channels.size(); ++c) {
        float& v = row[joint.first_channel + c];
        switch (joint.channels[c]) {
          case Channel::Xposition:
            v = t.x;
            break;
          case Channel::Yposition:
            v = t.y;
            break;
          case Channel::Zposition:
            v = t.z;
            break;
          default:
            v = angles[next_angle++];
            break;
        }
      }
    }
  }
  return clip;
}

PoseSequence slice(const PoseSequence& poses, int first, int count) {
  if (first < 0 || count < 0 || first + count > poses.frame_count) {
    throw std::out_of_range("slice: frames out of range");
  }
  PoseSequence out;
  out.skeleton = poses.skeleton;
  out.fps = poses.fps;
  out.frame_count = count;
  const auto begin = poses.at(first, 0), end = poses.at(first + count, 0);
  out.translation.assign(poses.translation.begin() + begin, poses.translation.begin() + end);
  out.rotation.assign(poses.rotation.begin() + begin, poses.rotation.begin() + end);
  return out;
}

std::vector<ResampleStep> resample_steps(int frame_count, double from_fps, double to_fps) {
  if (!(from_fps > 0.0) || !(to_fps > 0.0))
    throw std::invalid_argument("resample: frame rates must be positive");
  std::vector<ResampleStep> steps;
  if (frame_count <= 0) return steps;
  const double step = from_fps / to_fps;  // input frames per output frame
  // A tiny tolerance so that 120 -> 24 fps lands exactly on every 5th frame.
  const int count = static_cast<int>(std::floor((frame_count - 1) / step + 1e-9)) + 1;
  steps.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    const double s = k * step;
    const int a = std::min(static_cast<int>(std::floor(s + 1e-9)), frame_count - 1);
    const int b = std::min(a + 1, frame_count - 1);
    steps.push_back({a, b, static_cast<float>(std::max(0.0, s - a))});
  }
  return steps;
}

PoseSequence resample(const PoseSequence& poses, double fps) {
  const std::vector<ResampleStep> steps = resample_steps(poses.frame_count, poses.fps, fps);
  PoseSequence out;
  out.skeleton = poses.skeleton;
  out.fps = fps;
  out.frame_count = static_cast<int>(steps.size());
  const int joints = poses.joint_count();
  out.translation.resize(static_cast<size_t>(out.frame_count) * joints);
  out.rotation.resize(static_cast<size_t>(out.frame_count) * joints);
  for (int k = 0; k < out.frame_count; ++k) {
    const auto [a, b, w] = steps[static_cast<std::size_t>(k)];
    for (int j = 0; j < joints; ++j) {
      const glm::quat qa = poses.rotation[poses.at(a, j)];
      glm::quat qb = poses.rotation[poses.at(b, j)];
      if (glm::dot(qa, qb) < 0.0f) qb = -qb;
      out.translation[out.at(k, j)] =
          glm::mix(poses.translation[poses.at(a, j)], poses.translation[poses.at(b, j)], w);
      out.rotation[out.at(k, j)] = w < 1e-6f ? qa : glm::normalize(glm::slerp(qa, qb, w));
    }
  }
  return out;
}

void forward_kinematics(const PoseSequence& poses, int frame, GlobalPose& out) {
  const int joints = poses.joint_count();
  out.position.resize(joints);
  out.rotation.resize(joints);
  for (int j = 0; j < joints; ++j) {
    const int parent = poses.skeleton.joints[j].parent;
    const glm::vec3 t = poses.translation[poses.at(frame, j)];
    const glm::quat r = poses.rotation[poses.at(frame, j)];
    if (parent < 0) {
      out.position[j] = t;
      out.rotation[j] = r;
    } else {
      out.position[j] = out.position[parent] + out.rotation[parent] * t;
      out.rotation[j] = out.rotation[parent] * r;
    }
  }
}

}  // namespace mocap::motion
