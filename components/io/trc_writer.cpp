#include "io/trc_writer.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "core/input_error.hpp"

namespace mocap::io {
namespace {

// The unit the kernel copies a write in; a write killed by a signal stops only between pages.
constexpr std::int64_t kPage = 4096;
// The counts are rewritten in place: fixed-width fields, digits then spaces (readers trim them).
constexpr int kCountWidth = 10;
constexpr std::int64_t kMaxFrames = 100'000'000;

std::string error_text(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

void append_number(std::string& out, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? end : buf);
}

std::string count_field(std::int64_t count) {
  std::string field = std::to_string(count);
  field.resize(kCountWidth, ' ');
  return field;
}

std::string base_name(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

void check_layout(const TrcLayout& layout, const std::string& path) {
  if (layout.markers.empty()) throw std::invalid_argument("TRC writer: no markers (" + path + ")");
  if (!(layout.rate > 0.0) || !std::isfinite(layout.rate))
    throw std::invalid_argument("TRC writer: the rate must be positive (" + path + ")");
  if (layout.first_frame < 1)
    throw std::invalid_argument("TRC writer: Frame# starts at 1 or later (" + path + ")");
}

// Lines 1-2, then line 3 (the values, counts in fixed-width fields) and lines 4-5.
std::string header_line_1_2(const std::string& file_name) {
  return "PathFileType\t4\t(X/Y/Z)\t" + file_name +
         "\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame"
         "\tOrigNumFrames\n";
}

std::string values_line(const TrcLayout& layout, std::int64_t frames) {
  std::string line;
  append_number(line, layout.rate);
  line += '\t';
  append_number(line, layout.rate);
  line += '\t' + count_field(frames) + '\t' + std::to_string(layout.markers.size()) + "\tm\t";
  append_number(line, layout.rate);
  line += '\t' + std::to_string(layout.first_frame - 1) + '\t' + count_field(frames) + '\n';
  return line;
}

std::string names_lines(const TrcLayout& layout) {
  std::string out = "Frame#\tTime";
  for (const std::string& name : layout.markers) out += '\t' + name + "\t\t";
  out += "\n\t";
  for (std::size_t m = 1; m <= layout.markers.size(); ++m) {
    const std::string n = std::to_string(m);
    out += "\tX" + n + "\tY" + n + "\tZ" + n;
  }
  out += '\n';
  return out;
}

void append_row(std::string& out, std::int64_t frame_number, double rate,
                std::span<const glm::vec3> markers) {
  out += std::to_string(frame_number);
  out += '\t';
  append_number(out, static_cast<double>(frame_number) / rate);
  char buf[48];
  for (const glm::vec3& p : markers) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      out += "\t\t\t";
      continue;
    }
    const int n = std::snprintf(buf, sizeof buf, "\t%.6f\t%.6f\t%.6f", static_cast<double>(p.x),
                                static_cast<double>(p.y), static_cast<double>(p.z));
    out.append(buf, static_cast<std::size_t>(n));
  }
  out += '\n';
}

// Spaces that move `offset` to the next page start when `length` bytes from it would cross one.
std::size_t padding_to_keep_in_one_page(std::int64_t offset, std::size_t length) {
  const std::int64_t in_page = offset % kPage;
  const auto size = static_cast<std::int64_t>(length);
  if (size > kPage || in_page + size <= kPage) return 0;
  return static_cast<std::size_t>(kPage - in_page);
}

}  // namespace

std::string format_trc(const std::string& file_name, const TrcLayout& layout,
                       std::span<const std::vector<glm::vec3>> frames) {
  check_layout(layout, file_name);
  std::string out = header_line_1_2(file_name) +
                    values_line(layout, static_cast<std::int64_t>(frames.size())) +
                    names_lines(layout);
  std::int64_t number = layout.first_frame;
  for (const auto& frame : frames) {
    if (frame.size() != layout.markers.size())
      throw std::invalid_argument("TRC writer: " + std::to_string(frame.size()) + " markers for " +
                                  std::to_string(layout.markers.size()) + " (" + file_name + ")");
    append_row(out, number++, layout.rate, frame);
  }
  return out;
}

