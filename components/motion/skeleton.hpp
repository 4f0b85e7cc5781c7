#pragma once
// A joint hierarchy as BVH and ASF/AMC describe it, and a clip of motion on it.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace mocap::motion {

enum class Channel : std::uint8_t {
  Xposition,
  Yposition,
  Zposition,
  Xrotation,
  Yrotation,
  Zrotation
};

bool is_rotation(Channel c);
const char* channel_name(Channel c);

struct SkeletonJoint {
  std::string name;
  int parent = -1;         // index into Skeleton::joints, -1 for a root
  glm::vec3 offset{0.0f};  // from the parent, in the parent's frame, file units
  std::vector<Channel> channels;
  bool end_site = false;  // BVH "End Site": no channels, a point only
  int first_channel = 0;  // index of this joint's first value in a frame
};

// Joints are stored parents-first (a joint's parent always has a smaller index).
struct Skeleton {
  std::vector<SkeletonJoint> joints;
  int channel_count = 0;

  int find(const std::string& name) const;  // -1 when absent
  int joint_count() const { return static_cast<int>(joints.size()); }
  // Recomputes first_channel and channel_count from the joints' channel lists.
  void assign_channel_slots();
};

// Motion as the file stores it: one row of channel values per frame (degrees, file units).
struct Clip {
  std::string source;  // file path, for messages
  Skeleton skeleton;
  double frame_time = 1.0 / 120.0;
  int frame_count = 0;
  std::vector<float> values;  // frame_count * skeleton.channel_count, row-major

  const float* frame(int f) const {
    return values.data() + static_cast<size_t>(f) * skeleton.channel_count;
  }
  float* frame(int f) { return values.data() + static_cast<size_t>(f) * skeleton.channel_count; }
  double fps() const { return 1.0 / frame_time; }
};

}  // namespace mocap::motion
