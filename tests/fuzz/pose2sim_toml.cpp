// Fuzz target: Pose2Sim calibration TOML (camera/pose2sim_calibration.hpp).

#include "camera/pose2sim_calibration.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.toml";
  try {
    const auto cameras = camera::parse_pose2sim_calibration(fuzz::text(data, size), name);
    fuzz::check(!cameras.empty(), "a calibration without cameras was accepted");
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
