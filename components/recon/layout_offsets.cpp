#include "recon/layout_offsets.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <glm/geometric.hpp>
#include <vector>

#include "core/input_error.hpp"
#include "core/install_paths.hpp"

namespace mocap::recon {

namespace fs = std::filesystem;

std::string_view basis_name(OffsetBasis b) {
  switch (b) {
    case OffsetBasis::none:
      return "none";
    case OffsetBasis::shoulders:
      return "shoulders";
    case OffsetBasis::hips:
      return "hips";
    case OffsetBasis::bone:
      return "bone";
  }
  return "?";
}

namespace {

constexpr float kMaxCoefficient = 2.0f;  // beyond this a file is wrong, not a layout

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

class Parser {
 public:
  Parser(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}

  LayoutOffsets parse() {
    LayoutOffsets out;
    out.source = file_;
    std::array<bool, kBodyJoints> seen{};
    bool have_format = false, have_layout = false, in_joints = false;
    std::size_t pos = 0;
    while (pos < text_.size()) {
      std::size_t end = text_.find('\n', pos);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos, end - pos);
      pos = end + 1;
      ++line_;
      for (char c : line) {
        const auto u = static_cast<unsigned char>(c);
        if ((u < 0x20 && c != '\t' && c != '\r') || u > 0x7e)
          fail("not a text line (byte " + std::to_string(u) + "): not a layout offsets file");
      }
      if (const auto hash = line.find('#'); hash != std::string_view::npos)
        line = line.substr(0, hash);
      const bool indented = !line.empty() && (line.front() == ' ' || line.front() == '\t');
      line = trim(line);
      if (line.empty()) continue;
      const auto colon = line.find(':');
      if (colon == std::string_view::npos) fail("expected 'key: value', got '" + str(line) + "'");
      const std::string_view key = trim(line.substr(0, colon));
      const std::string_view value = trim(line.substr(colon + 1));
      if (!have_format) {
        if (key != "format" || value != kLayoutOffsetsFormat)
          fail("the first entry must be 'format: " + str(kLayoutOffsetsFormat) +
               "': not a layout offsets file");
        have_format = true;
        continue;
      }
      if (indented) {
        if (!in_joints) fail("indented line outside 'joints:'");
        const auto joint = joint_from_name(key);
        if (!joint) fail("unknown joint '" + str(key) + "'");
        const int j = index(*joint);
        if (seen[j]) fail("joint '" + str(key) + "' given twice");
        seen[j] = true;
        out.joints[j] = parse_joint(value);
        continue;
      }
      in_joints = false;
      if (key == "layout") {
        const KeypointLayout* l = find_layout(value);
        if (!l) fail("unknown layout '" + str(value) + "'");
        out.layout = l->id;
        have_layout = true;
      } else if (key == "joints") {
        if (!value.empty()) fail("'joints:' takes one indented line per joint");
        in_joints = true;
      } else if (key == "format") {
        fail("'format' given twice");
      } else if (key != "command" && key != "source" && key != "model") {
        fail("unknown key '" + str(key) +
             "' (expected format, layout, command, source, model, "
             "joints)");
      }
    }
    if (!have_format) fail("empty: not a layout offsets file");
    if (!have_layout) fail("no 'layout:' entry (file truncated?)");
    std::string missing;
    for (int j = 0; j < kBodyJoints; ++j) {
      if (seen[j]) continue;
      if (!missing.empty()) missing += ", ";
      missing += kJointNames[j];
    }
    if (!missing.empty()) fail("joints missing (file truncated?): " + missing);
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(file_, line_, what); }
  static std::string str(std::string_view s) { return std::string(s); }

