#include "recon/bvh_frame.hpp"

#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "core/input_error.hpp"

namespace mocap::recon {
namespace {

std::string another_database(const Person3D& person, const std::string& what) {
  return "person " + std::to_string(person.id) + ": " + what +
         "; was the pose matched against another database?";
}

void require_bvh_channels(const motion::Skeleton& skeleton, const std::string& source) {
  for (const motion::SkeletonJoint& joint : skeleton.joints) {
    int rotations = 0;
    for (motion::Channel c : joint.channels) rotations += motion::is_rotation(c) ? 1 : 0;
    if (rotations != 0 && rotations != 3) {
      throw InputError(source, "joint " + joint.name + " has " + std::to_string(rotations) +
                                   " rotation channels; BVH output needs 0 or 3");
    }
  }
}

}  // namespace

std::optional<DatabasePose> database_pose_of(const posedb::Database& db, const Person3D& person) {
  const Provenance& p = person.provenance;
  if (p.frame < 0 || p.view < 0) return std::nullopt;
  if (static_cast<std::uint64_t>(p.frame) >= db.frames().size()) {
    throw InputError(db.path(),
                     another_database(person, "database frame " + std::to_string(p.frame) +
                                                  " is beyond the database's " +
                                                  std::to_string(db.frames().size())));
  }
  if (static_cast<std::size_t>(p.view) >= db.views().size()) {
    throw InputError(db.path(), another_database(person, "view " + std::to_string(p.view) +
                                                             " is beyond the database's " +
                                                             std::to_string(db.views().size())));
  }
  const auto frame = static_cast<std::uint32_t>(p.frame);
  const std::string& clip = db.clips()[db.frames()[frame].clip].name;
  if (!p.clip.empty() && p.clip != clip) {
    throw InputError(db.path(), another_database(person, "database frame " + std::to_string(frame) +
                                                             " is in clip '" + clip +
                                                             "', the pose says '" + p.clip + "'"));
  }
  return DatabasePose{frame, static_cast<std::uint32_t>(p.view)};
}

const motion::Skeleton& source_skeleton(const posedb::Database& db, std::uint32_t frame) {
  return db.clips()[db.frames()[frame].clip].skeleton;
}

// The structure decides, not the names: the cgspeed 2008 release names two finger joints
// LFingers/RFingers where the 2010 one says LeftHandIndex1/RightHandIndex1, in the same tree.
bool same_hierarchy(const motion::Skeleton& a, const motion::Skeleton& b) {
  if (a.joint_count() != b.joint_count()) return false;
  for (int j = 0; j < a.joint_count(); ++j) {
    const motion::SkeletonJoint& x = a.joints[j];
    const motion::SkeletonJoint& y = b.joints[j];
    if (x.parent != y.parent || x.end_site != y.end_site || x.channels != y.channels) {
      return false;
    }
  }
  return true;
}

BvhFrameMaker::BvhFrameMaker(const motion::Skeleton& skeleton, const std::string& source) {
  if (skeleton.joints.empty())
    throw InputError(source, "no skeleton (motion stored as joint positions only): no BVH output");
  require_bvh_channels(skeleton, source);
  pose_.skeleton = skeleton;
  pose_.skeleton.assign_channel_slots();
  pose_.fps = 1.0;  // one frame at a time: the rate is never written
  pose_.frame_count = 1;
  pose_.translation.resize(skeleton.joints.size());
  pose_.rotation.resize(skeleton.joints.size());
  mapping_ = motion::map_to_body(pose_.skeleton, source);
}

std::optional<BvhPlacement> bvh_placement(const People3D& people, const Person3D& person) {
  if (!person.placed) return std::nullopt;
  // Camera axes (x right, y down, z forward) into the level world (x right, y up, camera on +Z).
  const glm::mat3 level_from_camera(glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, -1));
  BvhPlacement out;
  if (!people.has_ground) {
    out.root_m = level_from_camera * person.root.translation;
    return out;
  }
  // World axes in camera coordinates: up is the floor's normal, -Z the camera's forward direction
  // along the floor.
  const glm::vec3 up = glm::normalize(glm::vec3(people.ground.normal));
  const glm::vec3 forward(0.0f, 0.0f, 1.0f);
  glm::vec3 along = forward - glm::dot(forward, up) * up;
  if (glm::length(along) < 1e-3f) along = glm::vec3(0.0f, 1.0f, 0.0f);  // looking straight down
  const glm::vec3 z = -glm::normalize(along);
  const glm::vec3 x = glm::cross(up, z);
  const glm::mat3 world_from_camera = glm::transpose(glm::mat3(x, up, z));  // rows x, up, z
  out.root_m = world_from_camera * person.root.translation;
  out.root_m.y += static_cast<float>(people.ground.offset);  // the height over the floor
  out.height_known = true;
  out.world_from_level = glm::quat_cast(world_from_camera * glm::transpose(level_from_camera));
  return out;
}