TrcStreamWriter::TrcStreamWriter(std::string path, TrcLayout layout)
    : path_(std::move(path)), layout_(std::move(layout)) {
  check_layout(layout_, path_);
  const std::string lines_1_2 = header_line_1_2(base_name(path_));
  const std::string header = lines_1_2 + values_line(layout_, 0) + names_lines(layout_);
  // The counts are rewritten in place: the values line must sit inside one page (a file name
  // is at most 255 bytes, so the header's first three lines always do).
  values_offset_ = static_cast<std::int64_t>(lines_1_2.size());
  if (padding_to_keep_in_one_page(values_offset_, values_line(layout_, 0).size()) > 0)
    throw std::invalid_argument("TRC writer: file name too long (" + path_ + ")");
  struct stat existing {};
  const bool special = ::stat(path_.c_str(), &existing) == 0 && !S_ISREG(existing.st_mode);
  const std::string part = special ? path_ : path_ + ".part";
  fd_ = ::open(part.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(path_, error_text("cannot create the TRC file"));
  try {
    write_at(0, header);
    end_ = static_cast<std::int64_t>(header.size());
    if (!special && ::rename(part.c_str(), path_.c_str()) != 0)
      throw InputError(path_, error_text("cannot create the TRC file"));
  } catch (...) {
    release();
    if (!special) ::unlink(part.c_str());
    throw;
  }
}

TrcStreamWriter::TrcStreamWriter(TrcStreamWriter&& other) noexcept
    : path_(std::move(other.path_)),
      layout_(std::move(other.layout_)),
      fd_(std::exchange(other.fd_, -1)),
      suspended_(std::exchange(other.suspended_, false)),
      values_offset_(other.values_offset_),
      end_(other.end_),
      frames_(other.frames_) {}

TrcStreamWriter& TrcStreamWriter::operator=(TrcStreamWriter&& other) noexcept {
  if (this != &other) {
    release();
    path_ = std::move(other.path_);
    layout_ = std::move(other.layout_);
    fd_ = std::exchange(other.fd_, -1);
    suspended_ = std::exchange(other.suspended_, false);
    values_offset_ = other.values_offset_;
    end_ = other.end_;
    frames_ = other.frames_;
  }
  return *this;
}

TrcStreamWriter::~TrcStreamWriter() { release(); }

void TrcStreamWriter::release() noexcept {
  if (fd_ >= 0) ::close(std::exchange(fd_, -1));
}

void TrcStreamWriter::append(std::span<const glm::vec3> markers) {
  if (suspended_) resume();
  if (fd_ < 0) throw std::logic_error("TRC writer: append after close (" + path_ + ")");
  if (markers.size() != layout_.markers.size())
    throw std::invalid_argument("TRC writer: " + std::to_string(markers.size()) + " markers for " +
                                std::to_string(layout_.markers.size()) + " (" + path_ + ")");
  if (frames_ >= kMaxFrames)
    throw InputError(path_, "more than " + std::to_string(kMaxFrames) + " frames");
  row_.clear();
  append_row(row_, layout_.first_frame + frames_, layout_.rate, markers);
  const std::size_t padding = padding_to_keep_in_one_page(end_, row_.size());
  if (padding > 0) row_.insert(0, padding, ' ');  // one write: spaces, then the row on a new page
  write_at(end_, row_);
  ++frames_;
  try {
    write_counts();
  } catch (...) {
    --frames_;
    throw;
  }
  end_ += static_cast<std::int64_t>(row_.size());
}

// On failure the file is cut back to its counted rows, so that it stays valid.
void TrcStreamWriter::write_at(std::int64_t offset, std::string_view bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done,
                               static_cast<off_t>(offset) + static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string message = error_text("cannot write the TRC file (disk full?)");
      if (end_ > 0 && ::ftruncate(fd_, static_cast<off_t>(end_)) != 0) {
        // Best effort: the counts still declare only whole rows.
      }
      throw InputError(path_, message);
    }
    done += static_cast<std::size_t>(n);
  }
}

void TrcStreamWriter::write_counts() { write_at(values_offset_, values_line(layout_, frames_)); }

void TrcStreamWriter::suspend() {
  if (fd_ < 0) return;
  suspended_ = true;
  if (::close(std::exchange(fd_, -1)) != 0)
    throw InputError(path_, error_text("cannot close the TRC file"));
}

void TrcStreamWriter::resume() {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd_ < 0) throw InputError(path_, error_text("cannot reopen the TRC file"));
  suspended_ = false;
  struct stat status {};
  if (::fstat(fd_, &status) != 0 || (S_ISREG(status.st_mode) && status.st_size != end_)) {
    release();
    throw InputError(path_, "the TRC file was changed by another program while it was written");
  }
}

void TrcStreamWriter::close() {
  suspended_ = false;
  if (fd_ < 0) return;
  const bool synced = ::fdatasync(fd_) == 0 || errno == EINVAL || errno == EROFS;
  const std::string sync_error = synced ? std::string() : error_text("cannot flush the TRC file");
  const bool closed = ::close(std::exchange(fd_, -1)) == 0;
  if (!synced) throw InputError(path_, sync_error);
  if (!closed) throw InputError(path_, error_text("cannot close the TRC file"));
}

}  // namespace mocap::io
