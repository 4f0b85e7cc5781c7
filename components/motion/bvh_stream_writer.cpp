#include "motion/bvh_stream_writer.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "core/input_error.hpp"
#include "motion/bvh.hpp"

namespace mocap::motion {
namespace {

// The unit the kernel copies a write in; a write killed by a signal stops only between pages.
constexpr std::int64_t kPage = 4096;
constexpr int kCountDigits = 10;

std::string error_text(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

// Spaces that move `offset` to the next page start when `length` bytes from it would cross one.
std::size_t padding_to_keep_in_one_page(std::int64_t offset, std::size_t length) {
  const std::int64_t in_page = offset % kPage;
  const auto size = static_cast<std::int64_t>(length);
  if (size > kPage || in_page + size <= kPage) return 0;
  return static_cast<std::size_t>(kPage - in_page);
}

}  // namespace

BvhStreamWriter::BvhStreamWriter(std::string path, Skeleton skeleton, double frame_time)
    : path_(std::move(path)), skeleton_(std::move(skeleton)) {
  skeleton_.assign_channel_slots();
  if (skeleton_.channel_count == 0)
    throw std::invalid_argument("BvhStreamWriter: the skeleton has no channels (" + path_ + ")");
  if (!(frame_time > 0.0) || !std::isfinite(frame_time))
    throw std::invalid_argument("BvhStreamWriter: frame time must be positive (" + path_ + ")");
  // The file appears with its whole header or not at all. A new file is written unnamed
  // (O_TMPFILE) and linked as PATH with its first frame (or at close): a kill at any moment leaves
  // no PATH, or one with frames, and no temporary file. An existing file is replaced by writing
  // PATH.part and renaming it (a kill in between leaves the old PATH and PATH.part); so is a new
  // one where the file system has no unnamed files. A special file (/dev/null, /dev/full) is
  // written in place.
  struct stat existing {};
  const bool exists = ::stat(path_.c_str(), &existing) == 0;
  const bool special = exists && !S_ISREG(existing.st_mode);
  if (!exists && create_unnamed(frame_time)) return;
  const std::string part = special ? path_ : path_ + ".part";
  fd_ = ::open(part.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(path_, error_text("cannot create the BVH file"));
  try {
    write_header(frame_time);
    if (!special && ::rename(part.c_str(), path_.c_str()) != 0)
      throw InputError(path_, error_text("cannot create the BVH file"));
  } catch (...) {
    release();
    if (!special) ::unlink(part.c_str());
    throw;
  }
}

bool BvhStreamWriter::create_unnamed(double frame_time) {
  const std::size_t slash = path_.rfind('/');
  const std::string folder = slash == std::string::npos ? "." : path_.substr(0, slash + 1);
  fd_ = ::open(folder.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
  if (fd_ < 0) return false;  // no unnamed files here (or no folder): the .part way says why
  try {
    write_header(frame_time);
  } catch (...) {
    release();
    throw;
  }
  unnamed_ = true;
  return true;
}

void BvhStreamWriter::link_unnamed() {
  if (!unnamed_) return;
  const std::string self = "/proc/self/fd/" + std::to_string(fd_);
  if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, path_.c_str(), AT_SYMLINK_FOLLOW) != 0)
    throw InputError(path_, error_text("cannot create the BVH file"));
  unnamed_ = false;
}

BvhStreamWriter::BvhStreamWriter(BvhStreamWriter&& other) noexcept
    : path_(std::move(other.path_)),
      skeleton_(std::move(other.skeleton_)),
      fd_(std::exchange(other.fd_, -1)),
      count_offset_(other.count_offset_),
      end_(other.end_),
      frames_(other.frames_),
      suspended_(std::exchange(other.suspended_, false)),
      unnamed_(std::exchange(other.unnamed_, false)) {}

BvhStreamWriter& BvhStreamWriter::operator=(BvhStreamWriter&& other) noexcept {
  if (this != &other) {
    release();
    path_ = std::move(other.path_);
    skeleton_ = std::move(other.skeleton_);
    fd_ = std::exchange(other.fd_, -1);
    count_offset_ = other.count_offset_;
    end_ = other.end_;
    frames_ = other.frames_;
    suspended_ = std::exchange(other.suspended_, false);
    unnamed_ = std::exchange(other.unnamed_, false);
  }
  return *this;
}

// A file still unnamed (no frame yet) is linked now, as close() would: it was asked for.
BvhStreamWriter::~BvhStreamWriter() {
  try {
    link_unnamed();
  } catch (const InputError&) {
    // close() reports this; a destructor cannot.
  }
  release();
}

void BvhStreamWriter::release() noexcept {
  if (fd_ >= 0) ::close(std::exchange(fd_, -1));
  unnamed_ = false;
}

void BvhStreamWriter::write_header(double frame_time) {
  std::ostringstream text;
  write_bvh_hierarchy(skeleton_, text);
  std::string header = std::move(text).str() + "MOTION";
  const std::string count_label = "\nFrames: ";
  const auto digits_at = static_cast<std::int64_t>(header.size() + count_label.size());
  // The count is rewritten after every frame: keep its digits inside one page.
  header.append(padding_to_keep_in_one_page(digits_at, kCountDigits), ' ');
  header += count_label;
  count_offset_ = static_cast<std::int64_t>(header.size());
  header.append(kCountDigits, '0');
  header += "\nFrame Time: ";
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, frame_time);
  header.append(buf, end);
  header += '\n';
  write_at_end(header);
  end_ = static_cast<std::int64_t>(header.size());
}

void BvhStreamWriter::append(std::span<const float> values) {
  if (suspended_) resume();
  if (fd_ < 0) throw std::logic_error("BvhStreamWriter: append after close (" + path_ + ")");
  if (values.size() != static_cast<std::size_t>(skeleton_.channel_count)) {
    throw std::invalid_argument("BvhStreamWriter: " + std::to_string(values.size()) +
                                " values for " + std::to_string(skeleton_.channel_count) +
                                " channels (" + path_ + ")");
  }
  for (float v : values) {
    if (!std::isfinite(v))
      throw std::invalid_argument("BvhStreamWriter: non-finite channel value (" + path_ + ")");
  }
  if (frames_ >= kMaxFrames)
    throw InputError(path_, "more than " + std::to_string(kMaxFrames) + " frames");
  line_.clear();
  append_bvh_frame_line(values, line_);
  const std::size_t padding = padding_to_keep_in_one_page(end_, line_.size());
  if (padding > 0) {
    // Whitespace only: a kill right after it leaves a file the readers accept.
    write_at_end(std::string(padding, ' '));
    end_ += static_cast<std::int64_t>(padding);
  }
  write_at_end(line_);
  ++frames_;
  write_count();
  end_ += static_cast<std::int64_t>(line_.size());
  link_unnamed();
}

// Writes at the end of the counted frames. On failure the file is cut back there, so that it
// stays valid and a later append starts clean.
void BvhStreamWriter::write_at_end(const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done,
                               static_cast<off_t>(end_) + static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string message = error_text("cannot write the BVH file (disk full?)");
      cut_back();
      throw InputError(path_, message);
    }
    done += static_cast<std::size_t>(n);
  }
}