  float number(std::string_view key, std::string_view s) const {
    float v = 0.0f;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v))
      fail(std::string("'").append(key).append("' is not a number: '").append(s).append("'"));
    if (std::abs(v) > kMaxCoefficient)
      fail(std::string("'").append(key).append("' = ").append(s).append(
          " is beyond ±2 (a coefficient, not millimetres)"));
    return v;
  }

  JointOffset parse_joint(std::string_view value) const {
    if (value.size() < 2 || value.front() != '{' || value.back() != '}')
      fail("expected '{basis: ..., along: ..., lateral: ...}', got '" + str(value) + "'");
    value = value.substr(1, value.size() - 2);
    JointOffset out;
    bool have_basis = false, have_along = false, have_lateral = false, have_forward = false;
    while (!value.empty()) {
      const auto comma = value.find(',');
      const std::string_view item = trim(value.substr(0, comma));
      value = comma == std::string_view::npos ? std::string_view{} : value.substr(comma + 1);
      const auto colon = item.find(':');
      if (colon == std::string_view::npos) fail("expected 'key: value' in '" + str(item) + "'");
      const std::string_view k = trim(item.substr(0, colon));
      const std::string_view v = trim(item.substr(colon + 1));
      if (k == "basis") {
        if (v == "none")
          out.basis = OffsetBasis::none;
        else if (v == "shoulders")
          out.basis = OffsetBasis::shoulders;
        else if (v == "hips")
          out.basis = OffsetBasis::hips;
        else if (v == "bone")
          out.basis = OffsetBasis::bone;
        else
          fail("unknown basis '" + str(v) + "' (none, shoulders, hips, bone)");
        have_basis = true;
      } else if (k == "along") {
        out.along = number(k, v);
        have_along = true;
      } else if (k == "lateral") {
        out.lateral = number(k, v);
        have_lateral = true;
      } else if (k == "forward") {
        out.forward = number(k, v);
        have_forward = true;
      } else {
        fail("unknown key '" + str(k) + "' (basis, along, lateral, forward)");
      }
    }
    if (!have_basis) fail("no 'basis'");
    if (out.basis != OffsetBasis::none && !have_along) fail("no 'along'");
    if ((out.basis == OffsetBasis::shoulders || out.basis == OffsetBasis::hips) && !have_lateral)
      fail("no 'lateral'");
    if ((out.basis == OffsetBasis::none || out.basis == OffsetBasis::bone) && have_lateral &&
        out.lateral != 0.0f)
      fail("'lateral' only applies to the shoulders and hips bases");
    if ((out.basis == OffsetBasis::none || out.basis == OffsetBasis::bone) && have_forward &&
        out.forward != 0.0f)
      fail("'forward' only applies to the shoulders and hips bases");
    if (out.basis == OffsetBasis::none && out.along != 0.0f) fail("basis none takes no 'along'");
    return out;
  }

  std::string_view text_;
  std::string file_;
  long line_ = 0;
};

glm::vec2 trunk_normal(const glm::vec2&, const glm::vec2&) { return glm::vec2(0.0f); }
glm::vec3 trunk_normal(const glm::vec3& lateral, const glm::vec3& trunk) {
  const float n = glm::length(lateral);
  return n > 0.0f ? glm::cross(lateral, trunk) / n : glm::vec3(0.0f);
}

// The vectors of the model from a body (2D or 3D); false when a needed joint is missing.
template <class Point, class Present>
bool basis_vector(const JointOffset& o, int j, const std::array<Point, kBodyJoints>& p,
                  Present&& present, Point& out) {
  const int rs = index(Joint::right_shoulder), ls = index(Joint::left_shoulder);
  const int rh = index(Joint::right_hip), lh = index(Joint::left_hip);
  switch (o.basis) {
    case OffsetBasis::none:
      return false;
    case OffsetBasis::shoulders:
    case OffsetBasis::hips: {
      for (int k : {rs, ls, rh, lh})
        if (!present(k)) return false;
      const Point trunk = 0.5f * (p[rs] + p[ls]) - 0.5f * (p[rh] + p[lh]);
      const Point lateral = o.basis == OffsetBasis::shoulders ? p[ls] - p[rs] : p[lh] - p[rh];
      out = o.along * trunk + o.lateral * lateral + o.forward * trunk_normal(lateral, trunk);
      return true;
    }
    case OffsetBasis::bone: {
      const int parent = kJointParent[j];
      if (parent < 0 || !present(j) || !present(parent)) return false;
      out = o.along * (p[j] - p[parent]);
      return true;
    }
  }
  return false;
}

}  // namespace

LayoutOffsets parse_layout_offsets(std::string_view text, const std::string& file_name) {
  return Parser(text, file_name).parse();
}

