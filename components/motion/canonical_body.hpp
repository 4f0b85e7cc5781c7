#pragma once
// One canonical body for every mocap family (../shared/docs/SKELETONS.md): the proportions of the
// 15-joint body (14 bone lengths, the shoulders' placement against the trunk) and the retargeting
// that puts a pose of any family on given proportions while keeping its bone directions.

#include <array>
#include <span>
#include <string>

#include <glm/vec3.hpp>

#include "core/body15.hpp"

namespace mocap::motion {

using Body15 = std::array<glm::vec3, kBodyJoints>;

// The proportions of a 15-joint body, in metres.
struct BodyProportions {
  // bone_m[j]: length of the bone from kJointParent[j] to j (the 14 bones; bone_m[root] = 0).
  // bone_m[right_hip] = bone_m[left_hip] is half the hip width (the hips sit symmetric about the
  // root), bone_m[*_shoulder] the neck-to-shoulder distance, bone_m[head] neck to head top.
  std::array<float, kBodyJoints> bone_m{};
  // Angle between the trunk (root -> neck) and neck -> shoulder: 90 degrees = shoulders level
  // with the neck point, more = below it.
  float shoulder_angle_rad = 0.0f;

  float hip_width_m() const { return 2.0f * bone_m[index(Joint::right_hip)]; }
  float shoulder_width_m() const;  // between the shoulder joints when re-hung at the angle
  float total_bone_m() const;      // sum of the 14 bones
};

// The canonical body: every bone at the median length of the CMU cgspeed train split (subjects
// 01, 03, 08, 09, 86, 91 at 24 fps, left and right pooled), the shoulders at its median angle.
// Head = top of the head and neck = Neck1, as in body15.md. body_mapping_test recomputes these
// numbers from ../shared/data/mocap/cmu31 (measure_proportions) and checks they agree.
const BodyProportions& canonical_proportions();

// The joint span: the bones that stack up from ankle to top of head when standing (head, trunk,
// thigh, shin; left and right averaged), metres. What a calibration from people measures of a
// person's size (calibration/people_calibration.hpp).
float joint_span_m(const BodyProportions& proportions);

// A person's standing height (floor to top of head) over their joint span: the median over the
// cmu31 train subjects (01, 03, 08, 09, 86, 91; the first train file of each) of the stature in
// the subject's reference T-pose (motion::reference_stature_m: the head End Site, top of the head,
// above the lowest toe End Site) over the joint span of that pose: 1.0123 to 1.0196, median
// 1.0175 (stature 1.31 to 1.53 m, as ../shared/data/mocap/README.md lists the spans). It holds
// the ankle's height over the toes and the legs' and neck's slant. The skeletons have no heel and
// the toe End Site is not the sole, so a measured stature may be somewhat larger than this one
// (not measured: no subject's measured height is in ../shared). Recomputed by
// CanonicalBody.StatureOverJointSpanAgreesWithCmuTrain.
inline constexpr float kStatureOverJointSpan = 1.0175f;

// The canonical body's standing height: kStatureOverJointSpan x its joint span.
float canonical_stature_m();

// Medians over the frames of each bone length and of the shoulder angle. With `symmetric` the
// left and right bones of a pair are pooled (one length for both sides). Frames with non-finite
// joints are left out; all lengths are 0 when no frame is usable.
BodyProportions measure_proportions(std::span<const Body15> frames, bool symmetric = true);

// The bone lengths and shoulder angle of one pose.
BodyProportions proportions_of(const Body15& body);

// Puts `body` on `proportions`: the root stays, every bone keeps its direction and gets its
// length, walking out from the root; the shoulders are re-hung from the neck at the proportions'
// angle to the trunk, turned about the trunk as the source shoulders are (a shrug forward or
// back is kept); the hips are placed symmetric about the root along the source's hip line.
// A zero-length source bone (no direction) keeps its source offset.
Body15 retarget(const Body15& body, const BodyProportions& proportions);

// One line naming the proportions, for database records and reports.
std::string describe(const BodyProportions& proportions);

}  // namespace mocap::motion
