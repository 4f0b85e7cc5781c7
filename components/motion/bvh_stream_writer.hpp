#pragma once
// Writes a BVH file one frame at a time, so that the file on disk is a valid BVH after every
// frame, also when the process is killed (SIGKILL, a crash) at any moment: a GrowingFile
// (core/growing_file.hpp) whose header is the hierarchy and "Frames: 0000000000" (a fixed-width
// count kept inside one page), one line per frame. A new file appears with its first frame (or
// at close()), never without its whole header. A killed writer leaves the frames counted,
// possibly followed by one whole uncounted line or spaces: the project's reader
// (motion::read_bvh) ignores that line; Blender's reads it as a last frame. A line longer than a
// page (over ~400 channels) may be cut short by a kill.

#include <cstdint>
#include <span>
#include <string>

#include "core/growing_file.hpp"
#include "motion/skeleton.hpp"

namespace mocap::motion {

class BvhStreamWriter {
 public:
  // The most frames a file may hold: the reader's limit.
  static constexpr std::int64_t kMaxFrames = 100'000'000;

  // Writes the hierarchy and a frame count of 0 for `path`: a new file appears with its first
  // frame (or at close() or destruction), an existing one is replaced now. Throws
  // mocap::InputError naming the file when it cannot be created or written.
  BvhStreamWriter(std::string path, Skeleton skeleton, double frame_time);
  BvhStreamWriter(BvhStreamWriter&& other) noexcept = default;
  BvhStreamWriter& operator=(BvhStreamWriter&& other) noexcept = default;
  // Closes the file without throwing (a new file without frames appears, empty of motion);
  // call close() to learn about a failure.
  ~BvhStreamWriter() = default;

  // Appends one frame (skeleton().channel_count values, degrees and file units) and raises the
  // count. Throws InputError naming the file on a write error (the file is cut back to the frames
  // counted, so a later append may succeed) and std::invalid_argument on a wrong value count.
  void append(std::span<const float> values);
  // Flushes to the disk and closes; idempotent. Throws InputError naming the file on failure.
  void close() { file_.close(); }

  // Closes the file descriptor but keeps the writer's state; the next append() reopens the file
  // (a program writing many files at once stays under its open-file limit). Throws InputError
  // naming the file when it cannot be closed; append() throws when the file changed meanwhile.
  void suspend() { file_.suspend(); }

  const std::string& path() const { return file_.path(); }
  const Skeleton& skeleton() const { return skeleton_; }
  std::int64_t frame_count() const { return frames_; }
  bool is_open() const { return file_.is_open(); }
  bool is_suspended() const { return file_.is_suspended(); }

 private:
  struct Header {
    std::string text;
    std::int64_t count_offset = 0;  // where the count's digits are
  };
  static Header header(const Skeleton& skeleton, double frame_time, const std::string& path);

  Skeleton skeleton_;
  Header header_;
  GrowingFile file_;
  std::int64_t frames_ = 0;
  std::string line_;  // reused for each frame's text
};

}  // namespace mocap::motion
