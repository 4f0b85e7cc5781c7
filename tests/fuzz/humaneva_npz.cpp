// Fuzz target: HumanEva-I as VideoPose3D stores it (io/humaneva.hpp read_positions_3d and
// attach_positions_2d on an archive in memory): an .npz whose pickled dicts are walked into
// chunks. One input may hold positions_3d, positions_2d and metadata; the 2D part is attached to
// the 3D chunks read from the same input.

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "io/humaneva.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.npz";
  io::NpyLimits limits;
  limits.zip.max_member_bytes = 64u << 20;  // below libFuzzer's memory limit
  try {
    const io::NpzFile npz =
        io::NpzFile::from_bytes(std::string(fuzz::text(data, size)), name, limits);
    io::humaneva::Dataset dataset = io::humaneva::read_positions_3d(npz, name);
    for (const auto& chunk : dataset.chunks)
      fuzz::check(!chunk.positions_3d.empty(), "a chunk without frames was accepted");
    if (npz.contains("positions_2d")) {
      io::humaneva::attach_positions_2d(dataset, npz, name);
      for (const auto& chunk : dataset.chunks)
        for (const auto& camera : chunk.positions_2d)
          fuzz::check(camera.size() == chunk.frames(), "2D and 3D frame counts differ");
    }
    (void)dataset.select(io::humaneva::Split::train, "S1");
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
