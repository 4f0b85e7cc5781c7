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
  //   (FrameRecord::root_m[1]) and horizontally at 0: no translation is estimated yet;
  // - other position channels keep the skeleton's offsets (the database keeps no others).
  // The frame's clip must have this skeleton's hierarchy (same_hierarchy); throws
  // std::invalid_argument otherwise.
  void channels(const posedb::Database& db, DatabasePose pose, std::vector<float>& values);

  // From now on, channels() smooths every joint's rotation and the root height over successive
  // calls with the 1-Euro filter (on the rotation group), `t_seconds` being the frame's time.
  // Switching between mocap clips otherwise shows as jumps in the file.
  void enable_smoothing(const OneEuroParams& params);
  void channels(const posedb::Database& db, DatabasePose pose, double t_seconds,
                std::vector<float>& values);

 private:
  void smooth(double t_seconds);
  std::vector<OneEuroFilterQuat> rotation_filters_;  // empty: no smoothing
  OneEuroFilter height_filter_;
  motion::PoseSequence pose_;  // one frame, reused
  motion::BodyMapping mapping_;
  motion::GlobalPose global_;
};

}  // namespace mocap::recon
