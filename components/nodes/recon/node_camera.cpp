#include "nodes/recon/node_camera.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "camera/camera_file.hpp"
#include "core/input_error.hpp"

namespace mocap::nodes {

void declare_camera_params(graph::Contract& c) {
  c.param<int>("image_width", 0,
               "input image width in pixels; with image_height and hfov_deg the camera when no "
               "camera file is given (0: unknown)",
               {0, 100000});
  c.param<int>("image_height", 0, "input image height in pixels", {0, 100000});
  c.param<double>("hfov_deg", 60.0, "horizontal field of view assumed without a camera file",
                  {1.0, 179.0});
  c.param<std::string>("camera", "",
                       "calibrated camera: a rig file of one camera (OpenCV YAML from `mocap "
                       "calibrate intrinsics`, or TOML/YAML, docs/cameras.md): its matrix and "
                       "distortion replace image_width/height and hfov_deg");
}

NodeCamera read_camera_params(const graph::Context& ctx) {
  NodeCamera out;
  const int width = ctx.param<int>("image_width"), height = ctx.param<int>("image_height");
  if (const std::string file = ctx.param<std::string>("camera"); !file.empty()) {
    out.camera = camera::read_camera_file(file);
    if (width > 0 && height > 0 && (width != out.camera.width || height != out.camera.height))
      throw InputError(file, "is a camera of " + std::to_string(out.camera.width) + "x" +
                                 std::to_string(out.camera.height) + " pixels, the input is " +
                                 std::to_string(width) + "x" + std::to_string(height));
  } else if (width > 0 && height > 0) {
    out.hfov_deg = ctx.param<double>("hfov_deg");
    out.camera = camera::Camera::from_fov(width, height, out.hfov_deg);
    out.assumed = true;
  }
  return out;
}

void undistort(const NodeCamera& camera, std::array<Keypoint2D, kBodyJoints>& keypoints) {
  if (!camera.camera.has_distortion()) return;
  constexpr float kMissing = std::numeric_limits<float>::quiet_NaN();
  std::array<std::array<float, 2>, kBodyJoints> pixels;
  for (std::size_t j = 0; j < pixels.size(); ++j) {
    const Keypoint2D& k = keypoints[j];
    pixels[j] = k.confidence > 0 ? std::array<float, 2>{k.x, k.y}
                                 : std::array<float, 2>{kMissing, kMissing};
  }
  camera.camera.undistort_pixels(pixels);
  for (std::size_t j = 0; j < pixels.size(); ++j) {
    if (!(keypoints[j].confidence > 0)) continue;
    keypoints[j].x = pixels[j][0];
    keypoints[j].y = pixels[j][1];
  }
}

}  // namespace mocap::nodes
