#include "camera/camera_file.hpp"

#include <cmath>
#include <filesystem>
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

}  // namespace

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
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "no such file");
  if (std::filesystem::file_size(path, ec) == 0 || ec) throw InputError(path, "empty file");
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ))
      throw InputError(path, "not an OpenCV YAML/XML/JSON file");
  } catch (const cv::Exception& e) {
    throw InputError(path, "not a readable OpenCV YAML file (" + e.err + ")");
  }
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

void write_camera_file(const std::string& path, const CameraIntrinsics& camera, double rms_px) {
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
    fs.release();
  } catch (const cv::Exception& e) {
    throw InputError(path, "cannot write (" + e.err + ")");
  }
}

}  // namespace mocap::camera
