#pragma once
// TRC marker files (OpenSim / Motion Analysis, tab-separated), as Pose2Sim writes them
// (../shared/data/eval/pose2sim_demo/README.md): line 1 `PathFileType`, lines 2-3 a header table
// (DataRate, ..., NumFrames, NumMarkers, Units, ...), line 4 `Frame#`, `Time` and the marker
// names, line 5 the X1 Y1 Z1 ... labels, data from line 6. Units are converted to metres; axes are
// kept as in the file. One last row beyond NumFrames is ignored: a writer that keeps the count
// right after every row (io/trc_writer.hpp) leaves it when killed between the row and its count.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

namespace mocap::io {

struct TrcFile {
  std::string path;
  double rate = 0.0;  // frames per second (DataRate)
  std::vector<std::string> markers;
  std::vector<std::vector<glm::vec3>> frames;  // [frame][marker], metres; NaN for empty cells

  // The column of `name`, or nullopt.
  std::optional<std::size_t> marker(std::string_view name) const;
};

// Throws InputError naming the file and line on anything malformed (wrong header, a marker count
// that does not match the names, a row with too few or unparsable numbers, unknown units).
TrcFile read_trc(const std::filesystem::path& file);
TrcFile parse_trc(std::string_view text, const std::string& file_name);

}  // namespace mocap::io
