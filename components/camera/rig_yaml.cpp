// The OpenCV YAML side of rig_file.hpp (cv::FileStorage): a `cameras` list, or the single-camera
// file of `mocap calibrate intrinsics`.

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <opencv2/core.hpp>

#include "camera/rig_file.hpp"
#include "camera/rig_text.hpp"
#include "core/input_error.hpp"
#include "core/messages.hpp"

namespace mocap::camera {
namespace {

// A rig file of many cameras is a few hundred bytes per camera; anything beyond is not one.
constexpr std::size_t kMaxRigFileBytes = 1u << 20;
constexpr int kMaxMatrixSide = 64;

// Refuses, before OpenCV parses it, text its YAML parser cannot read safely.
void check_text(std::string_view text, const std::string& name) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos)
    throw InputError(name, "empty file");
  if (text.size() > kMaxRigFileBytes) throw InputError(name, "too large for a rig file");
  // OpenCV reads C strings: text with a NUL byte would be cut there, so it is refused whole.
  if (text.find('\0') != std::string_view::npos)
    throw InputError(name, "not a text file (NUL byte)");
  // A rig file is one YAML document whose start line is "---" alone, as OpenCV writes it.
  // OpenCV 4.6's YAML parser loops forever on some other starts ("----a" or "---YAML:1.0" and
  // "---", each followed by a list) and looks keys up outside root() when there are two
  // documents, so both are refused before it parses.
  int document_starts = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, end - at);
    // Directives ("%YAML:1.0") only as the first line, document ends ("...") not at all: OpenCV
    // also loops forever on texts that mix them with document starts.
    if (line.starts_with("%") && (at != 0 || line.find("---") != std::string_view::npos))
      throw InputError(name, "a YAML directive ('%') after the first line or with '---' on it");
    if (line.starts_with("..."))
      throw InputError(name, "a YAML document end ('...'): a rig file is one document");
    if (text.compare(at, 3, "---") == 0) {
      const std::string_view rest = text.substr(at + 3, end - at - 3);
      const std::size_t content = rest.find_first_not_of(" \t\r");
      if (content != std::string_view::npos && rest[content] != '#')
        throw InputError(name, "a '---' line with more on it (only '---' starts the document)");
      if (++document_starts > 1)
        throw InputError(name, "more than one YAML document (a second '---' line)");
    }
    at = end + 1;
  }
}

void open_text(cv::FileStorage& fs, std::string_view text, const std::string& name) {
  check_text(text, name);
  try {
    if (!fs.open(std::string(text), cv::FileStorage::READ | cv::FileStorage::MEMORY))
      throw InputError(name, "not an OpenCV YAML/XML/JSON file");
    // Keys are looked up in the root node: OpenCV throws for any other kind there.
    if (!fs.root().isMap())
      throw InputError(name, "not a rig or camera file (its top level is not a map of keys)");
  } catch (const cv::Exception& e) {
    throw InputError(name, "not a readable OpenCV YAML file (" + e.err + ")");
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    // OpenCV 4.6's YAML parser lets standard exceptions out on some malformed text (e.g.
    // std::length_error from a key it mis-measures).
    throw InputError(name, std::string("not a readable OpenCV YAML file (") + e.what() + ")");
  }
}

