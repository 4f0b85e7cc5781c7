#pragma once
// An MP4 video file that plays at every moment of its writing: a fragmented MP4 (an empty index
// first, then one fragment per frame, each handed to the operating system as soon as it is
// encoded), so a process killed at any time, SIGKILL included, leaves a file that FFmpeg-based
// players (and cv::VideoCapture) decode up to the last frame it wrote, at worst up to the one
// before. H.264 (libx264, preset superfast, no B-frames and no look-ahead, so no frame waits inside
// the encoder) when this FFmpeg has it, else MPEG-4 Part 2. libav stays inside the .cpp file.
// Costs and sizes against cv::VideoWriter: docs/overlay.md (mocap-bench-overlay).
//
// A file written through cv::VideoWriter (or any non-fragmented MP4) has its index at the end: a
// process killed before closing it leaves a file nothing plays.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "core/image_buffer.hpp"

namespace mocap::video {

enum class Mp4Codec { automatic, h264, mpeg4 };

// libx264's speed/size trade-off: ultrafast, superfast, veryfast, faster, fast, medium, ...
// superfast: docs/overlay.md, "Cost" (ultrafast saves little CPU for a much larger file).
inline constexpr std::string_view kDefaultH264Preset = "superfast";

struct Mp4WriterOptions {
  double fps = 30.0;                     // frame rate (frames are evenly spaced)
  Mp4Codec codec = Mp4Codec::automatic;  // automatic: H.264 when libx264 is there, else MPEG-4
  int keyframe_interval = 0;  // frames from one keyframe to the next (seeking); 0: one second
  int threads = 1;            // encoder threads (0: FFmpeg's choice, one per core)
  std::string h264_preset{kDefaultH264Preset};
};

// Whether this FFmpeg can encode H.264 (its libx264 encoder).
bool h264_available();

class Mp4Writer {
 public:
  // A video `path` for pictures of `width` x `height` (an odd size loses its last column or row:
  // the encoders work on 2x2 blocks). The file is created (or truncated) when its first frame is
  // encoded, with its header, so that it never exists without a picture to play; whether its
  // folder takes it is checked here. Throws InputError naming the file when it cannot be created
  // or written, std::invalid_argument for a size below 2 pixels or a frame rate that is not
  // positive and finite.
  Mp4Writer(std::string path, int width, int height, Mp4WriterOptions options = {});
  // Finishes the file (close()) if that was not done; errors are swallowed here.
  ~Mp4Writer();
  Mp4Writer(const Mp4Writer&) = delete;
  Mp4Writer& operator=(const Mp4Writer&) = delete;

  // Encodes one picture (any pixel format, the size given at construction) and writes its
  // fragment to the file. Throws InputError naming the file when writing fails (disk full,
  // file size limit), std::invalid_argument for a picture of another size.
  void write(const ImageBuffer& picture);
  // Writes what the encoder still holds and the file's end; idempotent. Same errors as write().
  void close();

  const std::string& path() const;
  std::int64_t frames() const;          // written so far
  std::string_view codec_name() const;  // "libx264" or "mpeg4"

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::video
