// Fuzz target: HumanEva camera JSON (io/humaneva.hpp parse_cameras). Cameras that read must
// project a point in front of them without crashing.

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "io/humaneva.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.json";
  try {
    const auto subjects = io::humaneva::parse_cameras(fuzz::text(data, size), name);
    for (const auto& [subject, cameras] : subjects)
      for (const auto& c : cameras) (void)c.project(c.centre + glm::dvec3(0.0, 0.0, 1.0));
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
