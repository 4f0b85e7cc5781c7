#include "motion/retarget.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/input_error.hpp"
#include "motion/body_mapping.hpp"
#include "motion/bvh.hpp"
#include "motion/pose_sequence.hpp"

namespace mocap::motion {
namespace {

// The joints a retarget matches by role. Left and right sides in the same order.
enum class Role : int {
  pelvis,
  spine,
  chest,
  neck,
  head,
  left_collar,
  left_upper_arm,
  left_forearm,
  left_hand,
  left_index,
  left_thigh,
  left_shin,
  left_foot,
  left_toe,
  right_collar,
  right_upper_arm,
  right_forearm,
  right_hand,
  right_index,
  right_thigh,
  right_shin,
  right_foot,
  right_toe,
  count
};
constexpr int kRoles = static_cast<int>(Role::count);
constexpr std::array<const char*, kRoles> kRoleNames = {
    "pelvis",          "spine",          "chest",        "neck",        "head",
    "left_collar",     "left_upper_arm", "left_forearm", "left_hand",   "left_index",
    "left_thigh",      "left_shin",      "left_foot",    "left_toe",    "right_collar",
    "right_upper_arm", "right_forearm",  "right_hand",   "right_index", "right_thigh",
    "right_shin",      "right_foot",     "right_toe"};

// Roles that are joints of the 15-joint body: taken from the family mapping (body_mapping).
constexpr std::array<std::pair<Role, Joint>, 13> kBodyRoles = {{
    {Role::neck, Joint::neck},
    {Role::left_upper_arm, Joint::left_shoulder},
    {Role::left_forearm, Joint::left_elbow},
    {Role::left_hand, Joint::left_wrist},
    {Role::left_thigh, Joint::left_hip},
    {Role::left_shin, Joint::left_knee},
    {Role::left_foot, Joint::left_ankle},
    {Role::right_upper_arm, Joint::right_shoulder},
    {Role::right_forearm, Joint::right_elbow},
    {Role::right_hand, Joint::right_wrist},
    {Role::right_thigh, Joint::right_hip},
    {Role::right_shin, Joint::right_knee},
    {Role::right_foot, Joint::right_ankle},
}};

struct ExtraRole {
  Role role;
  std::vector<const char*> names;  // first present wins
};

// The roles the 15-joint body does not have, per family (exact names; see
// ../shared/data/mocap/README.md and the Bandai README).
std::vector<ExtraRole> extra_roles(Family family) {
  switch (family) {
    case Family::cmu31:
      return {{Role::pelvis, {"Hips"}},
              {Role::spine, {"Spine"}},
              {Role::chest, {"Spine1"}},
              {Role::head, {"Head"}},
              {Role::left_collar, {"LeftShoulder"}},
              {Role::right_collar, {"RightShoulder"}},
              {Role::left_index, {"LeftHandIndex1", "LFingers"}},
              {Role::right_index, {"RightHandIndex1", "RFingers"}},
              {Role::left_toe, {"LeftToeBase"}},
              {Role::right_toe, {"RightToeBase"}}};
    case Family::cmu_asf:
      return {{Role::pelvis, {"root"}},           {Role::spine, {"lowerback"}},
              {Role::chest, {"upperback"}},       {Role::head, {"head"}},
              {Role::left_collar, {"lclavicle"}}, {Role::right_collar, {"rclavicle"}},
              {Role::left_index, {"lfingers"}},   {Role::right_index, {"rfingers"}},
              {Role::left_toe, {"ltoes"}},        {Role::right_toe, {"rtoes"}}};
    case Family::cmu_daz:
      return {{Role::pelvis, {"hip"}},          {Role::spine, {"abdomen"}},
              {Role::chest, {"chest"}},         {Role::head, {"head"}},
              {Role::left_collar, {"lCollar"}}, {Role::right_collar, {"rCollar"}},
              {Role::left_index, {"lIndex1"}},  {Role::right_index, {"rIndex1"}}};
    case Family::bandai:
      return {{Role::pelvis, {"Hips"}},
              {Role::spine, {"Spine"}},
              {Role::chest, {"Chest"}},
              {Role::head, {"Head"}},
              {Role::left_collar, {"Shoulder_L"}},
              {Role::right_collar, {"Shoulder_R"}},
              {Role::left_toe, {"Toes_L"}},
              {Role::right_toe, {"Toes_R"}}};
    case Family::generic:
      // Compared without case or separators (fold_joint_name).
      return {
          {Role::pelvis, {"hips", "hip", "pelvis"}},
          {Role::spine, {"spine", "abdomen", "spine01", "spinelower"}},
          {Role::chest, {"chest", "spine2", "spine1", "spine02", "upperchest"}},
          {Role::head, {"head"}},
          {Role::left_collar, {"leftshoulder", "lcollar", "lclavicle", "claviclel", "shoulderl"}},
          {Role::right_collar, {"rightshoulder", "rcollar", "rclavicle", "clavicler", "shoulderr"}},
          {Role::left_index, {"lefthandindex1", "lindex1", "leftindex1", "index1l"}},
          {Role::right_index, {"righthandindex1", "rindex1", "rightindex1", "index1r"}},
          {Role::left_toe, {"lefttoebase", "lefttoe", "ltoe", "toesl", "toel", "ltoes"}},
          {Role::right_toe, {"righttoebase", "righttoe", "rtoe", "toesr", "toer", "rtoes"}}};
  }
  return {};
}

int find_joint(const Skeleton& s, const char* name, bool folded) {
  for (int j = 0; j < s.joint_count(); ++j) {
    if (s.joints[j].end_site) continue;
    if (folded ? fold_joint_name(s.joints[j].name) == name : s.joints[j].name == name) return j;
  }
  return -1;
}

// The joint of each role on a skeleton (-1 where it has none). Throws InputError from
// map_to_body when the skeleton cannot be mapped onto the body.
std::array<int, kRoles> roles_of(const Skeleton& s, const std::string& source) {
  std::array<int, kRoles> out;
  out.fill(-1);
  const BodyMapping body = map_to_body(s, source);
  for (const auto& [role, joint] : kBodyRoles) {
    const BodyJointSource& src = body.joints[index(joint)];
    if (src.joint >= 0 && src.other < 0 && src.local_offset == glm::vec3(0.0f) &&
        !s.joints[src.joint].end_site)
      out[static_cast<int>(role)] = src.joint;
  }
  for (const ExtraRole& extra : extra_roles(body.family)) {
    for (const char* name : extra.names) {
      const int j = find_joint(s, name, body.family == Family::generic);
      if (j >= 0) {
        out[static_cast<int>(extra.role)] = j;
        break;
      }
    }
  }
  if (out[static_cast<int>(Role::pelvis)] < 0) out[static_cast<int>(Role::pelvis)] = 0;
  return out;
}

// Rest pose (zero rotations): world positions in file units.
std::vector<glm::vec3> rest_positions(const Skeleton& s) {
  std::vector<glm::vec3> p(s.joints.size());
  for (int j = 0; j < s.joint_count(); ++j) {
    const int parent = s.joints[j].parent;
    p[j] = (parent < 0 ? glm::vec3(0.0f) : p[parent]) + s.joints[j].offset;
  }
  return p;
}

bool is_descendant(const Skeleton& s, int joint, int ancestor) {
  for (int j = s.joints[joint].parent; j >= 0; j = s.joints[j].parent)
    if (j == ancestor) return true;
  return false;
}

// The rotation that turns direction u onto direction v by the shortest arc.
glm::quat swing(glm::vec3 u, glm::vec3 v) {
  const float lu = glm::length(u), lv = glm::length(v);
  if (lu < 1e-9f || lv < 1e-9f) return glm::quat(1, 0, 0, 0);
  u /= lu;
  v /= lv;
  const float d = glm::dot(u, v);
  if (d < -0.999999f) {
    glm::vec3 axis = glm::cross(glm::vec3(1, 0, 0), u);
    if (glm::length(axis) < 1e-3f) axis = glm::cross(glm::vec3(0, 1, 0), u);
    return glm::angleAxis(glm::pi<float>(), glm::normalize(axis));
  }
  const glm::vec3 c = glm::cross(u, v);
  return glm::normalize(glm::quat(1.0f + d, c.x, c.y, c.z));
}

// Rest height of the pelvis above the sole, measured along the legs: the pelvis' drop to the
// thigh, thigh and shin lengths, the ankle's height above the lowest point below it. The mean of
// both legs; 0 when the roles are missing.
float hip_height(const Skeleton& s, const std::array<int, kRoles>& roles) {
  const std::vector<glm::vec3> p = rest_positions(s);
  const int pelvis = roles[static_cast<int>(Role::pelvis)];
  float sum = 0.0f;
  int legs = 0;
  for (auto [thigh_role, shin_role, foot_role] :
       {std::array{Role::left_thigh, Role::left_shin, Role::left_foot},
        std::array{Role::right_thigh, Role::right_shin, Role::right_foot}}) {
    const int thigh = roles[static_cast<int>(thigh_role)];
    const int shin = roles[static_cast<int>(shin_role)];
    const int foot = roles[static_cast<int>(foot_role)];
    if (pelvis < 0 || thigh < 0 || shin < 0 || foot < 0) continue;
    float lowest = p[foot].y;
    for (int j = foot + 1; j < s.joint_count(); ++j)
      if (is_descendant(s, j, foot)) lowest = std::min(lowest, p[j].y);
    sum += (p[pelvis].y - p[thigh].y) + glm::length(p[shin] - p[thigh]) +
           glm::length(p[foot] - p[shin]) + (p[foot].y - lowest);
    ++legs;
  }
  if (legs > 0) return sum / static_cast<float>(legs);
  // No legs known: the pelvis' height above the lowest rest point.
  float lowest = p[pelvis].y;
  for (const glm::vec3& q : p) lowest = std::min(lowest, q.y);
  return p[pelvis].y - lowest;
}

std::string trim_comment(const std::string& line) {
  const auto hash = line.find('#');
  return hash == std::string::npos ? line : line.substr(0, hash);
}

// Says when a rig's rest pose is not standing upright with its left side on +X: the joints
// without a single bone (pelvis, chest, head, hands, feet) take the source's world orientation
// change as is, which needs both rest poses in that convention.
void check_rest_convention(const Skeleton& s, const std::array<int, kRoles>& roles,
                           const std::string& name, std::vector<std::string>& warnings) {
  const std::vector<glm::vec3> p = rest_positions(s);
  auto at = [&](Role r) { return roles[static_cast<int>(r)]; };
  const int pelvis = at(Role::pelvis), neck = at(Role::neck);
  const int left = at(Role::left_thigh), right = at(Role::right_thigh);
  auto off = [](glm::vec3 v, glm::vec3 axis) {
    return glm::length(v) < 1e-6f ? 0.0f
                                  : glm::degrees(std::acos(std::clamp(
                                        glm::dot(glm::normalize(v), axis), -1.0f, 1.0f)));
  };
  if (pelvis >= 0 && neck >= 0 && off(p[neck] - p[pelvis], {0, 1, 0}) > 30.0f)
    warnings.push_back(name +
                       ": in the rest pose (zero rotations) the spine does not point up "
                       "(+Y); pelvis, chest, head, hand and foot orientations will be off");
  if (left >= 0 && right >= 0 && off(p[left] - p[right], {1, 0, 0}) > 30.0f)
    warnings.push_back(name +
                       ": in the rest pose (zero rotations) the left hip is not on +X of "
                       "the right one; pelvis, chest, head, hand and foot orientations "
                       "will be off");
}

}  // namespace

namespace {

// Map and rig files are small text files; anything beyond this is not one.
constexpr std::uintmax_t kMaxRetargetFileBytes = 64u << 20;

std::string read_text_file(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open the ") + what + " file");
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxRetargetFileBytes)
    throw InputError(path, std::string("too large for a ") + what + " file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path, "read error");
  return text.str();
}

}  // namespace

JointMap read_joint_map(const std::string& path) {
  return parse_joint_map(read_text_file(path, "joint map"), path);
}

JointMap parse_joint_map(std::string_view text, const std::string& path) {
  JointMap map;
  map.path = path;
  long number = 0;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string line(text.substr(0, end));
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    ++number;
    if (line.size() > 4096) throw InputError(path, number, "line too long for a joint map");
    std::istringstream words(trim_comment(line));
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (w.empty()) continue;
    if (w.size() != 2) {
      throw InputError(
          path, number,
          "expected 'source_joint target_joint', found " + std::to_string(w.size()) + " words");
    }
    for (const std::string& name : w) {
      if (!std::all_of(name.begin(), name.end(),
                       [](char c) { return std::isprint(static_cast<unsigned char>(c)); }))
        throw InputError(path, number, "joint name with unprintable characters");
    }
    map.entries.push_back({w[0], w[1], number});
  }
  if (map.entries.empty()) throw InputError(path, "the joint map names no joints");
  return map;
}

