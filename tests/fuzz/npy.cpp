// Fuzz target: NumPy .npy files (io/npz.hpp parse_npy), numeric and pickled object arrays.

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "io/npz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.npy";
  io::NpyLimits limits;
  limits.zip.max_member_bytes = 64u << 20;  // below libFuzzer's memory limit
  try {
    const io::NpyContent content = io::parse_npy(fuzz::text(data, size), name, limits);
    if (!content.objects) {
      std::size_t count = 0;
      fuzz::check(io::element_count(content.array.shape, count) && count == content.array.count(),
                  "array shape and count disagree");
      (void)content.array.to_doubles();
    }
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
