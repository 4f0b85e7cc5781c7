#pragma once
// Writes a BVH file one frame at a time, so that the file on disk is a valid BVH after every
// frame, also when the process is killed (SIGKILL, a crash) at any moment:
//
// - the hierarchy and "Frames: 0000000000" (a fixed-width count) are written first, to an unnamed
//   file linked as PATH with the first frame, or at close() (to PATH.part renamed to PATH at once
//   when replacing a file, or where the file system has no unnamed files): the file never exists
//   without its whole header, and a new one not before its first frame unless closed without any;
// - each frame is one write() of one line, then the count is rewritten in place (pwrite);
// - a line never crosses a 4 KiB page boundary (spaces at the start of a line pad it to the next
//   page when it would), and neither does the count, because the kernel can stop a write killed
//   by a signal between two pages but not inside one.
//
// So a killed writer leaves the frames counted, possibly followed by the one line that was
// written before its count (whole, as a line crossing no page boundary cannot be cut), or by
// spaces. The project's reader (motion::read_bvh) ignores that one line; Blender's reads it as a
// last frame. A line longer than a page (over ~400 channels) may be cut short by a kill.
// Durability after a power cut is not promised: close() calls fdatasync, appends do not.

#include <cstdint>
#include <span>
#include <string>

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
  BvhStreamWriter(BvhStreamWriter&& other) noexcept;
  BvhStreamWriter& operator=(BvhStreamWriter&& other) noexcept;
  BvhStreamWriter(const BvhStreamWriter&) = delete;
  BvhStreamWriter& operator=(const BvhStreamWriter&) = delete;
  // Closes the file without throwing; call close() to learn about a failure.
  ~BvhStreamWriter();

  // Appends one frame (skeleton().channel_count values, degrees and file units) and raises the
  // count. Throws InputError naming the file on a write error (the file is cut back to the frames
  // counted, so a later append may succeed) and std::invalid_argument on a wrong value count.
  void append(std::span<const float> values);
  // Flushes to the disk and closes; idempotent. Throws InputError naming the file on failure.
  void close();

  // Closes the file descriptor but keeps the writer's state; the next append() reopens the file
  // (a program writing many files at once stays under its open-file limit). Throws InputError
  // naming the file when it cannot be closed; append() throws when the file changed meanwhile.
  void suspend();

  const std::string& path() const { return path_; }
  const Skeleton& skeleton() const { return skeleton_; }
  std::int64_t frame_count() const { return frames_; }
  bool is_open() const { return fd_ >= 0; }
  bool is_suspended() const { return suspended_; }

 private:
  void write_header(double frame_time);
  // A new file made unnamed with its header (linked as path_ by link_unnamed()); false where
  // unnamed files are not supported (nothing done then).
  bool create_unnamed(double frame_time);
  void link_unnamed();
  void resume();
  void write_at_end(const std::string& bytes);
  void write_count();
  void cut_back() noexcept;
  void release() noexcept;

  std::string path_;
  Skeleton skeleton_;
  int fd_ = -1;
  std::int64_t count_offset_ = 0;  // where the count's digits are
  std::int64_t end_ = 0;           // file size after the last complete frame
  std::int64_t frames_ = 0;
  bool suspended_ = false;
  bool unnamed_ = false;  // fd_ is a file without a name yet (no frame written)
  std::string line_;      // reused for each frame's text
};

}  // namespace mocap::motion
