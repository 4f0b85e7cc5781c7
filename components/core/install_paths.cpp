#include "core/install_paths.hpp"

#include <unistd.h>

#include <climits>
#include <stdexcept>
#include <string>

namespace mocap {

std::filesystem::path executable_path() {
  char path[PATH_MAX];
  const ssize_t size = readlink("/proc/self/exe", path, sizeof path - 1);
  if (size <= 0) throw std::runtime_error("cannot find the running executable (/proc/self/exe)");
  return std::string(path, static_cast<std::size_t>(size));
}

std::filesystem::path install_root() {
  try {
    return executable_path().parent_path().parent_path().parent_path();
  } catch (const std::runtime_error&) {
    return std::filesystem::current_path();
  }
}

}  // namespace mocap
