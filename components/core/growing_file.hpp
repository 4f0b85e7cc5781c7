#pragma once
// A text file that grows by whole lines and declares in its header how many it holds (a BVH's
// "Frames:", a TRC's NumFrames), valid on disk after every line, also when the process is killed
// (SIGKILL, a crash) at any moment. The scheme of motion::BvhStreamWriter and io::TrcStreamWriter:
//
// - the header is written before the file has its name: to an unnamed file (O_TMPFILE) linked
//   as PATH with the first line or at close() (`appear_with_first_line`), or to PATH.part renamed
//   to PATH (replacing a file, or where the file system has no unnamed files): PATH never exists
//   without its whole header; a special file (/dev/null) is written in place;
// - each line is one write(), then the owner's count field is rewritten in place by one pwrite();
// - a line never crosses a 4 KiB page boundary (spaces in front of it move it to the next page
//   when it would), nor must the count field (padding_to_keep_in_one_page() when laying out the
//   header), because the kernel can stop a write killed by a signal between two pages but not
//   inside one.
//
// So a killed writer leaves the counted lines, possibly followed by the one line written before
// its count, whole, or by spaces: the project's readers ignore such a last uncounted line. A line
// longer than a page may be cut short by a kill. Durability after a power cut is not promised:
// close() calls fdatasync, appends do not.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace mocap {

class GrowingFile {
 public:
  // Spaces that move `offset` to the next page start when `length` bytes from it would cross one.
  static std::size_t padding_to_keep_in_one_page(std::int64_t offset, std::size_t length);

  // Writes `header` for `path` (`kind` names the file in errors: "BVH file"). Throws
  // mocap::InputError naming the file when it cannot be created or written.
  GrowingFile(std::string path, std::string kind, std::string_view header,
              bool appear_with_first_line);
  GrowingFile(GrowingFile&& other) noexcept;
  GrowingFile& operator=(GrowingFile&& other) noexcept;
  GrowingFile(const GrowingFile&) = delete;
  GrowingFile& operator=(const GrowingFile&) = delete;
  // Closes without throwing (a file still unnamed is linked first: it was asked for); call
  // close() to learn about a failure.
  ~GrowingFile();

  // Appends `line` (its '\n' included), then writes `count` (the header's count field, already
  // raised) at `count_offset`. Throws InputError naming the file on a write error: the file is
  // cut back to the lines before, so that a later append may succeed.
  void append(std::string_view line, std::int64_t count_offset, std::string_view count);
  // Flushes to the disk and closes; idempotent. Throws InputError naming the file on failure.
  void close();
  // Closes the descriptor, keeping the state; the next append() reopens the file (a program
  // writing many files at once stays under its open-file limit). Throws InputError when it
  // cannot close, and append() when the file changed meanwhile.
  void suspend();

  const std::string& path() const { return path_; }
  bool is_open() const { return fd_ >= 0; }
  bool is_suspended() const { return suspended_; }

 private:
  bool create_unnamed(std::string_view header);
  void link_unnamed();
  void resume();
  void write_at(std::int64_t offset, std::string_view bytes, const char* what);
  void release() noexcept;
  std::string error(const char* what) const;

  std::string path_;
  std::string kind_;
  int fd_ = -1;
  std::int64_t end_ = 0;  // file size after the last counted line
  bool suspended_ = false;
  bool unnamed_ = false;  // fd_ is a file without a name yet (no line written)
  std::string padded_;    // reused: spaces and a line that would cross a page
};

}  // namespace mocap
