#pragma once
// What `mocap rig info` prints about a rig: its cameras (size, focal lengths, principal point,
// distortion), their positions and optical axes in the world, the baselines and the angles
// between optical axes of every pair, and the floor (with each camera's height and tilt above
// it). Plain text tables.

#include <string>

#include "camera/rig.hpp"

namespace mocap::camera {

std::string rig_report(const Rig& rig);

// The names of OpenCV's distortion coefficients in order (k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tx
// ty; fisheye: k1 k2 k3 k4) with their values, "none" without distortion.
std::string describe_distortion(const Camera& camera);

}  // namespace mocap::camera
