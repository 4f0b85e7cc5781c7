#pragma once
// The frames of a video file or an image folder by index, for a consumer that needs frame t long
// after the source sent it (the overlay draws a frame once its 3D arrives, up to a fit window
// later): it reads the file a second time instead of holding decoded frames. Indices are those of
// video::VideoSource (and so of source.video's messages): from 0, counting the frames that decode.
//
// Frames are decoded in order, the way they are asked for: the next index (or the same one again)
// costs at most one decode; a later one passes over the frames in between (decoded, not
// converted); an earlier one opens the source again and passes over the frames before it. One
// decoded frame is kept.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "video/video_source.hpp"

namespace mocap::video {

class FrameReader {
 public:
  // Opens the file or folder. Throws InputError naming it when it cannot be read, or when it is a
  // camera device or network stream (those cannot be read a second time).
  explicit FrameReader(std::string path, SourceOptions options = {});
  ~FrameReader();
  FrameReader(FrameReader&&) noexcept;
  FrameReader& operator=(FrameReader&&) noexcept;

  // The frame `index`; nullopt when the input ends before it (or for a negative index). Throws
  // InputError as VideoSource::read() does (truncated file, unreadable image).
  std::optional<Frame> frame(std::int64_t index);

  const std::string& path() const;
  int width() const;
  int height() const;
  std::int64_t returned() const;     // frames decoded and converted for a caller
  std::int64_t passed_over() const;  // frames passed over on the way to a later index
  std::int64_t reopened() const;     // times it started again from the first frame

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::video
