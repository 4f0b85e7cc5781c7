#include "motion/skeleton.hpp"

namespace mocap::motion {

bool is_rotation(Channel c) {
  return c == Channel::Xrotation || c == Channel::Yrotation || c == Channel::Zrotation;
}

const char* channel_name(Channel c) {
  switch (c) {
    case Channel::Xposition:
      return "Xposition";
    case Channel::Yposition:
      return "Yposition";
    case Channel::Zposition:
      return "Zposition";
    case Channel::Xrotation:
      return "Xrotation";
    case Channel::Yrotation:
      return "Yrotation";
    case Channel::Zrotation:
      return "Zrotation";
  }
  return "?";
}

int Skeleton::find(const std::string& joint_name) const {
  for (int j = 0; j < joint_count(); ++j) {
    if (joints[j].name == joint_name) return j;
  }
  return -1;
}

void Skeleton::assign_channel_slots() {
  int next = 0;
  for (auto& j : joints) {
    j.first_channel = next;
    next += static_cast<int>(j.channels.size());
  }
  channel_count = next;
}

}  // namespace mocap::motion
