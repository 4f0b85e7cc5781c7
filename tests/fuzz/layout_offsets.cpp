// Fuzz target: keypoint-layout offset files (recon/layout_offsets.hpp parse_layout_offsets).
// Offsets that read must be written back and read again to the same values.

#include "recon/layout_offsets.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.offsets";
  recon::LayoutOffsets offsets;
  try {
    offsets = recon::parse_layout_offsets(fuzz::text(data, size), name);
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
    return 0;
  }
  try {
    const recon::LayoutOffsets again =
        recon::parse_layout_offsets(recon::format_layout_offsets(offsets, "rewritten"), "again");
    fuzz::check(again.layout == offsets.layout, "offsets read back with another layout");
    for (std::size_t j = 0; j < offsets.joints.size(); ++j)
      fuzz::check(again.joints[j].basis == offsets.joints[j].basis,
                  "offsets read back with another basis");
  } catch (const InputError& e) {
    fuzz::fail(std::string("written offsets do not read back: ") + e.what());
  }
  return 0;
}
