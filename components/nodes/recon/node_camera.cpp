#include "nodes/recon/node_camera.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "camera/undistortion.hpp"
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
                       "calibrated camera file (OpenCV YAML, `mocap calibrate intrinsics`): its "
                       "matrix and distortion replace image_width/height and hfov_deg");
}

NodeCamera read_camera_params(const graph::Context& ctx) {
  NodeCamera out;
  const int width = ctx.param<int>("image_width"), height = ctx.param<int>("image_height");
  if (const std::string file = ctx.param<std::string>("camera"); !file.empty()) {
    out.lens = camera::read_camera_file(file);
    if (width > 0 && height > 0 && (width != out.lens->width || height != out.lens->height))
      throw InputError(file, "is a camera of " + std::to_string(out.lens->width) + "x" +
                                 std::to_string(out.lens->height) + " pixels, the input is " +
                                 std::to_string(width) + "x" + std::to_string(height));
    out.pinhole = {static_cast<float>(out.lens->fx()), static_cast<float>(out.lens->fy()),
                   static_cast<float>(out.lens->cx()), static_cast<float>(out.lens->cy())};
  } else if (width > 0 && height > 0) {
    out.hfov_deg = ctx.param<double>("hfov_deg");
    out.pinhole = recon::Pinhole::from_fov(width, height, static_cast<float>(out.hfov_deg));
    out.assumed = true;
  }
  return out;
}

void undistort(const NodeCamera& camera, std::array<Keypoint2D, kBodyJoints>& keypoints) {
  if (!camera.lens) return;
  constexpr float kMissing = std::numeric_limits<float>::quiet_NaN();
  std::array<std::array<float, 2>, kBodyJoints> pixels;
  for (std::size_t j = 0; j < pixels.size(); ++j) {
    const Keypoint2D& k = keypoints[j];
    pixels[j] = k.confidence > 0 ? std::array<float, 2>{k.x, k.y}
                                 : std::array<float, 2>{kMissing, kMissing};
  }
  camera::undistort_pixels(*camera.lens, pixels);
  for (std::size_t j = 0; j < pixels.size(); ++j) {
    if (!(keypoints[j].confidence > 0)) continue;
    keypoints[j].x = pixels[j][0];
    keypoints[j].y = pixels[j][1];
  }
}

}  // namespace mocap::nodes
