#pragma once
// One calibrated view as the multi-view library sees it: the projection of *undistorted* pixels,
// x ~ P X_w with P = K [R | t] (OpenCV conventions: x_c = R x_w + t, x right, y down, z forward).
// The library has no camera type of its own: the caller builds a ViewGeometry from its camera model
// (K, R, t, or any 3x4 matrix) and undistorts the keypoints before handing them over.

#include <array>
#include <span>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace mocap::multiview {

// Views are kept in 64-bit masks (which views a joint was triangulated from).
inline constexpr int kMaxViews = 64;

class ViewGeometry {
 public:
  // K the intrinsic matrix and R the world-to-camera rotation as GLM matrices (column-major:
  // K[2][0] is cx), t the world-to-camera translation, so that x_c = R x_w + t. The image size
  // (pixels; 0: unknown) tells which views should see a point.
  static ViewGeometry from_krt(const glm::dmat3& K, const glm::dmat3& R, const glm::dvec3& t,
                               int width = 0, int height = 0);
  // Any 3x4 projection matrix of undistorted pixels, row-major, at any scale and sign. Throws
  // std::invalid_argument when it is not finite or its left 3x3 block is singular.
  static ViewGeometry from_projection(std::span<const double, 12> row_major, int width = 0,
                                      int height = 0);

  // The matrix scaled so that depth(X) = row 3 · (X, 1): the first three entries of row 3 have
  // unit length and points in front of the camera have positive depth. Row-major.
  const std::array<double, 12>& projection() const { return p_; }
  const glm::dvec3& centre() const { return centre_; }
  // Focal length in pixels (mean of fx and fy): converts pixel errors to metres at a depth.
  double focal() const { return focal_; }

  // Distance in front of the camera along its optical axis (metres; <= 0: behind it).
  double depth(const glm::dvec3& world) const;
  // The undistorted pixel of a world point; non-finite when depth <= 0.
  glm::dvec2 project(const glm::dvec3& world) const;
  // Unit direction, in the world, of the ray from centre() through an undistorted pixel.
  glm::dvec3 ray(double x, double y) const;
  // In front of the camera and inside the image (anywhere in front when the size is unknown).
  bool sees(const glm::dvec3& world) const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  static ViewGeometry from_normalised(const std::array<double, 12>& p);

  std::array<double, 12> p_{};
  glm::dmat3 inverse_{1.0};  // of the left 3x3 block (K R): pixels to world directions
  glm::dvec3 centre_{0.0};
  double focal_ = 1.0;
  int width_ = 0, height_ = 0;
};

}  // namespace mocap::multiview
