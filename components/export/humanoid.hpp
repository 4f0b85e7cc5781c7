#pragma once
// The 15-joint body (docs/body15.md) as a Unity humanoid pose, for the VMC live link
// (docs/live-link.md).
//
// The humanoid's hierarchy and rest pose are Unity's (and VRM's normalised one): a T-pose facing
// +Z with every local rotation the identity, so a bone's local rotation is the whole of its pose:
//
//   Hips ─ Spine ─ Chest ─ Neck ─ Head
//                    ├─ LeftShoulder ─ LeftUpperArm ─ LeftLowerArm ─ LeftHand     (and Right...)
//   Hips ─ LeftUpperLeg ─ LeftLowerLeg ─ LeftFoot                                 (and Right...)
//
// Which joints drive which bone:
// - Hips: the pelvis frame, x along the hip line (right hip → left hip), y the trunk (root → neck)
//   made perpendicular to it;
// - Spine: the chest frame (y the trunk, x the shoulder line made perpendicular) relative to the
//   pelvis: the trunk's twist and bend; Chest: identity (one trunk segment only);
// - Neck: the swing taking the rest +Y to neck → head (top); Head: identity (no face points);
// - Left/RightShoulder: the swing of the collarbone (neck → shoulder) from its rest ±X;
// - Upper arm, lower arm, upper leg, lower leg: the swing (no twist about the bone) taking the
//   bone's rest direction (arms ±X, legs −Y) to its direction, in the parent bone's frame;
// - Hands, Feet: identity (no hand or toe points).
// Local positions are the rest offsets with this body's bone lengths (Hips: its height above the
// floor point under it), so that forward kinematics through the humanoid gives back the joints.
//
// Axes: the body comes in our world (right-handed, +Y up, metres, the floor at y = 0); Unity is
// left-handed +Y up. The conversion mirrors X: positions (x, y, z) → (−x, y, z), quaternions
// (x, y, z, w) → (x, −y, −z, w). Our rest pose faces +Z with its left hand at +X; after the mirror
// it faces +Z with its left hand at −X, as Unity's humanoid does.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "core/messages.hpp"

namespace mocap::exporting {

enum class HumanBone : std::uint8_t {
  Hips,
  Spine,
  Chest,
  Neck,
  Head,
  LeftShoulder,
  LeftUpperArm,
  LeftLowerArm,
  LeftHand,
  RightShoulder,
  RightUpperArm,
  RightLowerArm,
  RightHand,
  LeftUpperLeg,
  LeftLowerLeg,
  LeftFoot,
  RightUpperLeg,
  RightLowerLeg,
  RightFoot,
};
inline constexpr int kHumanBones = 19;

// Unity's HumanBodyBones names, as VMC sends them.
inline constexpr std::array<std::string_view, kHumanBones> kHumanBoneNames = {
    "Hips",          "Spine",         "Chest",         "Neck",         "Head",
    "LeftShoulder",  "LeftUpperArm",  "LeftLowerArm",  "LeftHand",     "RightShoulder",
    "RightUpperArm", "RightLowerArm", "RightHand",     "LeftUpperLeg", "LeftLowerLeg",
    "LeftFoot",      "RightUpperLeg", "RightLowerLeg", "RightFoot"};

// Parent of each bone in the hierarchy above, -1 for Hips.
inline constexpr std::array<int, kHumanBones> kHumanBoneParent = {
    -1, 0,  1,  2,  3,  // Hips, Spine, Chest, Neck, Head
    2,  5,  6,  7,      // left arm from the Chest
    2,  9,  10, 11,     // right arm
    0,  13, 14,         // left leg from the Hips
    0,  16, 17};        // right leg

// A pose in Unity's coordinates: `root` is the floor point under the hips (the avatar's root
// object), bones are relative to their parent (Hips to the root).
struct HumanoidPose {
  glm::vec3 root_position{0.0f};
  glm::quat root_rotation{1.0f, 0.0f, 0.0f, 0.0f};
  std::array<glm::vec3, kHumanBones> position{};
  std::array<glm::quat, kHumanBones> rotation{};
};

// The humanoid pose of 15 joints in our world (right-handed, +Y up, metres, floor y = 0).
// Bones of zero length or with non-finite ends get the identity rotation.
HumanoidPose humanoid_pose(std::span<const glm::vec3, kBodyJoints> world);

// A reconstructed person's 15 joints in our world: placed people (recon.fit) where the fitting
// put them, the floor at y = 0 (recon::bvh_placement's world, the camera on +Z looking at −Z);
// others with the root above the origin, at the height that puts the lower ankle 8 cm above the
// floor.
std::array<glm::vec3, kBodyJoints> world_joints(const People3D& people, const Person3D& person);

// Right-handed Y-up → Unity (left-handed Y-up): X mirrored.
inline glm::vec3 to_unity(const glm::vec3& p) { return {-p.x, p.y, p.z}; }
inline glm::quat to_unity(const glm::quat& q) { return glm::quat(q.w, q.x, -q.y, -q.z); }

}  // namespace mocap::exporting
