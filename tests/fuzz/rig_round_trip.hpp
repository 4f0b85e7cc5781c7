#pragma once
// What the rig fuzz targets (rig_toml.cpp, rig_yaml.cpp) check for either format: a rig that
// reads is one the rest of the program can use, and it writes and reads back the same.

#include <string>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

namespace mocap::fuzz {

using RigParser = camera::Rig (*)(std::string_view text, const std::string& name);
using RigFormatter = std::string (*)(const camera::Rig& rig);

inline int check_rig_reader(const std::uint8_t* data, std::size_t size, const std::string& name,
                            RigParser parse, RigFormatter format) {
  camera::Rig rig;
  try {
    rig = parse(text(data, size), name);
  } catch (const InputError& e) {
    expect_named(e, name);
    return 0;
  }
  check(!rig.cameras.empty(), "a rig without cameras was accepted");
  check(camera::rig_problem(rig).empty(), "a rig with a problem was accepted");
  try {
    // A 3x3 rotation read within the orthonormality tolerance comes back orthonormal, so the
    // first round trip is checked loosely and the second exactly.
    const camera::Rig again = parse(format(rig), "written");
    check(camera::rigs_match(rig, again, 1e-4), "a rig does not read back as written");
    const camera::Rig twice = parse(format(again), "written");
    check(camera::rigs_match(again, twice), "a rig does not read back as written");
  } catch (const InputError& e) {
    fail(std::string("a rig that was read does not read back: ") + e.what());
  }
  return 0;
}

}  // namespace mocap::fuzz
