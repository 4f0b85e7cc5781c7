// Fuzz target: HumanEva camera JSON (io/humaneva.hpp parse_cameras). The rigs that read must be
// usable and their cameras project a point in front of them without crashing.

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "io/humaneva.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.json";
  try {
    const auto subjects = io::humaneva::parse_cameras(fuzz::text(data, size), name);
    for (const auto& [subject, rig] : subjects) {
      fuzz::check(camera::rig_problem(rig).empty(), "a camera with a problem was accepted");
      for (const auto& c : rig.cameras) (void)c.project(c.centre() + c.optical_axis());
    }
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
