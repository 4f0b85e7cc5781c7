// Fuzz target: NumPy .npz archives (io/npz.hpp NpzFile, io/zip_archive.hpp): the ZIP central
// directory, stored and deflated members, CRC-32, then every member as a .npy.

#include "io/npz.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.npz";
  io::NpyLimits limits;
  limits.zip.max_member_bytes = 64u << 20;  // below libFuzzer's memory limit
  try {
    const io::NpzFile npz =
        io::NpzFile::from_bytes(std::string(fuzz::text(data, size)), name, limits);
    for (const std::string& key : npz.keys()) {
      fuzz::check(npz.contains(key), "a listed key is not found");
      try {
        (void)npz.read(key);
      } catch (const InputError& e) {
        fuzz::expect_named(e, name);
      }
    }
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