// Best effort after a failed write: when even this fails, the count still declares only whole
// frames and the reader ignores one unfinished line.
void BvhStreamWriter::cut_back() noexcept {
  if (end_ > 0 && ::ftruncate(fd_, static_cast<off_t>(end_)) != 0) return;
}

void BvhStreamWriter::write_count() {
  char digits[kCountDigits + 1];
  std::snprintf(digits, sizeof digits, "%0*lld", kCountDigits, static_cast<long long>(frames_));
  std::size_t done = 0;
  while (done < static_cast<std::size_t>(kCountDigits)) {
    const ssize_t n = ::pwrite(fd_, digits + done, kCountDigits - done,
                               static_cast<off_t>(count_offset_) + static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string message = error_text("cannot update the frame count");
      --frames_;
      cut_back();
      throw InputError(path_, message);
    }
    done += static_cast<std::size_t>(n);
  }
}

void BvhStreamWriter::suspend() {
  if (fd_ < 0) return;
  link_unnamed();  // closing an unnamed file would lose it
  suspended_ = true;
  if (::close(std::exchange(fd_, -1)) != 0)
    throw InputError(path_, error_text("cannot close the BVH file"));
}

void BvhStreamWriter::resume() {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd_ < 0) throw InputError(path_, error_text("cannot reopen the BVH file"));
  suspended_ = false;
  struct stat status {};
  if (::fstat(fd_, &status) != 0 || status.st_size != end_) {
    release();
    throw InputError(path_, "the BVH file was changed by another program while it was written");
  }
}

void BvhStreamWriter::close() {
  suspended_ = false;  // a suspended file was closed already, with every frame written
  if (fd_ < 0) return;
  link_unnamed();
  // Special files (a pipe, /dev/null) cannot be synced; that is no write error.
  const bool synced = ::fdatasync(fd_) == 0 || errno == EINVAL || errno == EROFS;
  const std::string sync_error = synced ? std::string() : error_text("cannot flush the BVH file");
  const bool closed = ::close(std::exchange(fd_, -1)) == 0;
  if (!synced) throw InputError(path_, sync_error);
  if (!closed) throw InputError(path_, error_text("cannot close the BVH file"));
}

}  // namespace mocap::motion
