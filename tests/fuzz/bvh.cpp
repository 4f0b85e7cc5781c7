// Fuzz target: BVH text (motion/bvh.hpp parse_bvh). A clip that parses must be consistent
// (values for every frame and channel) and must survive a write and a second read unchanged in
// shape.

#include <sstream>

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "motion/bvh.hpp"
#include "motion/pose_sequence.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.bvh";
  motion::Clip clip;
  try {
    clip = motion::parse_bvh(fuzz::text(data, size), name);
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
    return 0;
  }
  fuzz::check(clip.frame_count >= 0 &&
                  clip.values.size() ==
                      static_cast<std::size_t>(clip.frame_count) * clip.skeleton.channel_count,
              "clip values do not match frames x channels");
  std::ostringstream out;
  motion::write_bvh(clip, out);
  try {
    const motion::Clip again = motion::parse_bvh(out.str(), "rewritten.bvh");
    fuzz::check(again.frame_count == clip.frame_count &&
                    again.skeleton.joints.size() == clip.skeleton.joints.size(),
                "a written clip reads back with another shape");
  } catch (const InputError& e) {
    fuzz::fail(std::string("a written clip does not read back: ") + e.what());
  }
  if (clip.frame_count > 0 && clip.skeleton.channel_count > 0) {
    const motion::PoseSequence poses = motion::to_poses(clip);
    motion::GlobalPose pose;
    motion::forward_kinematics(poses, 0, pose);
  }
  return 0;
}
