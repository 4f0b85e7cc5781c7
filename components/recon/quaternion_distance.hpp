#pragma once
// Distances between rotations, and between poses given as sets of rotations: the measure the
// temporal selector compares candidate motions with (Lee et al. 2002, "Interactive control of
// avatars animated with human motion data", §4.1).
//
// Bones. Skeletons of different mocap sources have different rest poses and local frames, so their
// joint rotations cannot be compared directly. bone_rotations() therefore describes a pose of the
// 15-joint body by one rotation per bone: the smallest rotation (the "swing", no twist about the
// bone) taking the bone's canonical rest direction to its direction in the pose. Two poses of any
// skeletons then compare bone by bone. Bone b runs from joint kJointParent[b] to joint b, so the
// 14 bones are indexed by their child joint (root, the last joint, ends no bone).
//
// Rest pose: a T-pose in the pose database's frame, y up and facing +Z, hence the person's left
// is +X. Spine (root→neck) and head (neck→head) point +Y; left collarbone, upper arm and forearm
// +X, right ones −X; left pelvis half (root→left_hip) +X, right one −X; thighs and shins −Y.
// The rotations are global (not relative to the parent bone) and live in the frame of the joints
// given, so compare poses expressed in the same frame, e.g. the database's heading-removed one.
// Camera coordinates (y down, z forward) are that frame turned half a turn about X: map
// (x, y, z) → (x, −y, −z) first, or compare camera-frame poses only with each other.

#include <array>
#include <span>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/body15.hpp"

namespace mocap::recon {

inline constexpr int kBodyBones = kBodyJoints - 1;
static_assert(kJointParent[kBodyJoints - 1] == -1, "bone b ends at joint b: the root must be last");

using BoneRotations = std::array<glm::quat, kBodyBones>;

// The canonical rest direction of each bone (unit vectors; see the header comment).
inline constexpr std::array<glm::vec3, kBodyBones> kBoneRestDirection = {
    glm::vec3(0, 1, 0),   // head: neck → head
    glm::vec3(0, 1, 0),   // neck: root → neck (the spine)
    glm::vec3(-1, 0, 0),  // right_shoulder: neck → right_shoulder (collarbone)
    glm::vec3(-1, 0, 0),  // right_elbow: upper arm
    glm::vec3(-1, 0, 0),  // right_wrist: forearm
    glm::vec3(1, 0, 0),   // left_shoulder
    glm::vec3(1, 0, 0),   // left_elbow
    glm::vec3(1, 0, 0),   // left_wrist
    glm::vec3(-1, 0, 0),  // right_hip: root → right_hip (pelvis)
    glm::vec3(0, -1, 0),  // right_knee: thigh
    glm::vec3(0, -1, 0),  // right_ankle: shin
    glm::vec3(1, 0, 0),   // left_hip
    glm::vec3(0, -1, 0),  // left_knee
    glm::vec3(0, -1, 0),  // left_ankle
};

// Lee et al. weigh the rotations of the shoulders, elbows, hips, knees, pelvis and spine with 1
// and all others with 0. On the 15-joint body a joint's rotation moves the bone below it: the
// shoulder turns the upper arm, the elbow the forearm, the hip the thigh, the knee the shin, the
// pelvis the two pelvis halves, the spine the root → neck bone. Head and collarbones get 0.
inline constexpr std::array<float, kBodyBones> kLeeBoneWeights = {
    0, 1,     // head, spine
    0, 1, 1,  // right collarbone, upper arm, forearm
    0, 1, 1,  // left
    1, 1, 1,  // right pelvis half, thigh, shin
    1, 1, 1,  // left
};

// Angle in radians, in [0, π], of the rotation taking q1 to q2 (the angle of q1⁻¹·q2): the
// geodesic distance between the two rotations. q and −q are the same rotation and give the same
// value. Accurate near 0 and π (atan2 of the relative quaternion's vector and scalar parts, never
// acos of a dot product); the inputs need not be exactly unit length.
float quaternion_distance(const glm::quat& q1, const glm::quat& q2);

// Lee et al.'s weighted pose distance: Σ_j w_j · d(a_j, b_j)², d = quaternion_distance.
// Lee et al. write ‖log(a_j⁻¹ b_j)‖², whose quaternion logarithm is half the rotation angle; using
// the full angle multiplies every distance by 4 and changes no comparison. Squaring (rather than
// summing the angles) follows the paper and makes one badly wrong joint count more than several
// slightly wrong ones. Throws std::invalid_argument when the three sizes differ.
float pose_distance(std::span<const glm::quat> a, std::span<const glm::quat> b,
                    std::span<const float> weights);

// The smallest rotation taking direction `from` to direction `to` (neither needs unit length).
// Opposite directions: half a turn about the part of +Z perpendicular to `from` (about +X when
// `from` is along Z), so the choice is deterministic; for the rest directions above that is +Z.
// A zero-length or non-finite input gives the identity.
glm::quat swing_rotation(const glm::vec3& from, const glm::vec3& to);

// One swing rotation per bone (see the header comment). `joints` holds the 15 joints as x, y, z
// in Body15 order, e.g. posedb::Database::joints(). A bone of zero length or with a non-finite
// end gets the identity: give it weight 0 when comparing.
BoneRotations bone_rotations(std::span<const float, kBodyJoints * 3> joints);
BoneRotations bone_rotations(std::span<const glm::vec3, kBodyJoints> joints);

}  // namespace mocap::recon
