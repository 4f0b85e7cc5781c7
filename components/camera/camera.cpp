#include "camera/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/matrix.hpp>
#include <opencv2/calib3d.hpp>

namespace mocap::camera {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// Undistortion iterates until the point re-distorts within this many pixels (OpenCV measures the
// reprojection error in pixels), or for at most this many steps.
constexpr double kUndistortEpsilonPx = 1e-6;
constexpr int kUndistortMaxSteps = 100;

cv::Matx33d camera_matrix(const Camera& c) { return {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0, 0, 1}; }

bool finite2(double x, double y) { return std::isfinite(x) && std::isfinite(y); }

// Undistorts `in` (pixels, all finite) into `out` with the same K.
void undistort_points(const Camera& c, const std::vector<cv::Point2d>& in,
                      std::vector<cv::Point2d>& out) {
  const cv::Matx33d K = camera_matrix(c);
  const cv::TermCriteria until(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, kUndistortMaxSteps,
                               kUndistortEpsilonPx);
  if (c.fisheye) {
    cv::fisheye::undistortPoints(in, out, K, c.distortion, cv::noArray(), K, until);
  } else {
    cv::undistortPoints(in, out, K, c.distortion, cv::noArray(), K, until);
  }
}

}  // namespace

Camera Camera::from_fov(int width, int height, double hfov_deg, std::string name) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("Camera::from_fov: image size must be positive");
  if (!(hfov_deg > 0.0 && hfov_deg < 180.0))
    throw std::invalid_argument("Camera::from_fov: field of view must be in (0, 180) degrees");
  Camera c;
  c.name = std::move(name);
  c.width = width;
  c.height = height;
  c.fx = c.fy = 0.5 * width / std::tan(0.5 * hfov_deg * std::numbers::pi / 180.0);
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  return c;
}

bool Camera::has_distortion() const {
  return std::any_of(distortion.begin(), distortion.end(), [](double d) { return d != 0.0; });
}

std::array<double, 9> Camera::matrix() const { return {fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0}; }

glm::dvec3 Camera::rodrigues() const { return rodrigues_from_rotation(rotation); }

void Camera::set_rodrigues(const glm::dvec3& r) { rotation = rotation_from_rodrigues(r); }

void Camera::set_pose_from_centre(const glm::dmat3& camera_to_world, const glm::dvec3& c) {
  rotation = glm::transpose(camera_to_world);
  translation = -(rotation * c);
}

glm::dvec3 Camera::centre() const { return -(glm::transpose(rotation) * translation); }

glm::dvec3 Camera::optical_axis() const {
  return glm::transpose(rotation) * glm::dvec3(0.0, 0.0, 1.0);
}

glm::dvec3 Camera::to_world(const glm::dvec3& in_camera) const {
  return glm::transpose(rotation) * (in_camera - translation);
}

glm::dvec2 Camera::project_pinhole(const glm::dvec3& world) const {
  const glm::dvec3 c = to_camera(world);
  if (!(c.z > 0.0)) return {kNan, kNan};
  return {fx * c.x / c.z + cx, fy * c.y / c.z + cy};
}

glm::dvec2 Camera::project(const glm::dvec3& world) const {
  if (!has_distortion()) return project_pinhole(world);
  const glm::dvec3 c = to_camera(world);
  glm::dvec2 pixel;
  project_camera_points({&c, 1}, {&pixel, 1});
  return pixel;
}

