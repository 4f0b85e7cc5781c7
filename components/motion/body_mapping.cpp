#include "motion/body_mapping.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <vector>

#include "core/input_error.hpp"

namespace mocap::motion {
namespace {

// CMU's FAQ: ASF length units are inches scaled by 0.45.
constexpr float kCmuMetresPerUnit = (1.0f / 0.45f) * 2.54f / 100.0f;

struct NamedSource {
  const char* joint;
  const char* other = nullptr;  // midpoint partner
  glm::vec3 local_offset{0.0f};
  bool end_site_of_joint = false;  // the End Site child of `joint`
};

using FamilyTable = std::array<NamedSource, kBodyJoints>;

// Body15 order: head, neck, r_sho, r_elb, r_wri, l_sho, l_elb, l_wri, r_hip, r_kne, r_ank,
// l_hip, l_kne, l_ank, root.
const FamilyTable kCmu31 = {{
    {"Head", nullptr, {}, true},  // top of the head: the Head End Site
    {"Neck1"},                    // base of the neck just above the shoulder line
    {"RightArm"},
    {"RightForeArm"},
    {"RightHand"},
    {"LeftArm"},
    {"LeftForeArm"},
    {"LeftHand"},
    {"RightUpLeg"},
    {"RightLeg"},
    {"RightFoot"},
    {"LeftUpLeg"},
    {"LeftLeg"},
    {"LeftFoot"},
    {"LeftUpLeg", "RightUpLeg"},
}};

// CMU's own ASF/AMC: a joint sits at the start of the bone of the same name.
const FamilyTable kCmuAsf = {{
    {"head", nullptr, {}, true},  // top of the head: the end of the head bone
    {"upperneck"},
    {"rhumerus"},
    {"rradius"},
    {"rwrist"},
    {"lhumerus"},
    {"lradius"},
    {"lwrist"},
    {"rfemur"},
    {"rtibia"},
    {"rfoot"},
    {"lfemur"},
    {"ltibia"},
    {"lfoot"},
    {"lfemur", "rfemur"},
}};

const FamilyTable kCmuDaz = {{
    {"leftEye", "rightEye"},  // eye level: the figure has no head-top point
    {"neck"},
    {"rShldr"},
    {"rForeArm"},
    {"rHand"},
    {"lShldr"},
    {"lForeArm"},
    {"lHand"},
    {"rThigh"},
    {"rShin"},
    {"rFoot"},
    {"lThigh"},
    {"lShin"},
    {"lFoot"},
    {"lThigh", "rThigh"},
}};

const FamilyTable kBandai = {{
    {"Head", nullptr, {10.0f, 0.0f, 0.0f}},  // head top: 10 cm along Head's bone axis (+X)
    {"Neck"},
    {"UpperArm_R"},
    {"LowerArm_R"},
    {"Hand_R"},
    {"UpperArm_L"},
    {"LowerArm_L"},
    {"Hand_L"},
    {"UpperLeg_R"},
    {"LowerLeg_R"},
    {"Foot_R"},
    {"UpperLeg_L"},
    {"LowerLeg_L"},
    {"Foot_L"},
    {"UpperLeg_L", "UpperLeg_R"},
}};

// Names other exporters use (Mixamo, MotionBuilder, Blender rigs), tried for unknown skeletons.
// Names are compared without case, separators or a "prefix:" namespace.
const std::array<std::vector<const char*>, kBodyJoints> kGenericNames = {{
    {"head", "headtop", "head_end"},
    {"neck1", "neck", "upperneck"},
    {"rightarm", "rshldr", "upperarmr", "rupperarm", "rightupperarm", "rshoulder", "rhumerus"},
    {"rightforearm", "rforearm", "lowerarmr", "rlowerarm", "rightlowerarm", "relbow", "rradius"},
    {"righthand", "rhand", "handr", "rwrist"},
    {"leftarm", "lshldr", "upperarml", "lupperarm", "leftupperarm", "lshoulder", "lhumerus"},
    {"leftforearm", "lforearm", "lowerarml", "llowerarm", "leftlowerarm", "lelbow", "lradius"},
    {"lefthand", "lhand", "handl", "lwrist"},
    {"rightupleg", "rthigh", "upperlegr", "rupperleg", "rightupperleg", "rhip", "rfemur"},
    {"rightleg", "rshin", "lowerlegr", "rlowerleg", "rightlowerleg", "rknee", "rtibia"},
    {"rightfoot", "rfoot", "footr", "rankle"},
    {"leftupleg", "lthigh", "upperlegl", "lupperleg", "leftupperleg", "lhip", "lfemur"},
    {"leftleg", "lshin", "lowerlegl", "llowerleg", "leftlowerleg", "lknee", "ltibia"},
    {"leftfoot", "lfoot", "footl", "lankle"},
    {},  // root: midpoint of the hips, filled in below
}};

bool has_all(const Skeleton& s, std::initializer_list<const char*> names) {
  return std::all_of(names.begin(), names.end(), [&](const char* n) { return s.find(n) >= 0; });
}

int end_site_of(const Skeleton& s, int joint) {
  for (int j = joint + 1; j < s.joint_count(); ++j) {
    if (s.joints[j].parent == joint && s.joints[j].end_site) return j;
  }
  return -1;
}

BodyMapping from_table(const Skeleton& s, const FamilyTable& table, Family family,
                       const std::string& source) {
  BodyMapping m;
  m.family = family;
  for (int b = 0; b < kBodyJoints; ++b) {
    const NamedSource& n = table[b];
    BodyJointSource& out = m.joints[b];
    out.joint = s.find(n.joint);
    if (out.joint >= 0 && n.end_site_of_joint) out.joint = end_site_of(s, out.joint);
    if (n.other) out.other = s.find(n.other);
    out.local_offset = n.local_offset;
    if (out.joint < 0 || (n.other && out.other < 0)) {
      throw InputError(source, std::string("skeleton looks like the ") +
                                   std::string(family_name(family)) + " family but has no joint '" +
                                   n.joint + "' for body joint '" + std::string(kJointNames[b]) +
                                   "'");
    }
  }
  return m;
}

int find_generic(const Skeleton& s, const std::vector<const char*>& names) {
  for (const char* wanted : names) {
    for (int j = 0; j < s.joint_count(); ++j) {
      if (!s.joints[j].end_site && fold_joint_name(s.joints[j].name) == wanted) return j;
    }
  }
  return -1;
}

// Unknown units: pick the scale that makes thigh + shin closest to an adult's 0.85 m.
float guess_metres_per_unit(const Skeleton& s, const BodyMapping& m) {
  auto chain_length = [&](int from, int to) {
    float length = 0.0f;
    for (int j = to; j >= 0 && j != from; j = s.joints[j].parent)
      length += glm::length(s.joints[j].offset);
    return length;
  };
  const float leg = chain_length(m.joints[index(Joint::left_hip)].joint,
                                 m.joints[index(Joint::left_ankle)].joint);
  const float candidates[] = {1.0f, 0.01f, 0.001f, 0.0254f, kCmuMetresPerUnit};
  float best = 1.0f, best_error = 1e30f;
  for (float c : candidates) {
    const float error = std::abs(std::log(std::max(leg * c, 1e-9f) / 0.85f));
    if (error < best_error) best_error = error, best = c;
  }
  return best;
}

BodyMapping generic_mapping(const Skeleton& s, const std::string& source) {
  BodyMapping m;
  m.family = Family::generic;
  std::string missing;
  for (int b = 0; b < kBodyJoints - 1; ++b) {
    m.joints[b].joint = find_generic(s, kGenericNames[b]);
    if (m.joints[b].joint < 0)
      missing += (missing.empty() ? "" : ", ") + std::string(kJointNames[b]);
  }
  if (!missing.empty()) {
    throw InputError(
        source, "cannot map this skeleton to the 15-joint body: no joint found for " + missing +
                    " (known families: cmu31 cgspeed, cmu_daz, bandai; other skeletons need "
                    "common joint names such as LeftArm, LeftForeArm, LeftHand, LeftUpLeg)");
  }
  // A head joint is at the base of the skull: use its End Site (the top) when it has one.
  const int head = m.joints[index(Joint::head)].joint;
  if (const int top = end_site_of(s, head); top >= 0) m.joints[index(Joint::head)].joint = top;
  m.joints[index(Joint::root)] = {
      m.joints[index(Joint::left_hip)].joint, m.joints[index(Joint::right_hip)].joint, {}};
  m.metres_per_unit = guess_metres_per_unit(s, m);
  m.notes = "generic skeleton mapped by joint names; units guessed from the leg length (" +
            std::to_string(m.metres_per_unit) + " m per unit)";
  return m;
}

}  // namespace

std::string fold_joint_name(std::string_view name) {
  if (const auto colon = name.rfind(':'); colon != std::string_view::npos)
    name.remove_prefix(colon + 1);
  std::string out;
  for (char c : name) {
    if (std::isalnum(static_cast<unsigned char>(c)))
      out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  return out;
}

std::string_view family_name(Family f) {
  switch (f) {
    case Family::cmu31:
      return "cmu31";
    case Family::cmu_asf:
      return "cmu_asf";
    case Family::cmu_daz:
      return "cmu_daz";
    case Family::bandai:
      return "bandai";
    case Family::generic:
      return "generic";
  }
  return "?";
}

BodyMapping map_to_body(const Skeleton& s, const std::string& source) {
  if (has_all(s,
              {"Hips", "LHipJoint", "RHipJoint", "LowerBack", "Spine1", "Neck1", "LeftForeArm"})) {
    BodyMapping m = from_table(s, kCmu31, Family::cmu31, source);
    m.metres_per_unit = kCmuMetresPerUnit;
    m.first_frame_is_reference = true;
    m.notes =
        "cgspeed CMU: head = Head End Site (top of head), neck = Neck1, root = midpoint of the "
        "UpLeg joints";
    return m;
  }
  if (has_all(s, {"lhipjoint", "lfemur", "ltibia", "lhumerus", "lradius", "upperneck", "head"})) {
    BodyMapping m = from_table(s, kCmuAsf, Family::cmu_asf, source);
    m.metres_per_unit = kCmuMetresPerUnit;
    m.notes =
        "CMU ASF/AMC: head = end of the head bone, neck = upperneck, root = midpoint of the femur "
        "starts";
    return m;
  }
  if (has_all(s, {"hip", "abdomen", "chest", "rShldr", "lShldr", "rThigh", "lThigh", "leftEye"})) {
    BodyMapping m = from_table(s, kCmuDaz, Family::cmu_daz, source);
    m.metres_per_unit = 0.01f;
    m.first_frame_is_reference = true;
    m.notes =
        "cgspeed Daz: head = midpoint of the eyes (no head-top point), root = midpoint of the "
        "thighs";
    return m;
  }
  if (has_all(s, {"joint_Root", "Hips", "UpperArm_L", "LowerArm_R", "UpperLeg_L", "Toes_R"})) {
    BodyMapping m = from_table(s, kBandai, Family::bandai, source);
    m.metres_per_unit = 0.01f;
    m.notes =
        "Bandai: head = Head + 10 cm along its bone axis (head top), root = midpoint of the "
        "UpperLeg joints";
    return m;
  }
  return generic_mapping(s, source);
}

void body_positions(const BodyMapping& m, const GlobalPose& pose,
                    std::array<glm::vec3, kBodyJoints>& out) {
  for (int b = 0; b < kBodyJoints; ++b) {
    const BodyJointSource& src = m.joints[b];
    glm::vec3 p = pose.position[src.joint];
    if (src.other >= 0) p = 0.5f * (p + pose.position[src.other]);
    if (src.local_offset != glm::vec3(0.0f)) p += pose.rotation[src.joint] * src.local_offset;
    out[b] = p * m.metres_per_unit;
  }
}

float reference_stature_m(const Clip& clip, const BodyMapping& mapping) {
  if (!mapping.first_frame_is_reference || clip.frame_count < 1) return 0.0f;
  const PoseSequence poses = slice(to_poses(clip), 0, 1);
  GlobalPose pose;
  forward_kinematics(poses, 0, pose);
  std::array<glm::vec3, kBodyJoints> body;
  body_positions(mapping, pose, body);
  float lowest = std::numeric_limits<float>::max();
  for (const glm::vec3& p : pose.position) lowest = std::min(lowest, p.y * mapping.metres_per_unit);
  return body[index(Joint::head)].y - lowest;
}

bool is_blank_frame(const Clip& clip, int frame) {
  const float* row = clip.frame(frame);
  return std::all_of(row, row + clip.skeleton.channel_count, [](float v) { return v == 0.0f; });
}

}  // namespace mocap::motion