Skeleton read_rig(const std::string& path) { return parse_rig(read_text_file(path, "rig"), path); }

Skeleton parse_rig(std::string_view text, const std::string& path) {
  std::string bvh(text);
  if (bvh.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError(path, "the rig file is empty");
  // A rig may be a bare HIERARCHY: give it an empty MOTION section (after the text, so line
  // numbers in messages stay those of the file).
  if (bvh.find("MOTION") == std::string::npos) bvh += "\nMOTION\nFrames: 0\nFrame Time: 1\n";
  Clip clip = parse_bvh(bvh, path);
  int joints = 0;
  for (const SkeletonJoint& j : clip.skeleton.joints) joints += j.end_site ? 0 : 1;
  if (joints < 2) throw InputError(path, "the rig has fewer than two joints");
  return std::move(clip.skeleton);
}

namespace {

// Squared bone lengths are formed in float: offsets beyond this (file units: a kilometre in
// centimetres) would overflow them into inf and NaN rotations. No real rig comes near it.
constexpr float kMaxOffset = 1e5f;

void check_offsets(const Skeleton& skeleton, const std::string& name) {
  for (const SkeletonJoint& j : skeleton.joints) {
    // The result is written as Euler angles in the joint's own order: three axes or none.
    const auto rotations = std::count_if(j.channels.begin(), j.channels.end(), is_rotation);
    if (rotations != 0 && rotations != 3)
      throw InputError(name, "joint '" + j.name + "' has " + std::to_string(rotations) +
                                 " rotation channels; retargeting needs 0 or 3");
    for (int i = 0; i < 3; ++i) {
      if (!(std::abs(j.offset[i]) <= kMaxOffset))
        throw InputError(name, "joint '" + j.name + "' has an OFFSET beyond " +
                                   std::to_string(static_cast<long>(kMaxOffset)) +
                                   " units: not a rig");
    }
  }
}

}  // namespace

RetargetResult retarget(const Clip& source, const Skeleton& target,
                        const RetargetOptions& options) {
  const Skeleton& src = source.skeleton;
  const std::string& target_name = options.target_source;
  check_offsets(src, source.source);
  check_offsets(target, target_name);
  RetargetResult result;
  std::vector<int> source_of(target.joints.size(), -1);
  std::vector<std::string> how(target.joints.size());

  // 1. Roles, through the family mappings. Without a map file a rig that cannot be mapped is an
  //    error; with one, the map alone may do.
  std::array<int, kRoles> src_roles, tgt_roles;
  src_roles.fill(-1);
  tgt_roles.fill(-1);
  bool have_roles = true;
  try {
    src_roles = roles_of(src, source.source);
    tgt_roles = roles_of(target, target_name);
  } catch (const InputError&) {
    if (!options.map) throw;
    have_roles = false;
  }
  if (have_roles) {
    check_rest_convention(src, src_roles, source.source, result.warnings);
    check_rest_convention(target, tgt_roles, target_name, result.warnings);
    for (int r = 0; r < kRoles; ++r) {
      if (src_roles[r] >= 0 && tgt_roles[r] >= 0 && source_of[tgt_roles[r]] < 0) {
        source_of[tgt_roles[r]] = src_roles[r];
        how[tgt_roles[r]] = kRoleNames[r];
      }
    }
  }
  // 2. Identical names, where neither joint has a role match.
  {
    std::vector<bool> source_used(src.joints.size(), false);
    for (int t = 0; t < target.joint_count(); ++t)
      if (source_of[t] >= 0) source_used[source_of[t]] = true;
    for (int t = 0; t < target.joint_count(); ++t) {
      if (target.joints[t].end_site || source_of[t] >= 0) continue;
      const int s = find_joint(src, target.joints[t].name.c_str(), false);
      if (s >= 0 && !source_used[s]) {
        source_of[t] = s;
        source_used[s] = true;
        how[t] = "same name";
      }
    }
  }
  // 3. The map file overrides.
  if (options.map) {
    for (const JointMapEntry& e : options.map->entries) {
      const int s = find_joint(src, e.source_joint.c_str(), false);
      const int t = find_joint(target, e.target_joint.c_str(), false);
      if (s < 0) {
        throw InputError(
            options.map->path, e.line,
            "no joint '" + e.source_joint + "' in the source skeleton (" + source.source + ")");
      }
      if (t < 0) {
        throw InputError(
            options.map->path, e.line,
            "no joint '" + e.target_joint + "' in the target rig (" + target_name + ")");
      }
      source_of[t] = s;
      how[t] = "map file";
    }
  }
  // The roots correspond when nothing else says where the target's root goes.
  const int src_pelvis = have_roles ? src_roles[static_cast<int>(Role::pelvis)] : 0;
  const int tgt_pelvis = have_roles ? tgt_roles[static_cast<int>(Role::pelvis)] : 0;
  if (source_of[tgt_pelvis] < 0) {
    source_of[tgt_pelvis] = src_pelvis;
    how[tgt_pelvis] = "roots";
  }

  int mapped = 0;
  for (int t = 0; t < target.joint_count(); ++t) {
    if (target.joints[t].end_site) continue;
    if (source_of[t] >= 0) {
      ++mapped;
      result.matches.push_back({source_of[t], t, how[t]});
    } else {
      result.unmapped_target.push_back(t);
    }
  }
  if (mapped < options.min_mapped_joints) {
    throw InputError(target_name, "only " + std::to_string(mapped) +
                                      " joint(s) of the rig map onto the source skeleton (" +
                                      source.source + "), at least " +
                                      std::to_string(options.min_mapped_joints) +
                                      " needed; name them in a map file (--map FILE, lines "
                                      "'source_joint target_joint')");
  }
  for (const SkeletonJoint& j : target.joints) {
    if (j.end_site) continue;
    int rotations = 0;
    for (Channel c : j.channels) rotations += is_rotation(c) ? 1 : 0;
    if (rotations != 0 && rotations != 3)
      throw InputError(target_name, "joint '" + j.name + "' needs 0 or 3 rotation channels");
  }

  // 4. Bones: a mapped joint whose nearest mapped descendants are exactly one joint, mapped to a
  //    descendant of its own source joint. Rest alignment A = swing of the target's rest bone onto
  //    the source's; identity for other joints.
  const std::vector<glm::vec3> src_rest = rest_positions(src);
  const std::vector<glm::vec3> tgt_rest = rest_positions(target);
  std::vector<int> bone_end(target.joints.size(), -1);
  std::vector<glm::quat> align(target.joints.size(), glm::quat(1, 0, 0, 0));
  for (int t = 0; t < target.joint_count(); ++t) {
    if (source_of[t] < 0) continue;
    int end = -1, count = 0;
    for (int c = t + 1; c < target.joint_count(); ++c) {
      if (source_of[c] < 0 || !is_descendant(target, c, t)) continue;
      bool nearest = true;
      for (int a = target.joints[c].parent; a != t; a = target.joints[a].parent)
        if (source_of[a] >= 0) nearest = false;
      if (nearest) end = c, ++count;
    }
    if (count != 1 || !is_descendant(src, source_of[end], source_of[t])) continue;
    const glm::vec3 dt = tgt_rest[end] - tgt_rest[t];
    const glm::vec3 ds = src_rest[source_of[end]] - src_rest[source_of[t]];
    if (glm::length(dt) < 1e-6f || glm::length(ds) < 1e-6f) continue;
    bone_end[t] = end;
    align[t] = swing(dt, ds);
    result.bones.push_back({t, end, source_of[t], source_of[end]});
  }

  // 5. Scale.
  if (have_roles) {
    result.source_hip_height = hip_height(src, src_roles);
    result.target_hip_height = hip_height(target, tgt_roles);
  } else {
    std::array<int, kRoles> just_root;
    just_root.fill(-1);
    just_root[static_cast<int>(Role::pelvis)] = src_pelvis;
    result.source_hip_height = hip_height(src, just_root);
    just_root[static_cast<int>(Role::pelvis)] = tgt_pelvis;
    result.target_hip_height = hip_height(target, just_root);
  }
  if (options.scale) {
    if (!(*options.scale > 0.0f) || !std::isfinite(*options.scale))
      throw InputError("--scale", "must be a positive number");
    result.scale = *options.scale;
    result.scale_is_auto = false;
  } else {
    if (!(result.source_hip_height > 0.0f) || !(result.target_hip_height > 0.0f)) {
      throw InputError(target_name,
                       "cannot measure the hip height of both skeletons in their rest pose; give "
                       "--scale S (target units per source unit)");
    }
    result.scale = result.target_hip_height / result.source_hip_height;
  }

  // 6. The frames.
  const PoseSequence in = to_poses(source);
  PoseSequence out;
  out.skeleton = target;
  out.skeleton.assign_channel_slots();
  out.fps = in.fps;
  out.frame_count = in.frame_count;
  const int joints = target.joint_count();
  out.translation.resize(static_cast<size_t>(out.frame_count) * joints);
  out.rotation.resize(static_cast<size_t>(out.frame_count) * joints);
  // The joint that carries the translation: the pelvis or its nearest ancestor with position
  // channels.
  auto has_position = [&](int j) {
    return std::any_of(target.joints[j].channels.begin(), target.joints[j].channels.end(),
                       [](Channel c) { return !is_rotation(c); });
  };
  int mover = tgt_pelvis;
  while (mover >= 0 && !has_position(mover)) mover = target.joints[mover].parent;

  GlobalPose g;
  std::vector<glm::quat> world(joints);
  std::vector<glm::vec3> position(joints);
  for (int f = 0; f < in.frame_count; ++f) {
    forward_kinematics(in, f, g);
    for (int t = 0; t < joints; ++t) {
      const int parent = target.joints[t].parent;
      const glm::quat parent_world = parent < 0 ? glm::quat(1, 0, 0, 0) : world[parent];
      glm::quat w = parent_world;
      if (source_of[t] >= 0 && !target.joints[t].end_site) {
        const int s = source_of[t];
        w = g.rotation[s] * align[t];
        if (bone_end[t] >= 0) {
          const glm::vec3 now = w * (tgt_rest[bone_end[t]] - tgt_rest[t]);
          const glm::vec3 wanted = g.position[source_of[bone_end[t]]] - g.position[s];
          w = swing(now, wanted) * w;
        }
        w = glm::normalize(w);
      }
      world[t] = w;
      out.rotation[out.at(f, t)] = glm::normalize(glm::inverse(parent_world) * w);
      out.translation[out.at(f, t)] = target.joints[t].offset;
      position[t] = parent < 0 ? target.joints[t].offset
                               : position[parent] + parent_world * target.joints[t].offset;
    }
    if (mover >= 0) {
      const glm::vec3 wanted = result.scale * g.position[src_pelvis];
      const glm::vec3 delta = wanted - position[tgt_pelvis];
      const int parent = target.joints[mover].parent;
      const glm::quat parent_world = parent < 0 ? glm::quat(1, 0, 0, 0) : world[parent];
      out.translation[out.at(f, mover)] += glm::inverse(parent_world) * delta;
    }
  }
  result.clip = to_clip(out);
  result.clip.source = target_name;
  result.clip.frame_time = source.frame_time;
  return result;
}

std::vector<float> bone_direction_errors(const Clip& source, const RetargetResult& result) {
  const PoseSequence a = to_poses(source);
  const PoseSequence b = to_poses(result.clip);
  std::vector<float> errors;
  errors.reserve(static_cast<size_t>(a.frame_count) * result.bones.size());
  GlobalPose ga, gb;
  for (int f = 0; f < std::min(a.frame_count, b.frame_count); ++f) {
    forward_kinematics(a, f, ga);
    forward_kinematics(b, f, gb);
    for (const MatchedBone& bone : result.bones) {
      const glm::dvec3 u =
          glm::normalize(glm::dvec3(ga.position[bone.source_to] - ga.position[bone.source_from]));
      const glm::dvec3 v =
          glm::normalize(glm::dvec3(gb.position[bone.target_to] - gb.position[bone.target_from]));
      // atan2 of |cross| and dot: accurate for small angles, unlike acos.
      errors.push_back(static_cast<float>(
          glm::degrees(std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v)))));
    }
  }
  return errors;
}

}  // namespace mocap::motion
