// Fuzz target: TOML rig files, the Pose2Sim/anipose calibration layout (camera/rig_file.hpp
// parse_rig_toml); the checks are rig_round_trip.hpp's.

#include "rig_round_trip.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  return fuzz::check_rig_reader(data, size, "fuzz-input.toml", camera::parse_rig_toml,
                                camera::format_rig_toml);
}
