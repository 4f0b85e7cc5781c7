#pragma once
// The one camera model of the project (docs/cameras.md): a pinhole with OpenCV's lens distortion
// and a pose in a world frame, in the conventions OpenCV, Pose2Sim, anipose, Caliscope and
// FreeMoCap share:
//
//   camera coordinates  x right, y down, z forward (along the optical axis), metres
//   world -> camera     x_c = R x_w + t          (R: rotation, t: translation)
//   centre              C = -Rᵀ t                 (the camera's position in the world)
//   pixel               K · distort(x_c / z_c)    K = [fx 0 cx; 0 fy cy; 0 0 1]
//
// Pixel (0, 0) is the centre of the top-left pixel (OpenCV). Without a pose the camera's frame is
// the world (R = I, t = 0). The distortion follows OpenCV exactly (its projectPoints and
// undistortPoints do the work; fisheye: cv::fisheye); OpenCV stays in camera.cpp.

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace mocap::camera {

struct Camera {
  std::string name;  // unique within a rig ("cam_01")
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels
  // OpenCV's coefficients k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tx ty]]]] (0, 4, 5, 8, 12 or
  // 14 values); with `fisheye`, cv::fisheye's k1 k2 k3 k4. Empty or all zero: no distortion.
  std::vector<double> distortion;
  bool fisheye = false;
  glm::dmat3 rotation{1.0};     // R, world -> camera (glm is column-major: rotation[col][row])
  glm::dvec3 translation{0.0};  // t, world -> camera, metres

  // A camera of `width` x `height` pixels whose horizontal field of view is `hfov_deg`, square
  // pixels, the principal point at (width / 2, height / 2), no distortion, at the world origin:
  // what the monocular pipeline assumes without a calibration. Throws std::invalid_argument for a
  // non-positive size or a field of view outside (0, 180).
  static Camera from_fov(int width, int height, double hfov_deg, std::string name = "cam_01");

  bool has_intrinsics() const { return fx > 0 && fy > 0; }
  bool has_distortion() const;
  std::array<double, 9> matrix() const;  // K, row-major

  // The pose.
  glm::dvec3 rodrigues() const;  // the rotation as a Rodrigues (angle-axis) vector
  void set_rodrigues(const glm::dvec3& r);
  // Places the camera by its centre in the world and the rotation camera -> world (its columns
  // are the camera's x, y, z axes in the world), the convention of VideoPose3D and Blender-like
  // tools: R = camera_to_worldᵀ, t = -R · centre.
  void set_pose_from_centre(const glm::dmat3& camera_to_world, const glm::dvec3& centre);
  glm::dvec3 centre() const;        // C = -Rᵀ t
  glm::dvec3 optical_axis() const;  // the camera's +z in the world (unit)
  glm::dvec3 to_camera(const glm::dvec3& world) const { return rotation * world + translation; }
  glm::dvec3 to_world(const glm::dvec3& in_camera) const;

  // Projection. A point on or behind the camera plane (z_c <= 0) projects to NaN.
  glm::dvec2 project(const glm::dvec3& world) const;          // with the lens distortion
  glm::dvec2 project_pinhole(const glm::dvec3& world) const;  // without it
  // Camera-frame points to pixels, with the distortion; one OpenCV call for all of them.
  void project_camera_points(std::span<const glm::dvec3> in_camera,
                             std::span<glm::dvec2> pixels) const;
  // Where an ideal (undistorted) pixel is seen in the real image, and back: where a pixel of
  // the real image would be without lens distortion (same K). Identity without distortion;
  // non-finite pixels stay as they are. Undistortion iterates to 1e-6 px where OpenCV's default
  // stops after five steps.
  glm::dvec2 distort_pixel(const glm::dvec2& undistorted) const;
  glm::dvec2 undistort_pixel(const glm::dvec2& distorted) const;
  // Many pixels in place (a person's keypoints: one OpenCV call).
  void undistort_pixels(std::span<std::array<float, 2>> pixels) const;
  // The unit direction, in the world, of the ray from the centre through a (distorted) pixel.
  glm::dvec3 ray(const glm::dvec2& pixel) const;
  // The same in the camera frame.
  glm::dvec3 ray_in_camera(const glm::dvec2& pixel) const;

  bool operator==(const Camera&) const = default;
};

// The rotation matrix of a Rodrigues vector, and back (angle in [0, pi]).
glm::dmat3 rotation_from_rodrigues(const glm::dvec3& r);
glm::dvec3 rodrigues_from_rotation(const glm::dmat3& rotation);

// Why `m` is not a rotation (orthonormal within 1e-5, determinant +1), or empty.
std::string rotation_problem(const glm::dmat3& m);

// Why the camera cannot be used (no name, a non-positive or non-finite size or focal length,
// a non-finite value, a distortion of a length OpenCV does not take, a pose that is not a
// rotation), or empty.
std::string camera_problem(const Camera& camera);

}  // namespace mocap::camera
