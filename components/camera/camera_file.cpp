#include "camera/camera_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "core/input_error.hpp"

namespace mocap::camera {
namespace {

cv::FileNode required(const cv::FileStorage& fs, const std::string& path, const std::string& key) {
  cv::FileNode node = fs[key];
  if (node.empty() || node.isNone()) throw InputError(path, "missing key '" + key + "'");
  return node;
}

int read_size(const cv::FileStorage& fs, const std::string& path, const std::string& key) {
  const cv::FileNode node = required(fs, path, key);
  if (!node.isInt()) throw InputError(path, "key '" + key + "' is not an integer");
  const int value = static_cast<int>(node);
  if (value <= 0) throw InputError(path, "key '" + key + "' must be positive");
  return value;
}

cv::Mat read_matrix(const cv::FileStorage& fs, const std::string& path, const std::string& key) {
  const cv::FileNode node = required(fs, path, key);
  // OpenCV allocates rows x cols before it reads the data: the shape is checked first against
  // the data and a size no camera file needs, so "rows: 2000000000" cannot allocate gigabytes.
  if (!node.isMap()) throw InputError(path, "key '" + key + "' is not an OpenCV matrix");
  const cv::FileNode rows = node["rows"], cols = node["cols"], values = node["data"];
  if (!rows.isInt() || !cols.isInt() || !values.isSeq())
    throw InputError(path, "key '" + key + "' is not an OpenCV matrix (rows, cols, data)");
  constexpr int kMaxSide = 64;
  const int r = static_cast<int>(rows), c = static_cast<int>(cols);
  if (r < 1 || c < 1 || r > kMaxSide || c > kMaxSide ||
      values.size() != static_cast<std::size_t>(r) * static_cast<std::size_t>(c))
    throw InputError(path, "key '" + key + "' has a shape (" + std::to_string(r) + "x" +
                               std::to_string(c) + ") that does not fit its " +
                               std::to_string(values.size()) + " values");
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception&) {
    throw InputError(path, "key '" + key + "' is not an OpenCV matrix");
  }
  if (m.empty()) throw InputError(path, "key '" + key + "' is not an OpenCV matrix");
  if (m.channels() != 1) throw InputError(path, "key '" + key + "' has more than one channel");
  cv::Mat d;
  m.convertTo(d, CV_64F);
  for (auto it = d.begin<double>(); it != d.end<double>(); ++it)
    if (!std::isfinite(*it)) throw InputError(path, "key '" + key + "' has a non-finite value");
  return d;
}

// Camera files are a few hundred bytes; anything beyond this is not one.
constexpr std::uintmax_t kMaxCameraFileBytes = 1u << 20;

std::string read_camera_text(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "no such file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size == 0) throw InputError(path, "empty file");
  if (size > kMaxCameraFileBytes)
    throw InputError(path, "too large for a camera file (" + std::to_string(size) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(text.size())))
    throw InputError(path, "read error");
  return text;
}

void open_text(cv::FileStorage& fs, std::string_view text, const std::string& name) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos)
    throw InputError(name, "empty file");
  if (text.size() > kMaxCameraFileBytes) throw InputError(name, "too large for a camera file");
  // OpenCV reads C strings: text with a NUL byte would be cut there, so it is refused whole.
  if (text.find('\0') != std::string_view::npos)
    throw InputError(name, "not a text file (NUL byte)");
  // A camera file is one YAML document whose start line is "---" alone, as OpenCV writes it.
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
      throw InputError(name, "a YAML document end ('...'): a camera file is one document");
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
  try {
    if (!fs.open(std::string(text), cv::FileStorage::READ | cv::FileStorage::MEMORY))
      throw InputError(name, "not an OpenCV YAML/XML/JSON file");
    // Keys are looked up in the root node: OpenCV throws for any other kind there.
    if (!fs.root().isMap())
      throw InputError(name, "not a camera file (its top level is not a map of keys)");
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

// Why a plane cannot be stored, or empty.
std::string plane_problem(const GroundPlane& p) {
  const auto& n = p.normal;
  for (double v : n)
    if (!std::isfinite(v)) return "'ground_normal' has a non-finite value";
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (length < 1e-9) return "'ground_normal' is the zero vector";
  if (std::abs(length - 1.0) > 1e-3)
    return "'ground_normal' must be a unit vector, its length is " + std::to_string(length);
  if (!std::isfinite(p.offset)) return "'ground_offset' is not finite";
  return {};
}

}  // namespace

double camera_height_m(const GroundPlane& plane) { return plane.offset; }

double camera_tilt_deg(const GroundPlane& plane) {
  // The optical axis is +z; its component along "down" (-normal) is the sine of the tilt.
  const double down = std::clamp(-plane.normal[2], -1.0, 1.0);
  return std::asin(down) * 180.0 / std::numbers::pi;
}

std::optional<GroundPlane> read_ground_plane(const std::string& path) {
  return parse_ground_plane(read_camera_text(path), path);
}

