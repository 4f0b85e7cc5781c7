#pragma once
// Retargeting: a motion on one skeleton (BVH) put onto another skeleton given in its rest pose.
//
// Rest pose of both rigs = their OFFSETs with every rotation zero (any motion of the rig file is
// ignored). Joints correspond by role (pelvis, spine, chest, neck, head, collars, upper arms,
// forearms, hands, index fingers, thighs, shins, feet, toes) through the family mappings of
// body_mapping.hpp, then by identical names, then by an explicit map file. Each mapped target
// joint takes the source joint's world-space orientation change from rest:
//   R_target_world = R_source_world * R_source_rest_world^-1 * A_target
// where A_target is the identity for joints whose rest orientations are taken to agree (both rigs
// face +Z with Y up) and, for joints with one bone (a single nearest mapped descendant on both
// rigs), the swing that turns the target's rest bone onto the source's rest bone. A remaining
// swing per frame makes that bone point exactly like the source's bone even when unmapped source
// joints between the two ends rotate. Unmapped target joints keep their rest (zero) local
// rotation; the next mapped joint absorbs the difference. The pelvis moves by the source's
// pelvis translation times a scale (ratio of hip heights), so a ground at y = 0 stays at y = 0.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "motion/skeleton.hpp"

namespace mocap::motion {

// One line "source_joint target_joint" of a joint map file.
struct JointMapEntry {
  std::string source_joint;
  std::string target_joint;
  long line = 0;
};

struct JointMap {
  std::string path;  // for messages
  std::vector<JointMapEntry> entries;
};

// Reads a map file: one "source_joint target_joint" pair per line; '#' starts a comment; blank
// lines are skipped. Throws InputError naming the file and line.
JointMap read_joint_map(const std::string& path);
// The same from the map file's text; `path` names it in messages.
JointMap parse_joint_map(std::string_view text, const std::string& path);

// Reads a rig: a BVH file, with or without a MOTION section (its frames are not used).
// Throws InputError naming the file.
Skeleton read_rig(const std::string& path);
Skeleton parse_rig(std::string_view text, const std::string& path);

struct RetargetOptions {
  std::optional<float> scale;  // target units per source unit; nullopt: ratio of hip heights
  std::optional<JointMap> map;
  std::string target_source;  // the rig's file name, for messages
  int min_mapped_joints = 5;  // fewer mapped target joints is an error
};

struct JointMatch {
  int source = -1;
  int target = -1;
  std::string how;  // the role ("left_forearm"), "same name" or "map file"
};

// A bone both rigs have: from a mapped joint to its single nearest mapped descendant.
struct MatchedBone {
  int target_from = -1, target_to = -1;
  int source_from = -1, source_to = -1;
};

struct RetargetResult {
  Clip clip;  // the target skeleton with the source's frames and frame time
  std::vector<JointMatch> matches;
  std::vector<int> unmapped_target;  // joints (End Sites excluded) that keep their rest rotation
  std::vector<MatchedBone> bones;
  float scale = 1.0f;
  bool scale_is_auto = true;
  float source_hip_height = 0.0f;  // rest pose, source units (0 when not measurable)
  float target_hip_height = 0.0f;  // rest pose, target units
  // Rest poses that break the method's assumption (Y up, left on +X, standing): e.g. Bandai,
  // whose zero-rotation pose has every bone along its local +X.
  std::vector<std::string> warnings;
};

// Retargets `source` onto `target`. Throws InputError (naming the rig or the map file) when too
// few joints map, a map names an unknown joint, or the scale cannot be found.
RetargetResult retarget(const Clip& source, const Skeleton& target, const RetargetOptions& options);

// The angle (degrees) between each matched bone's direction in the source and in the result, per
// frame: frames * bones values, frame-major. For checking a retarget.
std::vector<float> bone_direction_errors(const Clip& source, const RetargetResult& result);

}  // namespace mocap::motion
