// Fuzz target: OpenCV YAML camera files (camera/camera_file.hpp parse_camera_file and
// parse_ground_plane). A camera that reads must satisfy what the reader promises.

#include <cmath>

#include "camera/camera_file.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.yml";
  try {
    const camera::CameraIntrinsics c = camera::parse_camera_file(fuzz::text(data, size), name);
    fuzz::check(c.width > 0 && c.height > 0 && c.fx() > 0 && c.fy() > 0,
                "a camera with a non-positive size or focal length was accepted");
    for (double v : c.distortion) fuzz::check(std::isfinite(v), "non-finite distortion accepted");
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  try {
    const auto plane = camera::parse_ground_plane(fuzz::text(data, size), name);
    if (plane) fuzz::check(std::isfinite(plane->offset), "non-finite ground offset accepted");
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
