#include "io/line_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/input_error.hpp"

namespace mocap::io {

namespace fs = std::filesystem;

LineFile::LineFile(std::string path) : path_(std::move(path)) {}

LineFile::~LineFile() { close(); }

void LineFile::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void LineFile::check_writable() const {
  std::error_code ec;
  if (fs::exists(path_, ec)) {
    const int fd = ::open(path_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
      throw InputError(path_, std::string("cannot write the file: ") + std::strerror(errno));
    ::close(fd);
    return;
  }
  const fs::path folder = fs::path(path_).parent_path();
  if (!folder.empty() && !fs::create_directories(folder, ec) && ec)
    throw InputError(path_, "cannot create the file: " + ec.message());
  // Built by append: GCC 12 warns (falsely, -Wrestrict) on "." + name + ".probe".
  std::string probe_name = ".";
  probe_name.append(fs::path(path_).filename().string()).append(".probe");
  const fs::path probe = (folder.empty() ? fs::path(".") : folder) / probe_name;
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0 && errno != EEXIST)
    throw InputError(path_, std::string("cannot create the file: ") + std::strerror(errno));
  if (fd >= 0) {
    ::close(fd);
    ::unlink(probe.c_str());
  }
}

void LineFile::write(std::string_view line) {
  if (fd_ < 0) {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw InputError(path_, std::string("cannot create the file: ") + std::strerror(errno));
    end_ = 0;
  }
  std::string text;
  text.reserve(line.size() + 1);
  text.append(line).push_back('\n');
  std::string_view rest = text;
  while (!rest.empty()) {
    const ssize_t n = ::write(fd_, rest.data(), rest.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n == 0 ? EIO : errno;
      [[maybe_unused]] const int cut = ::ftruncate(fd_, end_);  // best effort
      throw InputError(path_, std::string("write failed: ") + std::strerror(error) +
                                  " (disk full or over the file size limit?)");
    }
    rest.remove_prefix(static_cast<std::size_t>(n));
  }
  end_ += static_cast<off_t>(text.size());
}

}  // namespace mocap::io
