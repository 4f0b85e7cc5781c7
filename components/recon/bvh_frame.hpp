#pragma once
// A reconstructed person as BVH channel values on the mocap skeleton their pose came from: the
// paper's first approach. The database keeps every frame's source rotations; the person's pose
// is that frame, turned to face the matched view's camera.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "motion/body_mapping.hpp"
#include "motion/pose_sequence.hpp"
#include "posedb/database.hpp"
#include "recon/one_euro_filter.hpp"

namespace mocap::recon {

// The database frame and view a person's pose was matched to.
struct DatabasePose {
  std::uint32_t frame = 0;
  std::uint32_t view = 0;
};

// Reads a person's provenance. Returns nullopt when it names no frame or view (negative). Throws
// mocap::InputError naming the database when the frame or view is out of its range or the clip
// name differs from the database's: the pose was matched against another database.
std::optional<DatabasePose> database_pose_of(const posedb::Database& db, const Person3D& person);

// The source skeleton of a database frame's clip; empty (no joints) for motion that was stored as
// joint positions only.
const motion::Skeleton& source_skeleton(const posedb::Database& db, std::uint32_t frame);

// True when values for one skeleton are values for the other: the same tree (parents, End Sites)
// with the same channel lists; names and offsets (bone lengths) may differ.
bool same_hierarchy(const motion::Skeleton& a, const motion::Skeleton& b);

// Where a placed person (recon.fit: root translation estimated) goes in the BVH's world: y up, the
// floor at y = 0 when it is known, the camera on the +Z side looking towards -Z (as the rotations
// are written for a level camera), the origin on the floor below the camera.
struct BvhPlacement {
  glm::quat world_from_level{1.0f, 0.0f, 0.0f, 0.0f};  // corrects the rotations for camera tilt
  glm::vec3 root_m{0.0f};                              // the body root (mid-hips), metres
  bool height_known = false;  // false: no floor, the root height stays the mocap's
};

// The placement of `person` in a frame of `people`; nullopt when the person is not placed. For
// people in a camera's frame (People3D::frame): the level world is made from the camera and the
// floor; a message in the rig's world would already be in one (issue 19's multi-view BVH).
std::optional<BvhPlacement> bvh_placement(const People3D& people, const Person3D& person);

// Writes database poses as channel values for one skeleton (the first clip's, when a person's
// poses come from several clips of the same hierarchy).
class BvhFrameMaker {
 public:
  // `skeleton` must have joints, 0 or 3 rotation channels per joint and a known body mapping
  // (motion::map_to_body); throws InputError naming `source` (the clip) otherwise.
  BvhFrameMaker(const motion::Skeleton& skeleton, const std::string& source);

  const motion::Skeleton& skeleton() const { return pose_.skeleton; }

  // Channel values (skeleton().channel_count, degrees and file units) of database frame `pose`:
  // - every joint's rotation is the database's source rotation for that frame;
  // - the root's is turned as the person is seen from a camera on +Z looking at -Z, y up:
  //   Ry(-view yaw) * Ry(-heading) * R_root, heading being the facing the database removed;
  // - the root's position channels put the body root (mid-hips) at the source root height
  //   (FrameRecord::root_m[1]) and horizontally at 0 (the overload with a placement puts it
  //   where the fitting placed the person);
  // - other position channels keep the skeleton's offsets (the database keeps no others).
  // The frame's clip must have this skeleton's hierarchy (same_hierarchy); throws
  // std::invalid_argument otherwise.
  void channels(const posedb::Database& db, DatabasePose pose, std::vector<float>& values);
  // The same, placed in the world: the root turned by `placement.world_from_level` and the body
  // root at `placement.root_m` (its height the mocap's unless `height_known`).
  void channels(const posedb::Database& db, DatabasePose pose,
                const std::optional<BvhPlacement>& placement, std::vector<float>& values);

  // From now on, channels() smooths every joint's rotation and the root height over successive
  // calls with the 1-Euro filter (on the rotation group), `t_seconds` being the frame's time.
  // Switching between mocap clips otherwise shows as jumps in the file.
  void enable_smoothing(const OneEuroParams& params);
  void channels(const posedb::Database& db, DatabasePose pose, double t_seconds,
                std::vector<float>& values, const std::optional<BvhPlacement>& placement = {});

 private:
  void smooth(double t_seconds);
  std::vector<OneEuroFilterQuat> rotation_filters_;  // empty: no smoothing
  OneEuroFilter height_filter_;
  motion::PoseSequence pose_;  // one frame, reused
  motion::BodyMapping mapping_;
  motion::GlobalPose global_;
};

}  // namespace mocap::recon
