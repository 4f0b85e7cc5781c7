#pragma once
// Writing TRC marker files (OpenSim / Motion Analysis), laid out as Pose2Sim writes them and as
// io/trc.hpp reads them: line 1 `PathFileType 4 (X/Y/Z) <file name>`, lines 2-3 the header table
// (DataRate, CameraRate, NumFrames, NumMarkers, Units = m, OrigDataRate, OrigDataStartFrame,
// OrigNumFrames), line 4 `Frame#`, `Time` and each marker name followed by two empty cells, line 5
// the X1 Y1 Z1 ... labels, then one row per frame: Frame# (1-based), Time = Frame# / DataRate (as
// Pose2Sim writes it), X Y Z per marker in metres (micrometre precision); a missing marker (a
// non-finite coordinate) is three empty cells. Tab-separated, '\n' line ends.
//
// TrcStreamWriter keeps the file valid on disk after every frame, also when the process is killed
// at any moment: a GrowingFile (core/growing_file.hpp) whose header is written to PATH.part
// renamed to PATH (PATH never exists without its whole header; an existing PATH is replaced at
// once), one row per frame, the header's values line (line 3, the counts in fixed-width fields)
// rewritten in place after each. A killed writer leaves its counted rows, possibly followed by
// one whole uncounted row or spaces; io::parse_trc ignores such a last uncounted row.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/growing_file.hpp"

namespace mocap::io {

struct TrcLayout {
  double rate = 30.0;                // DataRate and CameraRate, frames per second
  std::vector<std::string> markers;  // names, in column order
  std::int64_t first_frame = 1;      // Frame# of the first row (OrigDataStartFrame: this - 1)
};

// A whole TRC file in memory (frames: [frame][marker], metres; non-finite: empty cells), line 1
// naming `file_name`. Throws std::invalid_argument on a frame whose marker count is wrong.
std::string format_trc(const std::string& file_name, const TrcLayout& layout,
                       std::span<const std::vector<glm::vec3>> frames);

class TrcStreamWriter {
 public:
  // Writes the header (NumFrames 0) and makes PATH. Throws InputError naming the file when it
  // cannot, std::invalid_argument on no markers, a rate that is not positive or a first frame < 1.
  TrcStreamWriter(std::string path, TrcLayout layout);
  TrcStreamWriter(TrcStreamWriter&& other) noexcept = default;
  TrcStreamWriter& operator=(TrcStreamWriter&& other) noexcept = default;
  TrcStreamWriter(const TrcStreamWriter&) = delete;
  TrcStreamWriter& operator=(const TrcStreamWriter&) = delete;
  ~TrcStreamWriter() = default;  // closes without throwing: call close() to learn about a failure

  // Appends the next frame (one position per marker; non-finite: missing) and raises the counts.
  // Throws InputError naming the file on a write error (the file is cut back to its counted rows)
  // and std::invalid_argument on a wrong marker count.
  void append(std::span<const glm::vec3> markers);
  // Flushes to the disk and closes; idempotent. Throws InputError naming the file on failure.
  void close() { file_.close(); }
  // Closes the file descriptor, keeping the state; the next append() reopens the file (a sink
  // with many people stays under the open-file limit). Throws InputError when the file changed.
  void suspend() { file_.suspend(); }

  const std::string& path() const { return file_.path(); }
  std::int64_t frame_count() const { return frames_; }
  bool is_open() const { return file_.is_open(); }

 private:
  static std::string header(const TrcLayout& layout, const std::string& path,
                            std::int64_t& values_offset);

  TrcLayout layout_;
  std::int64_t values_offset_ = 0;  // where header line 3 starts
  GrowingFile file_;
  std::int64_t frames_ = 0;
  std::string row_;  // reused for each row's text
};

}  // namespace mocap::io
