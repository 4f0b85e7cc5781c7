#pragma once
// The camera of the nodes that need one (recon.temporal_selector, recon.fit): the same parameters
// (`camera` file, or `image_width`, `image_height` and `hfov_deg`) read the same way.

#include <array>
#include <optional>

#include "camera/camera_file.hpp"
#include "core/messages.hpp"
#include "graph/node.hpp"
#include "recon/ray_alignment.hpp"

namespace mocap::nodes {

struct NodeCamera {
  recon::Pinhole pinhole;                        // invalid: neither a file nor an image size
  std::optional<camera::CameraIntrinsics> lens;  // from a camera file: its distortion too
  bool assumed = false;                          // the pinhole of a field of view, not calibrated
  double hfov_deg = 0.0;                         // when assumed
};

void declare_camera_params(graph::Contract& c);

// Throws InputError naming the camera file when it is unreadable or its size is not the input's.
NodeCamera read_camera_params(const graph::Context& ctx);

// The pixels the undistorted camera would see (unchanged without a lens distortion); missing
// keypoints (confidence 0 or non-finite) are left as they are.
void undistort(const NodeCamera& camera, std::array<Keypoint2D, kBodyJoints>& keypoints);

}  // namespace mocap::nodes