// The keys of one map node (the root, or one camera of `cameras`); errors name the file and,
// for a camera of a list, which one.
class Keys {
 public:
  Keys(cv::FileNode node, std::string file, std::string where)
      : node_(std::move(node)), file_(std::move(file)), where_(std::move(where)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(file_, where_ + "key '" + key + "' " + what);
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file_, where_.empty() ? what : where_ + what);
  }

  bool has(const std::string& key) const {
    const cv::FileNode n = node_[key];
    return !n.empty() && !n.isNone();
  }
  cv::FileNode required(const std::string& key) const {
    if (!has(key)) fail("missing key '" + key + "'");
    return node_[key];
  }
  int positive_int(const std::string& key) const {
    const cv::FileNode n = required(key);
    if (!n.isInt()) fail(key, "is not an integer");
    const int value = static_cast<int>(n);
    if (value <= 0) fail(key, "must be positive");
    return value;
  }
  double number(const std::string& key) const {
    const cv::FileNode n = required(key);
    if (!n.isReal() && !n.isInt()) fail(key, "is not a number");
    const double value = static_cast<double>(n);
    if (!std::isfinite(value)) fail(key, "is not finite");
    return value;
  }
  std::string text(const std::string& key) const {
    const cv::FileNode n = required(key);
    if (n.isString()) return static_cast<std::string>(n);
    if (n.isInt()) return std::to_string(static_cast<int>(n));  // a name like 1 reads as a number
    fail(key, "is not a string");
  }
  cv::Mat matrix(const std::string& key) const {
    const cv::FileNode node = required(key);
    // OpenCV allocates rows x cols before it reads the data: the shape is checked first against
    // the data and a size no rig file needs, so "rows: 2000000000" cannot allocate gigabytes.
    if (!node.isMap()) fail(key, "is not an OpenCV matrix");
    const cv::FileNode rows = node["rows"], cols = node["cols"], values = node["data"];
    if (!rows.isInt() || !cols.isInt() || !values.isSeq())
      fail(key, "is not an OpenCV matrix (rows, cols, data)");
    const int r = static_cast<int>(rows), c = static_cast<int>(cols);
    if (r < 1 || c < 1 || r > kMaxMatrixSide || c > kMaxMatrixSide ||
        values.size() != static_cast<std::size_t>(r) * static_cast<std::size_t>(c))
      fail(key, "has a shape (" + std::to_string(r) + "x" + std::to_string(c) +
                    ") that does not fit its " + std::to_string(values.size()) + " values");
    cv::Mat m;
    try {
      node >> m;
    } catch (const cv::Exception&) {
      fail(key, "is not an OpenCV matrix");
    }
    if (m.empty()) fail(key, "is not an OpenCV matrix");
    if (m.channels() != 1) fail(key, "has more than one channel");
    cv::Mat d;
    m.convertTo(d, CV_64F);
    for (auto it = d.begin<double>(); it != d.end<double>(); ++it)
      if (!std::isfinite(*it)) fail(key, "has a non-finite value");
    return d;
  }
  // A 3-vector given as 3x1 or 1x3.
  glm::dvec3 vector3(const std::string& key) const {
    const cv::Mat v = matrix(key);
    if ((v.rows != 1 && v.cols != 1) || v.total() != 3)
      fail(key, "must be a 3x1 matrix, not " + shape(v));
    return {v.at<double>(0), v.at<double>(1), v.at<double>(2)};
  }

  static std::string shape(const cv::Mat& m) {
    return std::to_string(m.rows) + "x" + std::to_string(m.cols);
  }

 private:
  cv::FileNode node_;
  std::string file_, where_;
};

// The intrinsics every camera entry has, the single-camera file's too.
void read_intrinsics(const Keys& keys, Camera& c) {
  c.width = keys.positive_int("image_width");
  c.height = keys.positive_int("image_height");
  const cv::Mat K = keys.matrix("camera_matrix");
  if (K.rows != 3 || K.cols != 3) keys.fail("camera_matrix", "must be 3x3, not " + Keys::shape(K));
  if (!(K.at<double>(0, 0) > 0 && K.at<double>(1, 1) > 0))
    keys.fail("camera_matrix", "has non-positive focal lengths");
  if (std::abs(K.at<double>(0, 1)) > 1e-9 * K.at<double>(0, 0))
    keys.fail("camera_matrix", "has a skew, which OpenCV's model does not have");
  if (K.at<double>(1, 0) != 0 || K.at<double>(2, 0) != 0 || K.at<double>(2, 1) != 0 ||
      K.at<double>(2, 2) != 1)
    keys.fail("camera_matrix", "is not [fx 0 cx; 0 fy cy; 0 0 1]");
  c.fx = K.at<double>(0, 0);
  c.cx = K.at<double>(0, 2);
  c.fy = K.at<double>(1, 1);
  c.cy = K.at<double>(1, 2);
  if (keys.has("fisheye")) {
    const cv::FileNode f = keys.required("fisheye");
    if (!f.isInt() || (static_cast<int>(f) != 0 && static_cast<int>(f) != 1))
      keys.fail("fisheye", "must be 0 or 1");
    c.fisheye = static_cast<int>(f) == 1;
  }
  const cv::Mat D = keys.matrix("distortion_coefficients");
  const std::size_t n = D.total();
  if ((D.rows != 1 && D.cols != 1) ||
      (c.fisheye ? n != 4 : !(n == 4 || n == 5 || n == 8 || n == 12 || n == 14)))
    keys.fail("distortion_coefficients",
              std::string("must be a vector of ") +
                  (c.fisheye ? "4 values (fisheye)" : "4, 5, 8, 12 or 14 values") + ", not " +
                  Keys::shape(D));
  c.distortion.assign(D.begin<double>(), D.end<double>());
  if (std::all_of(c.distortion.begin(), c.distortion.end(), [](double d) { return d == 0.0; }))
    c.distortion.clear();
}

void read_pose(const Keys& keys, Camera& c) {
  if (keys.has("rotation")) {
    const cv::Mat r = keys.matrix("rotation");
    if (r.rows == 3 && r.cols == 3) {
      for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) c.rotation[col][row] = r.at<double>(row, col);
      if (const std::string p = rotation_problem(c.rotation); !p.empty())
        keys.fail("rotation", "(a 3x3 matrix) " + p);
    } else {
      c.set_rodrigues(keys.vector3("rotation"));
    }
  }
  if (keys.has("translation")) c.translation = keys.vector3("translation");
}