void BvhFrameMaker::channels(const posedb::Database& db, DatabasePose pose,
                             std::vector<float>& values) {
  channels(db, pose, std::nullopt, values);
}

void BvhFrameMaker::channels(const posedb::Database& db, DatabasePose pose,
                             const std::optional<BvhPlacement>& placement,
                             std::vector<float>& values) {
  if (pose.frame >= db.frames().size() || pose.view >= db.views().size())
    throw std::out_of_range("BvhFrameMaker: database frame or view out of range");
  const posedb::FrameRecord& record = db.frames()[pose.frame];
  if (!same_hierarchy(source_skeleton(db, pose.frame), pose_.skeleton))
    throw std::invalid_argument("BvhFrameMaker: the frame's clip has another skeleton");
  const std::span<const float> q = db.rotations(pose.frame);
  const motion::Skeleton& skeleton = pose_.skeleton;
  const float yaw = glm::radians(db.views()[pose.view].yaw_deg);
  glm::quat turn = glm::angleAxis(-(yaw + record.heading_rad), glm::vec3(0, 1, 0));
  if (placement) turn = placement->world_from_level * turn;
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const auto at = static_cast<std::size_t>(j) * 4;
    const glm::quat source(q[at], q[at + 1], q[at + 2], q[at + 3]);
    const bool root = skeleton.joints[j].parent < 0;
    pose_.rotation[j] = root ? turn * source : source;
    pose_.translation[j] = root ? glm::vec3(0.0f) : skeleton.joints[j].offset;
  }
  // Global positions move with the root translation one for one: measure the body root with the
  // roots at 0, then shift them so that it lands at the source height above the origin.
  motion::forward_kinematics(pose_, 0, global_);
  std::array<glm::vec3, kBodyJoints> body;
  motion::body_positions(mapping_, global_, body);
  const glm::vec3 body_root = body[index(Joint::root)];
  glm::vec3 target(0.0f, record.root_m[1], 0.0f);
  if (placement) {
    target.x = placement->root_m.x;
    target.z = placement->root_m.z;
    if (placement->height_known) target.y = placement->root_m.y;
  }
  const glm::vec3 shift = (target - body_root) / mapping_.metres_per_unit;
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    if (skeleton.joints[j].parent < 0) pose_.translation[j] = shift;
  }
  values = motion::to_clip(pose_).values;
}

void BvhFrameMaker::enable_smoothing(const OneEuroParams& params) {
  rotation_filters_.assign(static_cast<std::size_t>(pose_.skeleton.joint_count()),
                           OneEuroFilterQuat(params));
  height_filter_ = OneEuroFilter(params);
}

void BvhFrameMaker::channels(const posedb::Database& db, DatabasePose pose, double t_seconds,
                             std::vector<float>& values,
                             const std::optional<BvhPlacement>& placement) {
  if (rotation_filters_.empty()) {
    channels(db, pose, placement, values);
    return;
  }
  channels(db, pose, placement, values);  // fills pose_ with this frame's rotations and root
  smooth(t_seconds);
  values = motion::to_clip(pose_).values;
}

void BvhFrameMaker::smooth(double t_seconds) {
  for (int j = 0; j < pose_.skeleton.joint_count(); ++j) {
    pose_.rotation[j] =
        rotation_filters_[static_cast<std::size_t>(j)].filter(t_seconds, pose_.rotation[j]);
    if (pose_.skeleton.joints[j].parent < 0) {
      glm::vec3& root = pose_.translation[j];
      root.y = static_cast<float>(height_filter_.filter(t_seconds, root.y));
    }
  }
}

}  // namespace mocap::recon
