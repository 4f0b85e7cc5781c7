#pragma once
// A text file written one whole line at a time, for outputs that must stay valid however the
// process ends (poses.jsonl). The file is created at the first line, so a run that fails before
// it leaves an earlier file of that name untouched; each line is one write() (retried only when
// the kernel takes part of it), so a kill can only cut the last line, never an earlier one; a
// failed write cuts the file back to its last whole line.

#include <sys/types.h>

#include <string>
#include <string_view>

namespace mocap::io {

class LineFile {
 public:
  // Nothing is touched yet; check_writable() says now whether the first line will fail.
  explicit LineFile(std::string path);
  ~LineFile();
  LineFile(const LineFile&) = delete;
  LineFile& operator=(const LineFile&) = delete;

  // Whether the file can be written, without changing it: an existing file is opened for writing
  // and closed (not truncated); for a new one its folder is made and a file created and removed
  // beside it (access() says yes to root even where it cannot write). Throws InputError naming
  // the file.
  void check_writable() const;
  // Appends `line` (with its newline), creating (or truncating) the file at the first one.
  // Throws InputError naming the file on a failure, the file cut back to its last whole line.
  void write(std::string_view line);
  void close();

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
  off_t end_ = 0;  // size after the last whole line
};

}  // namespace mocap::io