std::optional<GroundPlane> read_ground(const Keys& keys) {
  const bool has_normal = keys.has("ground_normal"), has_offset = keys.has("ground_offset");
  if (!has_normal && !has_offset) return std::nullopt;
  if (!has_normal) keys.fail("missing key 'ground_normal' (ground_offset is given)");
  if (!has_offset) keys.fail("missing key 'ground_offset' (ground_normal is given)");
  GroundPlane plane{keys.vector3("ground_normal"), keys.number("ground_offset")};
  if (const std::string p = ground_problem(plane); !p.empty())
    keys.fail(p.starts_with("normal") ? "ground_normal" : "ground_offset", p.substr(7));
  return plane;
}

std::string default_name(std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof(name), "cam_%02zu", index + 1);
  return name;
}

Rig parse(const cv::FileStorage& fs, const std::string& file) {
  const Keys root(fs.root(), file, "");
  Rig rig;
  if (root.has("cameras")) {
    const cv::FileNode list = fs["cameras"];
    if (!list.isSeq() || list.empty())
      root.fail("cameras", "must be a list with one entry per camera");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const cv::FileNode entry = list[static_cast<int>(i)];
      const std::string where = "cameras[" + std::to_string(i) + "]";
      if (!entry.isMap()) throw InputError(file, where + " is not a map of keys");
      Camera c;
      const Keys unnamed(entry, file, where + ": ");
      c.name = unnamed.has("name") ? unnamed.text("name") : default_name(i);
      const Keys keys(entry, file, where + " (" + c.name + "): ");
      read_intrinsics(keys, c);
      read_pose(keys, c);
      if (const std::string p = camera_problem(c); !p.empty()) keys.fail("the camera " + p);
      for (const Camera& other : rig.cameras)
        if (other.name == c.name) keys.fail("a second camera named '" + c.name + "'");
      rig.cameras.push_back(std::move(c));
    }
  } else {
    Camera c;
    c.name = root.has("camera_name") ? root.text("camera_name") : std::string(kDefaultCamera);
    read_intrinsics(root, c);
    if (const std::string p = camera_problem(c); !p.empty()) root.fail("the camera " + p);
    rig.cameras.push_back(std::move(c));
  }
  rig.floor = read_ground(root);
  return rig;
}

// An OpenCV matrix of doubles, on its own lines after the key.
std::string matrix_text(int rows, int cols, const std::vector<double>& values) {
  std::string out = "!!opencv-matrix\n";
  const std::string indent(8, ' ');
  out += indent + "rows: " + std::to_string(rows) + "\n";
  out += indent + "cols: " + std::to_string(cols) + "\n";
  out += indent + "dt: d\n";
  out += indent + "data: [";
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += i == 0 ? " " : ", ";
    out += detail::real_text(values[i]);
  }
  out += " ]\n";
  return out;
}

}  // namespace

Rig parse_rig_yaml(std::string_view text, const std::string& name) {
  cv::FileStorage fs;
  open_text(fs, text, name);
  try {
    return parse(fs, name);
  } catch (const cv::Exception& e) {
    throw InputError(name, "malformed rig file (" + e.err + ")");
  }
}

std::string format_rig_yaml(const Rig& rig) {
  if (const std::string p = rig_problem(rig); !p.empty())
    throw std::invalid_argument("format_rig_yaml: " + p);
  // Written as text rather than through cv::FileStorage, which leaves a name like 1e5 unquoted
  // (it would read back as a number).
  std::ostringstream out;
  out << "%YAML:1.0\n---\n"
      << "# A camera rig (docs/cameras.md), metres. rotation (Rodrigues vector) and translation:\n"
      << "# world -> camera (x_c = R x_w + t). ground_normal, ground_offset: the floor in the "
         "world,\n"
      << "# dot(normal, x) + offset = 0 with the normal up.\n"
      << "cameras:\n";
  for (const Camera& c : rig.cameras) {
    // OpenCV cannot store an empty matrix: no distortion is written as zeros.
    std::vector<double> d = c.distortion;
    if (d.empty()) d.assign(c.fisheye ? 4 : 5, 0.0);
    const glm::dvec3 r = c.rodrigues();
    out << "   - name: " << detail::quoted(c.name) << "\n"
        << "     image_width: " << c.width << "\n"
        << "     image_height: " << c.height << "\n"
        << "     camera_matrix: "
        << matrix_text(3, 3, {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0})
        << "     distortion_coefficients: " << matrix_text(1, static_cast<int>(d.size()), d)
        << "     fisheye: " << (c.fisheye ? 1 : 0) << "\n"
        << "     rotation: " << matrix_text(3, 1, {r.x, r.y, r.z}) << "     translation: "
        << matrix_text(3, 1, {c.translation.x, c.translation.y, c.translation.z});
  }
  if (rig.floor) {
    const GroundPlane& f = *rig.floor;
    out << "ground_normal: " << matrix_text(3, 1, {f.normal.x, f.normal.y, f.normal.z})
        << "ground_offset: " << detail::real_text(f.offset) << "\n";
  }
  return out.str();
}

}  // namespace mocap::camera
