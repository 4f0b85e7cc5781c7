#include "core/growing_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "core/input_error.hpp"

namespace mocap {
namespace {

// The unit the kernel copies a write in; a write killed by a signal stops only between pages.
constexpr std::int64_t kPage = 4096;

}  // namespace

std::size_t GrowingFile::padding_to_keep_in_one_page(std::int64_t offset, std::size_t length) {
  const std::int64_t in_page = offset % kPage;
  const auto size = static_cast<std::int64_t>(length);
  if (size > kPage || in_page + size <= kPage) return 0;
  return static_cast<std::size_t>(kPage - in_page);
}

std::string GrowingFile::error(const char* what) const {
  return std::string(what) + " the " + kind_ + ": " + std::strerror(errno);
}

GrowingFile::GrowingFile(std::string path, std::string kind, std::string_view header,
                         bool appear_with_first_line)
    : path_(std::move(path)), kind_(std::move(kind)) {
  struct stat existing {};
  const bool exists = ::stat(path_.c_str(), &existing) == 0;
  const bool special = exists && !S_ISREG(existing.st_mode);
  if (!exists && appear_with_first_line && create_unnamed(header)) return;
  const std::string part = special ? path_ : path_ + ".part";
  fd_ = ::open(part.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(path_, error("cannot create"));
  try {
    write_at(0, header, "cannot write");
    end_ = static_cast<std::int64_t>(header.size());
    if (!special && ::rename(part.c_str(), path_.c_str()) != 0)
      throw InputError(path_, error("cannot create"));
  } catch (...) {
    release();
    if (!special) ::unlink(part.c_str());
    throw;
  }
}

bool GrowingFile::create_unnamed(std::string_view header) {
  const std::size_t slash = path_.rfind('/');
  const std::string folder = slash == std::string::npos ? "." : path_.substr(0, slash + 1);
  fd_ = ::open(folder.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
  if (fd_ < 0) return false;  // no unnamed files here (or no folder): the .part way says why
  try {
    write_at(0, header, "cannot write");
  } catch (...) {
    release();
    throw;
  }
  end_ = static_cast<std::int64_t>(header.size());
  unnamed_ = true;
  return true;
}

void GrowingFile::link_unnamed() {
  if (!unnamed_) return;
  const std::string self = "/proc/self/fd/" + std::to_string(fd_);
  if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, path_.c_str(), AT_SYMLINK_FOLLOW) != 0)
    throw InputError(path_, error("cannot create"));
  unnamed_ = false;
}

GrowingFile::GrowingFile(GrowingFile&& other) noexcept
    : path_(std::move(other.path_)),
      kind_(std::move(other.kind_)),
      fd_(std::exchange(other.fd_, -1)),
      end_(other.end_),
      suspended_(std::exchange(other.suspended_, false)),
      unnamed_(std::exchange(other.unnamed_, false)) {}

GrowingFile& GrowingFile::operator=(GrowingFile&& other) noexcept {
  if (this != &other) {
    try {
      link_unnamed();
    } catch (const InputError&) {
      // As in the destructor.
    }
    release();
    path_ = std::move(other.path_);
    kind_ = std::move(other.kind_);
    fd_ = std::exchange(other.fd_, -1);
    end_ = other.end_;
    suspended_ = std::exchange(other.suspended_, false);
    unnamed_ = std::exchange(other.unnamed_, false);
  }
  return *this;
}

GrowingFile::~GrowingFile() {
  try {
    link_unnamed();
  } catch (const InputError&) {
    // close() reports this; a destructor cannot.
  }
  release();
}

void GrowingFile::release() noexcept {
  if (fd_ >= 0) ::close(std::exchange(fd_, -1));
  unnamed_ = false;
}

void GrowingFile::append(std::string_view line, std::int64_t count_offset, std::string_view count) {
  if (suspended_) resume();
  if (fd_ < 0) throw std::logic_error("GrowingFile: append after close (" + path_ + ")");
  std::string_view bytes = line;
  if (const std::size_t padding = padding_to_keep_in_one_page(end_, line.size()); padding > 0) {
    // One write: spaces, then the line on the next page (a kill between them leaves spaces).
    padded_.assign(padding, ' ');
    padded_.append(line);
    bytes = padded_;
  }
  write_at(end_, bytes, "cannot write");
  write_at(count_offset, count, "cannot update the count of");
  end_ += static_cast<std::int64_t>(bytes.size());
  link_unnamed();
}

// On failure the file is cut back to its counted lines, so that it stays valid (best effort:
// when even that fails, the count still declares only whole lines).
void GrowingFile::write_at(std::int64_t offset, std::string_view bytes, const char* what) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done,
                               static_cast<off_t>(offset) + static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string message = error(what);  // before errno changes
      if (end_ > 0 && ::ftruncate(fd_, static_cast<off_t>(end_)) != 0) {
        // Best effort, as said above.
      }
      throw InputError(path_, message);
    }
    done += static_cast<std::size_t>(n);
  }
}

void GrowingFile::suspend() {
  if (fd_ < 0) return;
  link_unnamed();  // closing an unnamed file would lose it
  suspended_ = true;
  if (::close(std::exchange(fd_, -1)) != 0) throw InputError(path_, error("cannot close"));
}

void GrowingFile::resume() {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd_ < 0) throw InputError(path_, error("cannot reopen"));
  suspended_ = false;
  struct stat status {};
  if (::fstat(fd_, &status) != 0 || (S_ISREG(status.st_mode) && status.st_size != end_)) {
    release();
    throw InputError(path_,
                     "the " + kind_ + " was changed by another program while it was written");
  }
}

void GrowingFile::close() {
  suspended_ = false;  // a suspended file was closed already, with every line written
  if (fd_ < 0) return;
  link_unnamed();
  // Special files (a pipe, /dev/null) cannot be synced; that is no write error.
  const bool synced = ::fdatasync(fd_) == 0 || errno == EINVAL || errno == EROFS;
  const std::string sync_error = synced ? std::string() : error("cannot flush");
  const bool closed = ::close(std::exchange(fd_, -1)) == 0;
  if (!synced) throw InputError(path_, sync_error);
  if (!closed) throw InputError(path_, error("cannot close"));
}

}  // namespace mocap
