#pragma once
// Where overlay pictures go: an MP4 video and/or a PNG snapshot every N pictures. The video is a
// fragmented MP4 (video::Mp4Writer: H.264, else MPEG-4 Part 2) that plays at every moment: a run
// killed at any point, SIGKILL included, leaves a file that plays up to about its last frame.

#include <cstdint>
#include <memory>
#include <string>

#include "core/image_buffer.hpp"
#include "video/mp4_writer.hpp"

namespace mocap::viz {

struct OverlayOutputOptions {
  std::string video;    // MP4 file; empty: no video
  double fps = 30.0;    // the video's frame rate
  int png_every = 0;    // a PNG of every Nth picture (the first included); 0: none
  std::string png_dir;  // where the PNGs go (created when missing): overlay_<frame>.png
  std::string h264_preset{video::kDefaultH264Preset};  // libx264 preset of the MP4
};

class OverlayOutput {
 public:
  // Creates the PNG folder. Throws InputError naming it when that fails, std::invalid_argument
  // when PNGs are asked for without a folder or the frame rate is not positive.
  explicit OverlayOutput(OverlayOutputOptions options);
  ~OverlayOutput();
  OverlayOutput(OverlayOutput&&) noexcept;
  OverlayOutput& operator=(OverlayOutput&&) noexcept;

  // Writes one picture (every picture of a run has the same size; any pixel format). The video
  // file is created on the first picture (nothing is touched before). Throws InputError naming
  // the file when it cannot be written (disk full, file size limit).
  void write(const ImageBuffer& picture, std::int64_t frame);
  // Finishes the video file; idempotent. Throws InputError naming the file when that fails.
  void close();

  std::int64_t pictures() const;  // written so far
  std::int64_t pngs() const;
  // Pictures written per second of wall-clock time, smoothed (0 before the second one).
  double pictures_per_second() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::viz
