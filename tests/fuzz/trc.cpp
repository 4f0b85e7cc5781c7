// Fuzz target: TRC marker files (io/trc.hpp parse_trc).

#include "io/trc.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.trc";
  try {
    const io::TrcFile trc = io::parse_trc(fuzz::text(data, size), name);
    for (const auto& frame : trc.frames)
      fuzz::check(frame.size() == trc.markers.size(), "a frame without a value per marker");
    if (!trc.markers.empty()) (void)trc.marker(trc.markers.back());
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
