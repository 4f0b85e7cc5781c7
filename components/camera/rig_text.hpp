#pragma once
// Text pieces shared by the rig writers (rig_toml.cpp, rig_yaml.cpp); not part of the library's
// API.

#include <string>

namespace mocap::camera::detail {

// The shortest text that reads back to the same double, always with a '.' or an exponent so that
// TOML and OpenCV's YAML both read a real ("1.0", not "1").
std::string real_text(double value);

// A double-quoted string with '"' and '\' escaped: the same rule in TOML and YAML (camera names
// have no control characters: camera_problem() refuses them).
std::string quoted(const std::string& text);

}  // namespace mocap::camera::detail
