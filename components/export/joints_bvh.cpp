#include "export/joints_bvh.hpp"

#include <cmath>
#include <filesystem>
#include <system_error>

#include <glm/gtx/quaternion.hpp>

#include "core/input_error.hpp"
#include "export/humanoid.hpp"
#include "motion/pose_sequence.hpp"

namespace mocap::exporting {
namespace {

// The humanoid's bones in depth-first order (BVH channel order follows the hierarchy), each with
// the end site after its chain's last bone: -1 marks an end site of the bone before it.
constexpr std::array<int, kHumanBones + 5> kOrder = {
    0,  1,  2,  3,  4,  -1,  // Hips, Spine, Chest, Neck, Head, head top
    5,  6,  7,  8,  -1,      // left arm
    9,  10, 11, 12, -1,      // right arm
    13, 14, 15, -1,          // left leg
    16, 17, 18, -1};         // right leg

HumanoidPose our_axes(const HumanoidPose& unity) {
  HumanoidPose pose = unity;  // to_unity mirrors X: applied twice it is the identity
  pose.root_position = to_unity(unity.root_position);
  for (int b = 0; b < kHumanBones; ++b) {
    pose.position[b] = to_unity(unity.position[b]);
    pose.rotation[b] = to_unity(unity.rotation[b]);
  }
  return pose;
}

motion::Skeleton humanoid_skeleton(const HumanoidPose& rest) {
  using motion::Channel;
  motion::Skeleton skeleton;
  std::array<int, kHumanBones> joint_of{};
  int previous = -1;
  for (const int bone : kOrder) {
    motion::SkeletonJoint joint;
    if (bone < 0) {  // an end site continuing the previous bone's direction
      joint.name = "End Site";
      joint.end_site = true;
      joint.parent = previous;
      const glm::vec3 along = skeleton.joints[static_cast<std::size_t>(previous)].offset;
      const float length = glm::length(along);
      joint.offset = length > 1e-6f ? along * (0.5f / length) * std::min(length, 0.2f)
                                    : glm::vec3(0.0f, 0.05f, 0.0f);
    } else {
      joint.name = std::string(kHumanBoneNames[bone]);
      const int parent = kHumanBoneParent[bone];
      joint.parent = parent < 0 ? -1 : joint_of[parent];
      joint.offset = bone == 0 ? glm::vec3(0.0f) : rest.position[bone];
      if (!std::isfinite(joint.offset.x + joint.offset.y + joint.offset.z))
        joint.offset = glm::vec3(0.0f);
      if (bone == 0) joint.channels = {Channel::Xposition, Channel::Yposition, Channel::Zposition};
      joint.channels.insert(joint.channels.end(),
                            {Channel::Zrotation, Channel::Xrotation, Channel::Yrotation});
      joint_of[bone] = static_cast<int>(skeleton.joints.size());
    }
    previous = static_cast<int>(skeleton.joints.size());
    skeleton.joints.push_back(std::move(joint));
  }
  skeleton.assign_channel_slots();
  return skeleton;
}

// One frame's channel values for the skeleton above.
std::vector<float> frame_values(const motion::Skeleton& skeleton, const HumanoidPose& pose) {
  motion::PoseSequence poses;
  poses.skeleton = skeleton;
  poses.fps = 30.0;
  poses.frame_count = 1;
  for (const int bone : kOrder) {
    if (bone < 0) {
      poses.translation.push_back(glm::vec3(0.0f));
      poses.rotation.push_back(glm::quat(1, 0, 0, 0));
      continue;
    }
    glm::vec3 t = skeleton.joints[poses.translation.size()].offset;
    if (bone == 0) t = pose.root_position + pose.root_rotation * pose.position[0];
    poses.translation.push_back(t);
    glm::quat r = bone == 0 ? pose.root_rotation * pose.rotation[0] : pose.rotation[bone];
    if (!std::isfinite(r.w + r.x + r.y + r.z)) r = glm::quat(1, 0, 0, 0);
    poses.rotation.push_back(r);
  }
  return motion::to_clip(poses).values;
}

}  // namespace

std::array<glm::vec3, kBodyJoints> level_joints(const People3D& people, const Person3D& person) {
  const GroundPlane floor = people.has_ground ? people.ground : GroundPlane{};
  const glm::vec3 normal = glm::normalize(glm::vec3(floor.normal));
  const glm::quat turn = glm::rotation(normal, glm::vec3(0.0f, 1.0f, 0.0f));
  std::array<glm::vec3, kBodyJoints> out = joints_in_frame(person);
  for (glm::vec3& p : out) {
    p = turn * p;
    p.y += static_cast<float>(floor.offset);  // height above the floor: n·p + offset
  }
  return out;
}

JointsBvhWriter::JointsBvhWriter(JointsBvhOptions options) : options_(std::move(options)) {
  std::error_code ec;
  std::filesystem::create_directories(options_.dir, ec);
  if (ec) throw InputError(options_.dir, "cannot create the folder: " + ec.message());
}

std::string JointsBvhWriter::path_for(int id) const {
  return (std::filesystem::path(options_.dir) / (options_.prefix + std::to_string(id) + ".bvh"))
      .string();
}

void JointsBvhWriter::write(const People3D& people) {
  const std::int64_t frame = people.header.frame;
  for (const Person3D& person : people.people) {
    if (!person.placed) continue;
    const std::array<glm::vec3, kBodyJoints> joints = level_joints(people, person);
    const HumanoidPose pose = our_axes(humanoid_pose(joints));
    auto it = people_.find(person.id);
    if (it == people_.end()) {
      motion::BvhStreamWriter writer(path_for(person.id), humanoid_skeleton(pose),
                                     1.0 / options_.fps);
      it = people_.emplace(person.id, Person{std::move(writer), frame - 1, {}}).first;
    }
    Person& p = it->second;
    std::vector<float> values = frame_values(p.writer.skeleton(), pose);
    for (std::int64_t gap = p.last_frame + 1; gap < frame && !p.last_values.empty(); ++gap)
      p.writer.append(p.last_values);  // missed frames repeat the last pose
    p.writer.append(values);
    p.last_values = std::move(values);
    p.last_frame = frame;
  }
}

void JointsBvhWriter::close() {
  std::exception_ptr first;
  for (auto& [id, person] : people_) {
    try {
      person.writer.close();
    } catch (...) {
      if (!first) first = std::current_exception();
    }
  }
  if (first) std::rethrow_exception(first);
}

}  // namespace mocap::exporting
