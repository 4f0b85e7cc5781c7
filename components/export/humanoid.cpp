#include "export/humanoid.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "recon/bvh_frame.hpp"
#include "recon/quaternion_distance.hpp"

namespace mocap::exporting {
namespace {

// The ankle joint's height over the floor when the floor is not known.
constexpr float kAnkleHeight_m = 0.08f;
// The head bone (skull base) sits this far from the neck towards the top of the head.
constexpr float kHeadBoneFraction = 0.35f;

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

float length_of(const glm::vec3& v) {
  const float l = glm::length(v);
  return std::isfinite(l) ? l : 0.0f;
}

// The rotation whose `first` axis (0 = x, 1 = y) is along `a`, and whose other of x, y is the
// part of `b` perpendicular to `a`. Identity when the two are degenerate.
glm::quat frame(const glm::vec3& a, const glm::vec3& b, int first) {
  if (!finite(a) || !finite(b) || glm::length(a) < 1e-6f) return {1.0f, 0.0f, 0.0f, 0.0f};
  const glm::vec3 u = glm::normalize(a);
  glm::vec3 v = b - glm::dot(b, u) * u;
  if (glm::length(v) < 1e-6f)
    return recon::swing_rotation(first == 0 ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0), u);
  v = glm::normalize(v);
  const glm::vec3 x = first == 0 ? u : v;
  const glm::vec3 y = first == 0 ? v : u;
  return glm::normalize(glm::quat_cast(glm::mat3(x, y, glm::cross(x, y))));
}

// The swing taking `rest` to `direction` seen from a bone whose global rotation is `parent`.
glm::quat local_swing(const glm::quat& parent, const glm::vec3& rest, const glm::vec3& direction) {
  if (!finite(direction)) return {1.0f, 0.0f, 0.0f, 0.0f};
  return recon::swing_rotation(rest, glm::inverse(parent) * direction);
}

}  // namespace

HumanoidPose humanoid_pose(std::span<const glm::vec3, kBodyJoints> w) {
  using B = HumanBone;
  auto at = [&](Joint j) { return w[index(j)]; };
  auto id = [](B b) { return static_cast<int>(b); };
  const glm::vec3 root = at(Joint::root), neck = at(Joint::neck);
  const glm::vec3 trunk = neck - root;

  std::array<glm::quat, kHumanBones> local;
  local.fill(glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  std::array<glm::vec3, kHumanBones> offset{};

  const glm::quat hips = frame(at(Joint::left_hip) - at(Joint::right_hip), trunk, 0);
  const glm::quat chest = frame(trunk, at(Joint::left_shoulder) - at(Joint::right_shoulder), 1);
  local[id(B::Hips)] = hips;
  local[id(B::Spine)] = glm::normalize(glm::inverse(hips) * chest);
  local[id(B::Neck)] = local_swing(chest, {0, 1, 0}, at(Joint::head) - neck);

  const float half_trunk = 0.5f * length_of(trunk);
  offset[id(B::Chest)] = {0.0f, half_trunk, 0.0f};
  offset[id(B::Neck)] = {0.0f, half_trunk, 0.0f};
  offset[id(B::Head)] = {0.0f, kHeadBoneFraction * length_of(at(Joint::head) - neck), 0.0f};

  // Arms: neck → shoulder (collarbone), shoulder → elbow, elbow → wrist, rest along ±X.
  for (const bool left : {true, false}) {
    const glm::vec3 rest(left ? 1.0f : -1.0f, 0.0f, 0.0f);
    const B shoulder = left ? B::LeftShoulder : B::RightShoulder;
    const B upper = left ? B::LeftUpperArm : B::RightUpperArm;
    const B lower = left ? B::LeftLowerArm : B::RightLowerArm;
    const B hand = left ? B::LeftHand : B::RightHand;
    const glm::vec3 s = at(left ? Joint::left_shoulder : Joint::right_shoulder);
    const glm::vec3 e = at(left ? Joint::left_elbow : Joint::right_elbow);
    const glm::vec3 h = at(left ? Joint::left_wrist : Joint::right_wrist);
    local[id(shoulder)] = local_swing(chest, rest, s - neck);
    const glm::quat g_shoulder = chest * local[id(shoulder)];
    local[id(upper)] = local_swing(g_shoulder, rest, e - s);
    const glm::quat g_upper = g_shoulder * local[id(upper)];
    local[id(lower)] = local_swing(g_upper, rest, h - e);
    offset[id(shoulder)] = {0.0f, half_trunk, 0.0f};
    offset[id(upper)] = rest * length_of(s - neck);
    offset[id(lower)] = rest * length_of(e - s);
    offset[id(hand)] = rest * length_of(h - e);
  }
  // Legs: root → hip (in the Hips bone), hip → knee, knee → ankle, rest along −Y.
  for (const bool left : {true, false}) {
    const glm::vec3 side(left ? 1.0f : -1.0f, 0.0f, 0.0f), down(0.0f, -1.0f, 0.0f);
    const B upper = left ? B::LeftUpperLeg : B::RightUpperLeg;
    const B lower = left ? B::LeftLowerLeg : B::RightLowerLeg;
    const B foot = left ? B::LeftFoot : B::RightFoot;
    const glm::vec3 hip = at(left ? Joint::left_hip : Joint::right_hip);
    const glm::vec3 knee = at(left ? Joint::left_knee : Joint::right_knee);
    const glm::vec3 ankle = at(left ? Joint::left_ankle : Joint::right_ankle);
    local[id(upper)] = local_swing(hips, down, knee - hip);
    local[id(lower)] = local_swing(hips * local[id(upper)], down, ankle - knee);
    offset[id(upper)] = side * length_of(hip - root);
    offset[id(lower)] = down * length_of(knee - hip);
    offset[id(foot)] = down * length_of(ankle - knee);
  }

  HumanoidPose pose;
  const glm::vec3 ground = finite(root) ? glm::vec3(root.x, 0.0f, root.z) : glm::vec3(0.0f);
  offset[id(B::Hips)] = {0.0f, finite(root) ? root.y : 0.0f, 0.0f};
  pose.root_position = to_unity(ground);
  for (int b = 0; b < kHumanBones; ++b) {
    pose.position[b] = to_unity(offset[b]);
    pose.rotation[b] = to_unity(glm::normalize(local[b]));
  }
  return pose;
}

std::array<glm::vec3, kBodyJoints> world_joints(const People3D& people, const Person3D& person) {
  std::array<glm::vec3, kBodyJoints> out;
  const std::optional<recon::BvhPlacement> placement = recon::bvh_placement(people, person);
  // Camera axes (x right, y down, z forward) into the level world (x right, y up, camera on +Z).
  auto level = [](const glm::vec3& p) { return glm::vec3(p.x, -p.y, -p.z); };
  const glm::quat turn = placement ? placement->world_from_level : glm::quat(1, 0, 0, 0);
  for (int j = 0; j < kBodyJoints; ++j)
    out[j] = turn * level(person.positions[j] - person.positions[index(Joint::root)]);
  glm::vec3 root(0.0f);
  if (placement) root = placement->root_m;
  if (!placement || !placement->height_known) {
    const float lowest =
        std::min(out[index(Joint::left_ankle)].y, out[index(Joint::right_ankle)].y);
    root.y = std::isfinite(lowest) ? kAnkleHeight_m - lowest : 0.0f;
  }
  for (glm::vec3& p : out) p += root;
  return out;
}

}  // namespace mocap::exporting
