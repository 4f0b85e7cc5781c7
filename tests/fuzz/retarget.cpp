// Fuzz target: retargeting inputs (motion/retarget.hpp): a rig (BVH, with or without MOTION),
// optionally followed by a line "@@MAP@@" and a joint map file. A rig and map that read are used
// to retarget a small fixed motion, which must give finite rotations or an InputError.

#include <cmath>

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "motion/bvh.hpp"
#include "motion/retarget.hpp"

namespace {

// A small humanoid with CMU-like names (so roles map), in its rest pose; frames are filled in.
constexpr const char* kSourceHierarchy = R"(HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT LeftUpLeg
  {
    OFFSET 1 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftLeg
    {
      OFFSET 0 -4 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT LeftFoot
      {
        OFFSET 0 -4 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0 -1 0
        }
      }
    }
  }
  JOINT RightUpLeg
  {
    OFFSET -1 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT RightLeg
    {
      OFFSET 0 -4 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT RightFoot
      {
        OFFSET 0 -4 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0 -1 0
        }
      }
    }
  }
  JOINT Spine
  {
    OFFSET 0 2 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT Neck
    {
      OFFSET 0 4 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT Head
      {
        OFFSET 0 1 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0 -1 0
        }
      }
    }
    JOINT LeftShoulder
    {
      OFFSET 1 3 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT LeftArm
      {
        OFFSET 1 0 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT LeftForeArm
        {
          OFFSET 2 0 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          JOINT LeftHand
          {
            OFFSET 2 0 0
            CHANNELS 3 Zrotation Xrotation Yrotation
            End Site
            {
              OFFSET 0 -1 0
            }
          }
        }
      }
    }
    JOINT RightShoulder
    {
      OFFSET -1 3 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT RightArm
      {
        OFFSET -1 0 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT RightForeArm
        {
          OFFSET -2 0 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          JOINT RightHand
          {
            OFFSET -2 0 0
            CHANNELS 3 Zrotation Xrotation Yrotation
            End Site
            {
              OFFSET 0 -1 0
            }
          }
        }
      }
    }
  }
}
MOTION
Frames: 0
Frame Time: 0.0333333
)";

mocap::motion::Clip source_clip() {
  mocap::motion::Clip clip = mocap::motion::parse_bvh(kSourceHierarchy, "source.bvh");
  clip.frame_count = 3;
  clip.values.resize(static_cast<std::size_t>(clip.frame_count) * clip.skeleton.channel_count);
  for (std::size_t i = 0; i < clip.values.size(); ++i)
    clip.values[i] = static_cast<float>(static_cast<int>(i * 37 % 91) - 45);  // degrees
  return clip;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  std::string_view rig_text = fuzz::text(data, size), map_text;
  const bool has_map = fuzz::split(fuzz::text(data, size), "\n@@MAP@@\n", rig_text, map_text);
  static const motion::Clip source = source_clip();
  motion::RetargetOptions options;
  options.target_source = "fuzz-rig.bvh";
  motion::Skeleton rig;
  try {
    rig = motion::parse_rig(rig_text, "fuzz-rig.bvh");
    if (has_map) options.map = motion::parse_joint_map(map_text, "fuzz-map.txt");
  } catch (const InputError& e) {
    if (std::string_view(e.what()).find("fuzz-rig.bvh") == std::string_view::npos)
      fuzz::expect_named(e, "fuzz-map.txt");
    return 0;
  }
  try {
    const motion::RetargetResult result = motion::retarget(source, rig, options);
    fuzz::check(result.clip.frame_count == source.frame_count, "retargeting lost frames");
    for (float v : result.clip.values) {
      // Rigs with huge offsets may give huge translations; rotations in degrees stay finite.
      if (!std::isfinite(v)) fuzz::fail("retargeting gave a non-finite channel value");
    }
    (void)motion::bone_direction_errors(source, result);
  } catch (const InputError& e) {
    if (std::string_view(e.what()).find("fuzz-rig.bvh") == std::string_view::npos)
      fuzz::expect_named(e, "fuzz-map.txt");
  }
  return 0;
}
