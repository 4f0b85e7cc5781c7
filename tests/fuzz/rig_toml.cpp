// Fuzz target: TOML rig files, the Pose2Sim/anipose calibration layout (camera/rig_file.hpp
// parse_rig_toml). A rig that reads must be one the rest of the program can use, and must write
// and read back the same.

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.toml";
  camera::Rig rig;
  try {
    rig = camera::parse_rig_toml(fuzz::text(data, size), name);
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
    return 0;
  }
  fuzz::check(!rig.cameras.empty(), "a rig without cameras was accepted");
  fuzz::check(camera::rig_problem(rig).empty(), "a rig with a problem was accepted");
  try {
    // A 3x3 rotation read within the orthonormality tolerance comes back orthonormal, so the
    // first round trip is checked loosely and the second exactly.
    const camera::Rig again = camera::parse_rig_toml(camera::format_rig_toml(rig), "written");
    fuzz::check(camera::rigs_match(rig, again, 1e-4), "a rig does not read back as written");
    const camera::Rig twice = camera::parse_rig_toml(camera::format_rig_toml(again), "written");
    fuzz::check(camera::rigs_match(again, twice), "a rig does not read back as written");
  } catch (const InputError& e) {
    fuzz::fail(std::string("a rig that was read does not read back: ") + e.what());
  }
  return 0;
}
