#pragma once
// The camera of the nodes that need one (recon.temporal_selector, recon.fit, sink.web): the same
// parameters (`camera`: a rig file of one camera, e.g. the single-camera file of `mocap calibrate
// intrinsics`; or `image_width`, `image_height` and `hfov_deg`) read the same way.

#include <array>

#include "camera/camera.hpp"
#include "core/messages.hpp"
#include "graph/node.hpp"

namespace mocap::nodes {

struct NodeCamera {
  camera::Camera camera;  // without intrinsics (fx 0): neither a file nor an image size
  bool assumed = false;   // the pinhole of a field of view, not calibrated
  double hfov_deg = 0.0;  // when assumed

  bool known() const { return camera.has_intrinsics(); }
};

void declare_camera_params(graph::Contract& c);

// Throws InputError naming the camera file when it is unreadable, holds more than one camera or
// its size is not the input's.
NodeCamera read_camera_params(const graph::Context& ctx);

// The pixels the undistorted camera would see (unchanged without a lens distortion); missing
// keypoints (confidence 0 or non-finite) are left as they are.
void undistort(const NodeCamera& camera, std::array<Keypoint2D, kBodyJoints>& keypoints);

}  // namespace mocap::nodes
