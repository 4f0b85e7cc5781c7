#include "motion/asf_amc.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include <glm/gtc/quaternion.hpp>
#include <glm/trigonometric.hpp>

#include "core/input_error.hpp"
#include "motion/pose_sequence.hpp"

namespace mocap::motion {
namespace {

// Limits that keep garbage from turning into huge allocations or absurd geometry.
constexpr int kMaxBones = 1000;
constexpr size_t kMaxTokensPerLine = 4096;
constexpr size_t kMaxNameLength = 256;
constexpr double kMaxMagnitude = 1e7;  // no length, position or angle in a real file is larger
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 30;
constexpr long kMaxFrameNumber = 1'000'000'000;
// Poses take far more memory than their text: a CMU trial has up to ~1.5 million joint-frames.
constexpr long kMaxJointFrames = 50'000'000;

bool is_separator(char c) {
  // Acclaim treats commas and parentheses as white space: "limits (-160.0 20.0)".
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == ',' || c == '(' ||
         c == ')';
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

std::string excerpt(std::string_view s) {
  // Garbage input may hold control bytes or very long tokens: show a readable, short excerpt.
  std::string out = "'";
  for (char c : s.substr(0, 40)) {
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  return out + (s.size() > 40 ? "...'" : "'");
}

std::optional<double> to_number(std::string_view tok) {
  // from_chars takes no '+' sign; files may write one.
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
  if (ec != std::errc() || end != tok.data() + tok.size() || std::isnan(value)) return std::nullopt;
  return value;
}

std::optional<long> to_integer(std::string_view tok) {
  long value = 0;
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
  if (ec != std::errc() || end != tok.data() + tok.size()) return std::nullopt;
  return value;
}

// Walks ASF/AMC text one line at a time and cuts each line into tokens; '#' starts a comment.
class LineReader {
 public:
  LineReader(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  // Moves to the next line that has tokens; false at the end of the text.
  bool next() {
    while (pos_ < text_.size()) {
      line_start_ = pos_;
      line_ = next_line_;
      size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      const std::string_view raw = text_.substr(pos_, end - pos_);
      pos_ = std::min(end + 1, text_.size());
      ++next_line_;
      tokenize(raw);
      if (!tokens_.empty()) return true;
    }
    tokens_.clear();
    line_ = std::max(1L, next_line_ - 1);  // messages about a missing end name the last line
    return false;
  }

  // Steps back so that next() returns the current line again: a section ends at the keyword
  // of the next one, which the caller must still see.
  void unread() {
    pos_ = line_start_;
    next_line_ = line_;
    tokens_.clear();
  }

  size_t size() const { return tokens_.size(); }
  std::string_view operator[](size_t i) const { return tokens_[i]; }
  bool is_keyword() const { return !tokens_.empty() && tokens_[0].front() == ':'; }
  long line() const { return line_; }

  [[noreturn]] void fail(const std::string& what) const { fail_at(line_, what); }
  [[noreturn]] void fail_at(long line, const std::string& what) const {
    throw InputError(source_, line, what);
  }

  void expect_size(size_t n, const char* usage) const {
    if (tokens_.size() != n) fail(std::string("expected '") + usage + "'");
  }

  // A finite number of plausible size (or an infinite one where the format allows it).
  double number(size_t i, const char* what, bool allow_infinite = false) const {
    const std::optional<double> v = to_number(tokens_[i]);
    if (!v) fail(std::string("expected a number for ") + what + ", found " + excerpt(tokens_[i]));
    if (std::isinf(*v) ? !allow_infinite : std::abs(*v) > kMaxMagnitude) {
      fail(std::string("number out of range for ") + what + ": " + excerpt(tokens_[i]));
    }
    return *v;
  }

  glm::dvec3 vec3(size_t first, const char* what) const {
    return {number(first, what), number(first + 1, what), number(first + 2, what)};
  }

 private:
  void tokenize(std::string_view raw) {
    tokens_.clear();
    size_t i = 0;
    while (i < raw.size() && raw[i] != '#') {
      if (is_separator(raw[i])) {
        ++i;
        continue;
      }
      const size_t start = i;
      while (i < raw.size() && !is_separator(raw[i]) && raw[i] != '#') ++i;
      if (tokens_.size() == kMaxTokensPerLine) {
        fail("line has more than " + std::to_string(kMaxTokensPerLine) + " fields");
      }
      tokens_.push_back(raw.substr(start, i - start));
    }
  }

  std::string_view text_;
  const std::string& source_;
  std::vector<std::string_view> tokens_;
  size_t pos_ = 0;
  size_t line_start_ = 0;
  long line_ = 0;
  long next_line_ = 1;
};

std::optional<AsfDof> to_dof(std::string_view tok) {
  static constexpr std::pair<std::string_view, AsfDof> kNames[] = {
      {"tx", AsfDof::tx}, {"ty", AsfDof::ty}, {"tz", AsfDof::tz},
      {"rx", AsfDof::rx}, {"ry", AsfDof::ry}, {"rz", AsfDof::rz}};
  for (const auto& [name, dof] : kNames) {
    if (iequals(tok, name)) return dof;
  }
  return std::nullopt;
}

bool is_rotation_dof(AsfDof d) { return d == AsfDof::rx || d == AsfDof::ry || d == AsfDof::rz; }
int axis_of(AsfDof d) { return static_cast<int>(d) % 3; }

std::optional<AsfAxisOrder> to_axis_order(std::string_view tok) {
  if (tok.size() != 3) return std::nullopt;
  AsfAxisOrder order{};
  bool used[3] = {false, false, false};
  for (int i = 0; i < 3; ++i) {
    const int axis = std::tolower(static_cast<unsigned char>(tok[i])) - 'x';
    if (axis < 0 || axis > 2 || used[axis]) return std::nullopt;
    used[axis] = true;
    order[i] = static_cast<std::uint8_t>(axis);
  }
  return order;
}

// Names end up in BVH files and messages: printable, no braces, no spaces.
bool is_valid_name(std::string_view name) {
  if (name.empty() || name.size() > kMaxNameLength) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isgraph(static_cast<unsigned char>(c)) && c != '{' && c != '}';
  });
}

// Reads the dof list of a bone or the root's `order` from tokens [first, end) of a line.
std::vector<AsfDof> parse_dofs(const LineReader& in, size_t first) {
  std::vector<AsfDof> dofs;
  for (size_t i = first; i < in.size(); ++i) {
    if (iequals(in[i], "l")) in.fail("dof 'l' (bone length changes) is not supported");
    const std::optional<AsfDof> dof = to_dof(in[i]);
    if (!dof) {
      in.fail("unknown degree of freedom " + excerpt(in[i]) + " (expected rx ry rz tx ty tz)");
    }
    if (std::find(dofs.begin(), dofs.end(), *dof) != dofs.end()) {
      in.fail("degree of freedom " + excerpt(in[i]) + " given twice");
    }
    dofs.push_back(*dof);
  }
  return dofs;
}

class AsfParser {
 public:
  AsfParser(std::string_view text, const std::string& source) : in_(text, source) {
    skel_.source = source;
  }

  AsfSkeleton parse() {
    while (in_.next()) {
      if (!in_.is_keyword()) {
        in_.fail("expected a keyword such as ':root' or ':bonedata', found " + excerpt(in_[0]));
      }
      parse_section(in_[0]);
    }
    if (!seen_root_) in_.fail("no ':root' section (is this an ASF file?)");
    if (!skel_.bones.empty() && !seen_hierarchy_) in_.fail("no ':hierarchy' section");
    link_bones();
    return std::move(skel_);
  }

 private:
  struct HierarchyLine {
    long line;
    std::vector<std::string> names;  // parent, then its children
  };

  void parse_section(std::string_view key) {
    if (key == ":version") return;
    if (key == ":name") {
      if (in_.size() > 1) skel_.name = std::string(in_[1]);
    } else if (key == ":units") {
      if (angles_read_) in_.fail("':units' must come before ':root' and ':bonedata'");
      parse_units();
    } else if (key == ":root") {
      once(seen_root_, key);
      parse_root();
    } else if (key == ":bonedata") {
      once(seen_bonedata_, key);
      parse_bonedata();
    } else if (key == ":hierarchy") {
      once(seen_hierarchy_, key);
      parse_hierarchy();
    } else {
      skip_section();  // :documentation, and sections this reader has no use for (e.g. :skin)
    }
  }

  void once(bool& seen, std::string_view key) {
    if (seen) in_.fail("second '" + std::string(key) + "' section");
    seen = true;
  }

  // Reads lines up to the next keyword; false when the section is over.
  bool next_in_section() {
    if (!in_.next()) return false;
    if (!in_.is_keyword()) return true;
    in_.unread();
    return false;
  }

  void skip_section() {
    while (next_in_section()) continue;
  }

  void parse_units() {
    while (next_in_section()) {
      in_.expect_size(2, "mass|length|angle VALUE");
      if (in_[0] == "mass") {
        skel_.mass_unit = in_.number(1, "the mass unit");
      } else if (in_[0] == "length") {
        skel_.length_unit = in_.number(1, "the length unit");
        if (!(skel_.length_unit > 0.0)) in_.fail("the length unit must be positive");
      } else if (in_[0] == "angle") {
        if (!iequals(in_[1], "deg") && !iequals(in_[1], "rad")) {
          in_.fail("angle unit must be 'deg' or 'rad', found " + excerpt(in_[1]));
        }
        skel_.angles_in_degrees = iequals(in_[1], "deg");
      }  // other unit kinds do not change the geometry
    }
  }

  glm::dvec3 angles(size_t first, const char* what) {
    angles_read_ = true;
    const glm::dvec3 v = in_.vec3(first, what);
    return skel_.angles_in_degrees ? v : glm::degrees(v);
  }

  void parse_root() {
    while (next_in_section()) {
      const std::string_view key = in_[0];
      if (key == "order") {
        skel_.root.order = parse_dofs(in_, 1);
      } else if (key == "axis") {
        in_.expect_size(2, "axis XYZ");
        const auto order = to_axis_order(in_[1]);
        if (!order) in_.fail("expected an axis order such as XYZ, found " + excerpt(in_[1]));
        skel_.root.axis_order = *order;
      } else if (key == "position") {
        in_.expect_size(4, "position X Y Z");
        skel_.root.position = in_.vec3(1, "the root position");
      } else if (key == "orientation") {
        in_.expect_size(4, "orientation X Y Z");
        skel_.root.orientation = angles(1, "the root orientation");
      } else {
        in_.fail("unknown ':root' field " + excerpt(key));
      }
    }
  }

  void parse_bonedata() {
    while (next_in_section()) {
      if (in_[0] != "begin") in_.fail("expected 'begin' of a bone, found " + excerpt(in_[0]));
      if (static_cast<int>(skel_.bones.size()) == kMaxBones) {
        in_.fail("more than " + std::to_string(kMaxBones) + " bones");
      }
      parse_bone();
    }
  }

  void parse_bone() {
    AsfBone bone;
    const long begin_line = in_.line();
    bool has_direction = false, has_length = false;
    for (;;) {
      if (!in_.next()) in_.fail("file ends inside a bone (no 'end')");
      if (in_.is_keyword()) in_.fail("bone has no 'end' before " + excerpt(in_[0]));
      const std::string_view key = in_[0];
      if (key == "end") break;
      if (key == "id") {
        in_.expect_size(2, "id N");
        const auto id = to_integer(in_[1]);
        if (!id || *id < 0 || *id > 1'000'000) in_.fail("bad bone id " + excerpt(in_[1]));
        bone.id = static_cast<int>(*id);
      } else if (key == "name") {
        in_.expect_size(2, "name NAME");
        if (!is_valid_name(in_[1])) in_.fail("bad bone name " + excerpt(in_[1]));
        bone.name = std::string(in_[1]);
      } else if (key == "direction") {
        in_.expect_size(4, "direction X Y Z");
        bone.direction = in_.vec3(1, "the bone direction");
        has_direction = true;
      } else if (key == "length") {
        in_.expect_size(2, "length L");
        bone.length = in_.number(1, "the bone length");
        if (bone.length < 0.0) in_.fail("negative bone length");
        has_length = true;
      } else if (key == "axis") {
        parse_bone_axis(bone);
      } else if (key == "dof") {
        if (!bone.dofs.empty()) in_.fail("second 'dof' line");
        bone.dofs = parse_dofs(in_, 1);
      } else if (key == "limits") {
        parse_limits(bone);
      } else if (key == "bodymass" || key == "cofmass") {
        // Dynamics data: not needed for kinematics.
      } else {
        in_.fail("unknown bone field " + excerpt(key));
      }
    }
    finish_bone(std::move(bone), begin_line, has_direction && has_length);
  }

  void parse_bone_axis(AsfBone& bone) {
    if (in_.size() != 4 && in_.size() != 5) in_.expect_size(5, "axis X Y Z ORDER");
    bone.axis = angles(1, "the bone axis");
    if (in_.size() == 5) {
      const auto order = to_axis_order(in_[4]);
      if (!order) in_.fail("expected an axis order such as XYZ, found " + excerpt(in_[4]));
      bone.axis_order = *order;
    }
  }

  // "limits (min max)" per dof, usually one pair per line: reads on until all pairs are in.
  void parse_limits(AsfBone& bone) {
    if (bone.dofs.empty()) in_.fail("'limits' before 'dof'");
    if (!bone.limits.empty()) in_.fail("second 'limits' field");
    std::vector<double> values;
    const size_t wanted = 2 * bone.dofs.size();
    for (size_t first = 1;; first = 0) {
      for (size_t i = first; i < in_.size(); ++i) {
        if (values.size() == wanted) in_.fail("more limits than the bone's dofs");
        values.push_back(in_.number(i, "a limit", true));
      }
      if (values.size() == wanted) break;
      if (!in_.next() || !to_number(in_[0])) {
        in_.fail("expected " + std::to_string(bone.dofs.size()) + " limit pairs, one per dof");
      }
    }
    for (size_t d = 0; d < bone.dofs.size(); ++d) {
      double lo = values[2 * d], hi = values[2 * d + 1];
      if (is_rotation_dof(bone.dofs[d]) && !skel_.angles_in_degrees) {
        lo = glm::degrees(lo);
        hi = glm::degrees(hi);
      }
      bone.limits.emplace_back(lo, hi);
    }
    angles_read_ = true;
  }

  void finish_bone(AsfBone bone, long begin_line, bool complete) {
    if (bone.name.empty()) in_.fail("bone has no name");
    if (!complete) in_.fail("bone " + excerpt(bone.name) + " needs 'direction' and 'length'");
    if (iequals(bone.name, "root")) in_.fail("a bone may not be called 'root'");
    if (skel_.find(bone.name) >= 0) in_.fail("second bone called " + excerpt(bone.name));
    skel_.bones.push_back(std::move(bone));
    bone_lines_.push_back(begin_line);
  }

  void parse_hierarchy() {
    if (!next_in_section() || in_[0] != "begin") in_.fail("expected 'begin' after ':hierarchy'");
    for (;;) {
      if (!in_.next()) in_.fail("file ends inside ':hierarchy' (no 'end')");
      if (in_.is_keyword()) in_.fail("':hierarchy' has no 'end' before " + excerpt(in_[0]));
      if (in_[0] == "end") return;
      HierarchyLine line{in_.line(), {}};
      for (size_t i = 0; i < in_.size(); ++i) line.names.emplace_back(in_[i]);
      hierarchy_.push_back(std::move(line));
    }
  }

  // Sets every bone's parent from the hierarchy, then orders the bones parents-first.
  void link_bones() {
    const int n = static_cast<int>(skel_.bones.size());
    std::vector<std::vector<int>> children(n + 1);  // [0] = the root's, [b + 1] = bone b's
    std::vector<bool> has_parent(n, false);
    for (const HierarchyLine& h : hierarchy_) {
      const bool is_root = iequals(h.names[0], "root");
      const int parent = is_root ? -1 : skel_.find(h.names[0]);
      if (parent < 0 && !is_root) in_.fail_at(h.line, "unknown bone " + excerpt(h.names[0]));
      for (size_t i = 1; i < h.names.size(); ++i) {
        const int child = skel_.find(h.names[i]);
        if (child < 0) in_.fail_at(h.line, "unknown bone " + excerpt(h.names[i]));
        if (has_parent[child]) {
          in_.fail_at(h.line, "bone " + excerpt(h.names[i]) + " has two parents");
        }
        has_parent[child] = true;
        skel_.bones[child].parent = parent;
        children[parent + 1].push_back(child);
      }
    }
    order_parents_first(children);
  }

  void order_parents_first(const std::vector<std::vector<int>>& children) {
    const int n = static_cast<int>(skel_.bones.size());
    std::vector<int> order;  // depth-first, children in hierarchy order
    std::vector<int> stack(children[0].rbegin(), children[0].rend());
    while (!stack.empty()) {
      const int b = stack.back();
      stack.pop_back();
      order.push_back(b);
      stack.insert(stack.end(), children[b + 1].rbegin(), children[b + 1].rend());
    }
    if (static_cast<int>(order.size()) < n) {
      std::vector<bool> reached(n, false);
      for (int b : order) reached[b] = true;
      const int lost =
          static_cast<int>(std::find(reached.begin(), reached.end(), false) - reached.begin());
      in_.fail_at(bone_lines_[lost], "bone " + excerpt(skel_.bones[lost].name) +
                                         " is not connected to the root in ':hierarchy'"
                                         " (missing, or part of a cycle)");
    }
    std::vector<int> new_index(n);
    for (int i = 0; i < n; ++i) new_index[order[i]] = i;
    std::vector<AsfBone> sorted;
    sorted.reserve(n);
    for (int b : order) {
      sorted.push_back(std::move(skel_.bones[b]));
      if (sorted.back().parent >= 0) sorted.back().parent = new_index[sorted.back().parent];
    }
    skel_.bones = std::move(sorted);
  }

  LineReader in_;
  AsfSkeleton skel_;
  std::vector<long> bone_lines_;  // line of each bone's 'begin', for messages
  std::vector<HierarchyLine> hierarchy_;
  bool seen_root_ = false, seen_bonedata_ = false, seen_hierarchy_ = false;
  bool angles_read_ = false;
};

// ---- Conversion to the Clip representation ----

glm::dquat axis_rotation(int axis, double radians) {
  glm::dvec3 v(0.0);
  v[axis] = 1.0;
  return glm::angleAxis(radians, v);
}

// Rotations about the global axes, applied in `order`: XYZ gives Rz·Ry·Rx.
glm::dquat ordered_rotation(const glm::dvec3& degrees, const AsfAxisOrder& order) {
  glm::dquat q(1.0, 0.0, 0.0, 0.0);
  for (std::uint8_t axis : order) q = axis_rotation(axis, glm::radians(degrees[axis])) * q;
  return q;
}

bool has_translation(const std::vector<AsfDof>& dofs) {
  return std::any_of(dofs.begin(), dofs.end(), [](AsfDof d) { return !is_rotation_dof(d); });
}
bool has_rotation(const std::vector<AsfDof>& dofs) {
  return std::any_of(dofs.begin(), dofs.end(), [](AsfDof d) { return is_rotation_dof(d); });
}

void add_channels(SkeletonJoint& joint, bool translation, bool rotation) {
  using enum Channel;
  if (translation) joint.channels.insert(joint.channels.end(), {Xposition, Yposition, Zposition});
  if (rotation) joint.channels.insert(joint.channels.end(), {Zrotation, Yrotation, Xrotation});
}

glm::vec3 bone_vector(const AsfBone& bone) { return glm::vec3(bone.direction * bone.length); }

// The joints in parents-first order plus, for each bone, the index of its joint.
struct JointLayout {
  Skeleton skeleton;
  std::vector<int> joint_of_bone;
};

JointLayout layout_joints(const AsfSkeleton& asf) {
  JointLayout out;
  const int n = static_cast<int>(asf.bones.size());
  std::vector<bool> has_children(n, false);
  for (const AsfBone& b : asf.bones) {
    if (b.parent >= 0) has_children[b.parent] = true;
  }
  SkeletonJoint root;
  root.name = "root";
  root.offset = glm::vec3(asf.root.position);
  add_channels(root, has_translation(asf.root.order),
               has_rotation(asf.root.order) || asf.root.orientation != glm::dvec3(0.0));
  out.skeleton.joints.push_back(std::move(root));
  // Bones are already depth-first, so an End Site right after its leaf keeps that order.
  for (int b = 0; b < n; ++b) {
    const AsfBone& bone = asf.bones[b];
    SkeletonJoint joint;
    joint.name = bone.name;
    joint.parent = bone.parent < 0 ? 0 : out.joint_of_bone[bone.parent];
    if (bone.parent >= 0) joint.offset = bone_vector(asf.bones[bone.parent]);
    add_channels(joint, has_translation(bone.dofs), has_rotation(bone.dofs));
    out.joint_of_bone.push_back(out.skeleton.joint_count());
    out.skeleton.joints.push_back(std::move(joint));
    if (!has_children[b]) {
      SkeletonJoint end;
      end.name = bone.name + "_End";
      end.parent = out.joint_of_bone[b];
      end.offset = bone_vector(bone);
      end.end_site = true;
      out.skeleton.joints.push_back(std::move(end));
    }
  }
  out.skeleton.assign_channel_slots();
  return out;
}

// One AMC value group: the root's or one bone's values within a frame.
struct AmcSlot {
  int bone = -1;  // -1 = the root
  const std::vector<AsfDof>* dofs = nullptr;
  int first_value = 0;
};

// Turns one frame of AMC values into local joint transforms.
class FramePoser {
 public:
  FramePoser(const AsfSkeleton& asf, const JointLayout& layout, bool degrees)
      : asf_(asf), layout_(layout), degrees_(degrees) {
    for (const AsfBone& b : asf.bones) {
      const glm::dquat c = ordered_rotation(b.axis, b.axis_order);
      axis_.push_back(c);
      axis_inverse_.push_back(glm::conjugate(c));
    }
    orientation_ = ordered_rotation(asf.root.orientation, asf.root.axis_order);
  }

  void append(const std::vector<AmcSlot>& slots, const std::vector<double>& values,
              PoseSequence& out) const {
    for (const SkeletonJoint& j : layout_.skeleton.joints) out.translation.push_back(j.offset);
    out.rotation.resize(out.translation.size(), glm::quat(1, 0, 0, 0));
    const size_t base = out.translation.size() - layout_.skeleton.joints.size();
    for (const AmcSlot& slot : slots) {
      glm::dvec3 t(0.0);
      const glm::dquat m = motion(*slot.dofs, values.data() + slot.first_value, t);
      if (slot.bone < 0) {
        out.translation[base] = glm::vec3(asf_.root.position + orientation_ * t);
        out.rotation[base] = glm::quat(glm::normalize(orientation_ * m));
        continue;
      }
      const size_t j = base + static_cast<size_t>(layout_.joint_of_bone[slot.bone]);
      const glm::dquat& c = axis_[slot.bone];
      out.translation[j] += glm::vec3(c * t);
      out.rotation[j] = glm::quat(glm::normalize(c * m * axis_inverse_[slot.bone]));
    }
  }

 private:
  // M from the dof values in the order listed (the first listed is applied first), and the
  // translation dofs into `t`.
  glm::dquat motion(const std::vector<AsfDof>& dofs, const double* v, glm::dvec3& t) const {
    glm::dquat m(1.0, 0.0, 0.0, 0.0);
    for (size_t i = 0; i < dofs.size(); ++i) {
      if (is_rotation_dof(dofs[i])) {
        m = axis_rotation(axis_of(dofs[i]), degrees_ ? glm::radians(v[i]) : v[i]) * m;
      } else {
        t[axis_of(dofs[i])] = v[i];
      }
    }
    return m;
  }

  const AsfSkeleton& asf_;
  const JointLayout& layout_;
  bool degrees_;
  std::vector<glm::dquat> axis_, axis_inverse_;
  glm::dquat orientation_;
};

class AmcParser {
 public:
  AmcParser(const AsfSkeleton& asf, std::string_view text, const std::string& source)
      : asf_(asf), in_(text, source), degrees_(asf.angles_in_degrees) {
    add_slot("root", -1, asf.root.order);
    for (int b = 0; b < static_cast<int>(asf.bones.size()); ++b) {
      add_slot(asf.bones[b].name, b, asf.bones[b].dofs);
    }
  }

  PoseSequence parse(double fps) {
    const JointLayout layout = layout_joints(asf_);
    PoseSequence poses;
    poses.skeleton = layout.skeleton;
    poses.fps = fps;
    parse_header();
    const FramePoser poser(asf_, layout, degrees_);
    const long max_frames = kMaxJointFrames / layout.skeleton.joint_count();
    while (read_frame()) {
      if (poses.frame_count == max_frames) {
        in_.fail("more than " + std::to_string(max_frames) + " frames: too long to hold in memory");
      }
      poser.append(slots_, values_, poses);
      ++poses.frame_count;
    }
    if (poses.frame_count == 0) in_.fail("no frames (is this an AMC file?)");
    return poses;
  }

 private:
  void add_slot(const std::string& name, int bone, const std::vector<AsfDof>& dofs) {
    slot_of_name_.emplace(name, static_cast<int>(slots_.size()));
    slots_.push_back({bone, &dofs, values_per_frame_});
    values_per_frame_ += static_cast<int>(dofs.size());
  }

  // ":FULLY-SPECIFIED", ":DEGREES" or ":RADIANS" before the first frame.
  void parse_header() {
    while (in_.next()) {
      if (!in_.is_keyword()) {
        in_.unread();
        return;
      }
      if (iequals(in_[0], ":DEGREES")) degrees_ = true;
      if (iequals(in_[0], ":RADIANS")) degrees_ = false;
    }
  }

  bool is_frame_number_line() const {
    return in_.size() == 1 && to_integer(in_[0]) && !slot_of_name_.contains(in_[0]);
  }

  // Reads one frame: its number line, then one line per bone. False at the end of the text.
  bool read_frame() {
    if (!in_.next()) return false;
    if (!is_frame_number_line()) {
      in_.fail("expected a frame number, found " + excerpt(in_[0]));
    }
    const long number = *to_integer(in_[0]);
    const long frame_line = in_.line();
    if (number < 0 || number > kMaxFrameNumber)
      in_.fail("implausible frame number " + excerpt(in_[0]));
    if (frames_read_ > 0 && number != last_frame_number_ + 1) {
      in_.fail("frame " + std::to_string(number) + " follows frame " +
               std::to_string(last_frame_number_) + " (frames must be consecutive)");
    }
    last_frame_number_ = number;
    ++frames_read_;
    values_.assign(static_cast<size_t>(values_per_frame_), 0.0);
    seen_.assign(slots_.size(), false);
    while (in_.next()) {
      if (is_frame_number_line()) {
        in_.unread();
        break;
      }
      read_bone_line(number);
    }
    check_complete(number, frame_line);
    return true;
  }

  void read_bone_line(long frame) {
    if (in_.is_keyword()) in_.fail("keyword " + excerpt(in_[0]) + " after the first frame");
    const auto it = slot_of_name_.find(in_[0]);
    if (it == slot_of_name_.end()) {
      in_.fail("unknown bone " + excerpt(in_[0]) + " (not in the ASF)");
    }
    const AmcSlot& slot = slots_[it->second];
    if (seen_[it->second]) {
      in_.fail("bone " + excerpt(in_[0]) + " given twice in frame " + std::to_string(frame));
    }
    seen_[it->second] = true;
    const size_t count = slot.dofs->size();
    if (in_.size() - 1 != count) {
      in_.fail("bone " + excerpt(in_[0]) + " has " + std::to_string(in_.size() - 1) +
               " values, the ASF gives it " + std::to_string(count) + " dofs");
    }
    for (size_t i = 0; i < count; ++i) {
      values_[static_cast<size_t>(slot.first_value) + i] = in_.number(i + 1, "a dof value");
    }
  }

  void check_complete(long frame, long frame_line) const {
    for (size_t s = 0; s < slots_.size(); ++s) {
      if (!seen_[s] && !slots_[s].dofs->empty()) {
        const std::string name = slots_[s].bone < 0 ? "root" : asf_.bones[slots_[s].bone].name;
        in_.fail_at(frame_line,
                    "frame " + std::to_string(frame) + " has no values for bone " + excerpt(name));
      }
    }
  }

  const AsfSkeleton& asf_;
  LineReader in_;
  bool degrees_;
  std::vector<AmcSlot> slots_;
  std::map<std::string, int, std::less<>> slot_of_name_;
  int values_per_frame_ = 0;
  std::vector<double> values_;
  std::vector<bool> seen_;
  long frames_read_ = 0;
  long last_frame_number_ = 0;
};

std::string read_text(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxFileBytes) {
    throw InputError(path, "file is larger than " + std::to_string(kMaxFileBytes >> 20) + " MiB");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw InputError(path, "read error");
  return buffer.str();
}

}  // namespace

int AsfSkeleton::find(std::string_view bone_name) const {
  for (int b = 0; b < static_cast<int>(bones.size()); ++b) {
    if (bones[b].name == bone_name) return b;
  }
  return -1;
}

AsfSkeleton parse_asf(std::string_view text, const std::string& source) {
  return AsfParser(text, source).parse();
}

Skeleton to_skeleton(const AsfSkeleton& skeleton) { return layout_joints(skeleton).skeleton; }

Clip parse_amc(const AsfSkeleton& skeleton, std::string_view text, const std::string& source,
               double fps) {
  if (!(fps > 0.0)) throw InputError(source, "frame rate must be positive");
  // Without a single dof there is nothing to animate (and no valid BVH to write).
  const bool animated =
      !skeleton.root.order.empty() || std::any_of(skeleton.bones.begin(), skeleton.bones.end(),
                                                  [](const AsfBone& b) { return !b.dofs.empty(); });
  if (!animated) throw InputError(skeleton.source, "the skeleton has no degrees of freedom");
  Clip clip = to_clip(AmcParser(skeleton, text, source).parse(fps));
  clip.source = source;
  return clip;
}

AsfSkeleton read_asf(const std::string& asf_path) {
  return parse_asf(read_text(asf_path), asf_path);
}

Clip read_asf_amc(const std::string& asf_path, const std::string& amc_path, double fps) {
  const AsfSkeleton skeleton = read_asf(asf_path);
  return parse_amc(skeleton, read_text(amc_path), amc_path, fps);
}

}  // namespace mocap::motion
