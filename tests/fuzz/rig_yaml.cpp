// Fuzz target: OpenCV YAML rig files (camera/rig_file.hpp parse_rig_yaml): a `cameras` list or
// the single-camera file of `mocap calibrate intrinsics`; the checks are rig_round_trip.hpp's.

#include "rig_round_trip.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  return fuzz::check_rig_reader(data, size, "fuzz-input.yml", camera::parse_rig_yaml,
                                camera::format_rig_yaml);
}