void Camera::project_camera_points(std::span<const glm::dvec3> in_camera,
                                   std::span<glm::dvec2> pixels) const {
  if (pixels.size() != in_camera.size())
    throw std::invalid_argument("Camera::project_camera_points: spans of different sizes");
  std::vector<cv::Point3d> in;
  in.reserve(in_camera.size());
  for (const glm::dvec3& p : in_camera) {
    if (p.z > 0.0 && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
      in.emplace_back(p.x, p.y, p.z);
  }
  std::vector<cv::Point2d> out;
  if (!in.empty() && has_distortion()) {
    const cv::Vec3d zero(0.0, 0.0, 0.0);
    if (fisheye) {
      // cv::fisheye takes its points as a 1xN matrix of 3-channel doubles.
      cv::fisheye::projectPoints(cv::Mat(in).reshape(3, 1), out, zero, zero, camera_matrix(*this),
                                 distortion);
    } else {
      cv::projectPoints(in, zero, zero, camera_matrix(*this), distortion, out);
    }
  } else {
    for (const cv::Point3d& p : in) out.emplace_back(fx * p.x / p.z + cx, fy * p.y / p.z + cy);
  }
  std::size_t next = 0;
  for (std::size_t i = 0; i < in_camera.size(); ++i) {
    const glm::dvec3& p = in_camera[i];
    const bool used = p.z > 0.0 && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    pixels[i] = used ? glm::dvec2(out[next].x, out[next].y) : glm::dvec2(kNan, kNan);
    next += used ? 1 : 0;
  }
}

glm::dvec2 Camera::distort_pixel(const glm::dvec2& undistorted) const {
  if (!has_distortion() || !finite2(undistorted.x, undistorted.y)) return undistorted;
  const glm::dvec3 point((undistorted.x - cx) / fx, (undistorted.y - cy) / fy, 1.0);
  glm::dvec2 pixel;
  project_camera_points({&point, 1}, {&pixel, 1});
  return pixel;
}

glm::dvec2 Camera::undistort_pixel(const glm::dvec2& distorted) const {
  if (!has_distortion() || !finite2(distorted.x, distorted.y)) return distorted;
  std::vector<cv::Point2d> out;
  undistort_points(*this, {cv::Point2d(distorted.x, distorted.y)}, out);
  return {out[0].x, out[0].y};
}

void Camera::undistort_pixels(std::span<std::array<float, 2>> pixels) const {
  if (!has_distortion()) return;
  std::vector<cv::Point2d> in;
  in.reserve(pixels.size());
  for (const auto& [x, y] : pixels)
    if (finite2(x, y)) in.emplace_back(x, y);
  if (in.empty()) return;
  std::vector<cv::Point2d> out;
  undistort_points(*this, in, out);
  std::size_t next = 0;
  for (auto& [x, y] : pixels) {
    if (!finite2(x, y)) continue;  // non-finite input stays as it is
    x = static_cast<float>(out[next].x);
    y = static_cast<float>(out[next].y);
    ++next;
  }
}

glm::dvec3 Camera::ray_in_camera(const glm::dvec2& pixel) const {
  const glm::dvec2 ideal = undistort_pixel(pixel);
  return glm::normalize(glm::dvec3((ideal.x - cx) / fx, (ideal.y - cy) / fy, 1.0));
}

glm::dvec3 Camera::ray(const glm::dvec2& pixel) const {
  return glm::transpose(rotation) * ray_in_camera(pixel);
}

glm::dmat3 rotation_from_rodrigues(const glm::dvec3& r) {
  const double theta = glm::length(r);
  if (theta < 1e-12) return glm::dmat3(1.0);
  const glm::dvec3 k = r / theta;
  const double c = std::cos(theta), s = std::sin(theta), C = 1.0 - c;
  // R = c I + s [k]x + C k kᵀ; glm is column-major: m[col][row].
  glm::dmat3 m;
  m[0] = {c + k.x * k.x * C, k.y * k.x * C + k.z * s, k.z * k.x * C - k.y * s};
  m[1] = {k.x * k.y * C - k.z * s, c + k.y * k.y * C, k.z * k.y * C + k.x * s};
  m[2] = {k.x * k.z * C + k.y * s, k.y * k.z * C - k.x * s, c + k.z * k.z * C};
  return m;
}

glm::dvec3 rodrigues_from_rotation(const glm::dmat3& rotation) {
  // Through the unit quaternion: stable at every angle, including near 0 and pi.
  glm::dquat q = glm::quat_cast(rotation);
  if (q.w < 0.0) q = -q;
  const glm::dvec3 v(q.x, q.y, q.z);
  const double s = glm::length(v);
  if (s < 1e-15) return glm::dvec3(0.0);
  const double angle = 2.0 * std::atan2(s, q.w);
  return v * (angle / s);
}

std::string rotation_problem(const glm::dmat3& m) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (!std::isfinite(m[c][r])) return "has a non-finite value";
  const glm::dmat3 product = glm::transpose(m) * m;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (std::abs(product[c][r] - (c == r ? 1.0 : 0.0)) > 1e-5) return "is not orthonormal";
  if (glm::determinant(m) < 0.0) return "is a reflection (determinant -1), not a rotation";
  return {};
}

std::string camera_problem(const Camera& c) {
  if (c.name.empty()) return "has no name";
  for (const char ch : c.name)
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f)
      return "has a control character in its name";
  if (c.width <= 0 || c.height <= 0)
    return "has a non-positive image size (" + std::to_string(c.width) + "x" +
           std::to_string(c.height) + ")";
  if (!(std::isfinite(c.fx) && std::isfinite(c.fy) && c.fx > 0 && c.fy > 0))
    return "has a non-positive or non-finite focal length";
  if (!(std::isfinite(c.cx) && std::isfinite(c.cy))) return "has a non-finite principal point";
  for (const double d : c.distortion)
    if (!std::isfinite(d)) return "has a non-finite distortion coefficient";
  const std::size_t n = c.distortion.size();
  if (c.fisheye ? !(n == 0 || n == 4)
                : !(n == 0 || n == 4 || n == 5 || n == 8 || n == 12 || n == 14))
    return "has " + std::to_string(n) + " distortion coefficients; OpenCV takes " +
           (c.fisheye ? std::string("4 (fisheye)") : std::string("4, 5, 8, 12 or 14"));
  if (const std::string p = rotation_problem(c.rotation); !p.empty()) return "rotation " + p;
  if (!(std::isfinite(c.translation.x) && std::isfinite(c.translation.y) &&
        std::isfinite(c.translation.z)))
    return "has a non-finite translation";
  return {};
}

}  // namespace mocap::camera
