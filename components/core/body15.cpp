#include "core/body15.hpp"

namespace mocap {

std::optional<Joint> joint_from_name(std::string_view joint_name) {
  for (int j = 0; j < kBodyJoints; ++j) {
    if (kJointNames[j] == joint_name) return static_cast<Joint>(j);
  }
  return std::nullopt;
}

}  // namespace mocap
