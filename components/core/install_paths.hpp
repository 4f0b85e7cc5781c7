#pragma once
// Where the running program and the tree it belongs to are: data that ships beside the programs
// (graphs/, calibration/) is found from here, whatever the working directory.

#include <filesystem>

namespace mocap {

// The running executable (/proc/self/exe). Throws std::runtime_error when it cannot be read.
std::filesystem::path executable_path();

// The repository or install root: the executable lives in <root>/<build>/bin. Falls back to the
// working directory when the executable cannot be found.
std::filesystem::path install_root();

}  // namespace mocap
