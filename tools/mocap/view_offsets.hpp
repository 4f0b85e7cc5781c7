#pragma once
// Frame offsets of OpenPose JSON views of a calibrated rig (camera/frame_offsets.hpp), read from
// their folders: what `mocap rig offsets` prints and `mocap reconstruct --calibration --offsets
// auto` applies.

#include <string>
#include <vector>

#include "camera/frame_offsets.hpp"
#include "camera/rig.hpp"
#include "io/openpose_json.hpp"

namespace mocap::cli {

struct ViewOffsets {
  std::vector<camera::ViewOffset> offsets;  // per folder
  std::vector<std::size_t> frames;          // per folder: its frames
};

// One offset per folder (the rig's cameras, in order) against view `reference`; each folder's
// unreadable frames are named on stderr with `who` in front, and left out.
ViewOffsets estimate_view_offsets(const camera::Rig& rig, const std::vector<std::string>& folders,
                                  const io::OpenPoseOptions& json, std::size_t reference,
                                  const camera::OffsetOptions& options, const std::string& who);

}  // namespace mocap::cli