std::optional<GroundPlane> parse_ground_plane(std::string_view text, const std::string& path) {
  cv::FileStorage fs;
  open_text(fs, text, path);
  const auto present = [&](const char* key) {
    try {
      const cv::FileNode node = fs[key];
      return !node.empty() && !node.isNone();
    } catch (const cv::Exception& e) {
      throw InputError(path, "malformed camera file (" + e.err + ")");
    }
  };
  const bool has_normal = present("ground_normal");
  const bool has_offset = present("ground_offset");
  if (!has_normal && !has_offset) return std::nullopt;
  if (!has_normal) throw InputError(path, "missing key 'ground_normal' (ground_offset is given)");
  if (!has_offset) throw InputError(path, "missing key 'ground_offset' (ground_normal is given)");
  GroundPlane plane;
  try {
    const cv::Mat n = read_matrix(fs, path, "ground_normal");
    if ((n.rows != 1 && n.cols != 1) || n.total() != 3)
      throw InputError(path, "key 'ground_normal' must be a 3x1 matrix, not " +
                                 std::to_string(n.rows) + "x" + std::to_string(n.cols));
    for (int i = 0; i < 3; ++i) plane.normal[i] = n.at<double>(i);
    const cv::FileNode offset = fs["ground_offset"];
    if (!offset.isReal() && !offset.isInt())
      throw InputError(path, "key 'ground_offset' is not a number");
    plane.offset = static_cast<double>(offset);
  } catch (const cv::Exception& e) {
    throw InputError(path, "malformed ground plane (" + e.err + ")");
  }
  if (const std::string problem = plane_problem(plane); !problem.empty())
    throw InputError(path, "key " + problem);
  return plane;
}

void write_ground_plane(const std::string& path, const GroundPlane& plane) {
  if (const std::string problem = plane_problem(plane); !problem.empty())
    throw std::invalid_argument("write_ground_plane: " + problem);
  const CameraIntrinsics camera = read_camera_file(path);
  double rms = -1.0;
  {
    cv::FileStorage fs;
    open_text(fs, read_camera_text(path), path);
    const cv::FileNode node = fs["avg_reprojection_error"];
    if (node.isReal() || node.isInt()) rms = static_cast<double>(node);
    if (!std::isfinite(rms) || rms < 0) rms = -1.0;
  }
  // Written beside the file, then renamed over it: a failed write leaves the old file intact.
  const std::string temporary = path + ".tmp";
  write_camera_file(temporary, camera, rms, plane);
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw InputError(path, "cannot replace the file");
  }
}

CameraIntrinsics from_fov(int width, int height, double hfov_deg) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("from_fov: image size must be positive");
  if (!(hfov_deg > 0.0 && hfov_deg < 180.0))
    throw std::invalid_argument("from_fov: field of view must be in (0, 180) degrees");
  const double f = 0.5 * width / std::tan(0.5 * hfov_deg * std::numbers::pi / 180.0);
  CameraIntrinsics c;
  c.width = width;
  c.height = height;
  c.K = {f, 0.0, 0.5 * (width - 1), 0.0, f, 0.5 * (height - 1), 0.0, 0.0, 1.0};
  c.distortion.assign(5, 0.0);
  return c;
}

CameraIntrinsics read_camera_file(const std::string& path) {
  return parse_camera_file(read_camera_text(path), path);
}

CameraIntrinsics parse_camera_file(std::string_view text, const std::string& path) {
  cv::FileStorage fs;
  open_text(fs, text, path);
  CameraIntrinsics c;
  try {
    c.width = read_size(fs, path, "image_width");
    c.height = read_size(fs, path, "image_height");
    const cv::Mat K = read_matrix(fs, path, "camera_matrix");
    if (K.rows != 3 || K.cols != 3)
      throw InputError(path, "key 'camera_matrix' must be 3x3, not " + std::to_string(K.rows) +
                                 "x" + std::to_string(K.cols));
    for (int i = 0; i < 9; ++i) c.K[i] = K.at<double>(i / 3, i % 3);
    if (!(c.K[0] > 0 && c.K[4] > 0))
      throw InputError(path, "key 'camera_matrix' has non-positive focal lengths");
    const cv::Mat D = read_matrix(fs, path, "distortion_coefficients");
    const int n = static_cast<int>(D.total());
    if ((D.rows != 1 && D.cols != 1) || !(n == 4 || n == 5 || n == 8 || n == 12 || n == 14))
      throw InputError(path,
                       "key 'distortion_coefficients' must be a vector of 4, 5, 8, 12 or 14 "
                       "values, not " +
                           std::to_string(D.rows) + "x" + std::to_string(D.cols));
    c.distortion.assign(D.begin<double>(), D.end<double>());
  } catch (const cv::Exception& e) {
    throw InputError(path, "malformed camera file (" + e.err + ")");
  }
  return c;
}

void write_camera_file(const std::string& path, const CameraIntrinsics& camera, double rms_px,
                       const std::optional<GroundPlane>& ground) {
  if (ground)
    if (const std::string problem = plane_problem(*ground); !problem.empty())
      throw std::invalid_argument("write_camera_file: " + problem);
  try {
    cv::FileStorage fs(path, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) throw InputError(path, "cannot write");
    fs << "image_width" << camera.width;
    fs << "image_height" << camera.height;
    cv::Mat K(3, 3, CV_64F);
    for (int i = 0; i < 9; ++i) K.at<double>(i / 3, i % 3) = camera.K[i];
    fs << "camera_matrix" << K;
    // An empty distortion is written as five zeros, since OpenCV cannot store an empty matrix.
    const int n = camera.distortion.empty() ? 5 : static_cast<int>(camera.distortion.size());
    cv::Mat D = cv::Mat::zeros(1, n, CV_64F);
    for (size_t i = 0; i < camera.distortion.size(); ++i)
      D.at<double>(0, static_cast<int>(i)) = camera.distortion[i];
    fs << "distortion_coefficients" << D;
    if (rms_px >= 0) fs << "avg_reprojection_error" << rms_px;
    if (ground) {
      fs << "ground_normal" << cv::Mat(3, 1, CV_64F, const_cast<double*>(ground->normal.data()));
      fs << "ground_offset" << ground->offset;
    }
    fs.release();
  } catch (const cv::Exception& e) {
    throw InputError(path, "cannot write (" + e.err + ")");
  }
}

}  // namespace mocap::camera