LayoutOffsets load_layout_offsets(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "cannot open the layout offsets file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  if (text.size() > (1u << 20))
    throw InputError(file.string(), "larger than 1 MB: not a layout offsets file");
  return parse_layout_offsets(text, file.string());
}

std::string format_layout_offsets(const LayoutOffsets& o, std::string_view header) {
  std::ostringstream out;
  std::istringstream lines{std::string(header)};
  for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  out << "format: " << kLayoutOffsetsFormat << "\n";
  out << "layout: " << layout(o.layout).name << "\n";
  out << "joints:\n";
  char number[32];
  for (int j = 0; j < kBodyJoints; ++j) {
    const JointOffset& jo = o.joints[j];
    out << "  " << kJointNames[j] << ": {basis: " << basis_name(jo.basis);
    if (jo.basis != OffsetBasis::none) {
      std::snprintf(number, sizeof number, "%.4f", static_cast<double>(jo.along));
      out << ", along: " << number;
    }
    if (jo.basis == OffsetBasis::shoulders || jo.basis == OffsetBasis::hips) {
      std::snprintf(number, sizeof number, "%.4f", static_cast<double>(jo.lateral));
      out << ", lateral: " << number;
      std::snprintf(number, sizeof number, "%.4f", static_cast<double>(jo.forward));
      out << ", forward: " << number;
    }
    out << "}\n";
  }
  return out.str();
}

std::string layout_offsets_file_name(LayoutId id) {
  std::string name;
  for (char c : layout(id).name)
    if (std::isalnum(static_cast<unsigned char>(c)))
      name.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  return name + ".yaml";
}

std::optional<fs::path> find_layout_offsets(LayoutId id) {
  const std::string name = layout_offsets_file_name(id);
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("MOCAP_LAYOUT_DIR"); env && *env) dirs.emplace_back(env);
  dirs.push_back(install_root() / "calibration" / "layouts");
  dirs.push_back(fs::path("calibration") / "layouts");
  for (const fs::path& dir : dirs) {
    std::error_code ec;
    if (fs::is_regular_file(dir / name, ec)) return dir / name;
  }
  return std::nullopt;
}

std::optional<LayoutOffsets> resolve_layout_offsets(std::string_view setting, LayoutId id) {
  if (setting == "off" || setting.empty()) return std::nullopt;
  if (setting == "auto") {
    const auto file = find_layout_offsets(id);
    if (!file) return std::nullopt;
    return load_layout_offsets(*file);
  }
  LayoutOffsets offsets = load_layout_offsets(fs::path(setting));
  if (offsets.layout != id)
    throw InputError(std::string(setting), "holds offsets for " +
                                               std::string(layout(offsets.layout).name) +
                                               ", the input is " + std::string(layout(id).name));
  return offsets;
}

void apply_layout_offsets(const LayoutOffsets& offsets, std::span<float, kBodyJoints * 3> body) {
  std::array<glm::vec2, kBodyJoints> p;
  std::array<bool, kBodyJoints> ok;
  for (int j = 0; j < kBodyJoints; ++j) {
    p[j] = {body[3 * j], body[3 * j + 1]};
    ok[j] = body[3 * j + 2] > 0.0f && std::isfinite(p[j].x) && std::isfinite(p[j].y);
  }
  const auto present = [&](int k) { return ok[k]; };
  for (int j = 0; j < kBodyJoints; ++j) {
    glm::vec2 d;
    if (!ok[j] || !basis_vector(offsets.joints[j], j, p, present, d)) continue;
    body[3 * j] = p[j].x + d.x;
    body[3 * j + 1] = p[j].y + d.y;
  }
}

void apply_layout_offsets_3d(const LayoutOffsets& offsets,
                             std::array<glm::vec3, kBodyJoints>& joints, float direction) {
  const std::array<glm::vec3, kBodyJoints> p = joints;
  const auto present = [&](int k) {
    return std::isfinite(p[k].x) && std::isfinite(p[k].y) && std::isfinite(p[k].z);
  };
  for (int j = 0; j < kBodyJoints; ++j) {
    glm::vec3 d;
    if (!present(j) || !basis_vector(offsets.joints[j], j, p, present, d)) continue;
    joints[j] = p[j] + direction * d;
  }
}

}  // namespace mocap::recon
