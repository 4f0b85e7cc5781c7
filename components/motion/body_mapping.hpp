#pragma once
// Mocap skeleton families and how each one is mapped onto the internal 15-joint body.
// The families are the ones in ../shared/data/mocap (see its README): the cgspeed CMU
// conversion (31 joints), the cgspeed Daz conversion (43 joints) and Bandai Namco (22 joints).
// Other skeletons are mapped by common joint names when they have them.

#include <array>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "motion/pose_sequence.hpp"

namespace mocap::motion {

enum class Family { cmu31, cmu_asf, cmu_daz, bandai, generic };

std::string_view family_name(Family f);

// A joint name as the name tables compare it: without a namespace prefix ("mixamorig:"), letters
// and digits only, lower case ("Left_UpLeg" -> "leftupleg").
std::string fold_joint_name(std::string_view name);

// Where one body joint sits on a skeleton: at a joint, at the midpoint of two joints, and/or
// displaced by an offset in the first joint's local frame (file units).
struct BodyJointSource {
  int joint = -1;
  int other = -1;  // >= 0: midpoint of `joint` and `other`
  glm::vec3 local_offset{0.0f};
};

struct BodyMapping {
  Family family = Family::generic;
  std::array<BodyJointSource, kBodyJoints> joints;
  float metres_per_unit = 1.0f;
  // Frame 0 of the file is an inserted reference pose, not capture data (the cgspeed files).
  bool first_frame_is_reference = false;
  std::string notes;  // how derived joints were made, for `db info` and reports
};

// Recognises the family and builds the mapping. Throws InputError(source, ...) naming the body
// joints it cannot find when the skeleton is of no known family and its names do not tell.
BodyMapping map_to_body(const Skeleton& skeleton, const std::string& source);

// The 15 body joints (metres) of one frame whose global pose is `pose`.
void body_positions(const BodyMapping& mapping, const GlobalPose& pose,
                    std::array<glm::vec3, kBodyJoints>& out);

// A subject's standing height, floor to top of head (metres), from a file whose frame 0 is an
// upright reference pose (`first_frame_is_reference`, the cgspeed CMU files' T-pose): the body's
// head (top of the head) above the lowest joint or End Site of that frame (the toes' End Site)
// along y (BVH up). 0 when the file has no reference frame.
float reference_stature_m(const Clip& clip, const BodyMapping& mapping);

// True when every channel value of the frame is zero: not capture data (cgspeed 07_12, 09_10).
bool is_blank_frame(const Clip& clip, int frame);

}  // namespace mocap::motion
