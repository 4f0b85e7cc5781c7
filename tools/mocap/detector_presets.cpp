#include "detector_presets.hpp"

#include <stdexcept>

namespace mocap::cli {

const std::vector<DetectorPreset>& detector_presets() {
  static const std::vector<DetectorPreset> presets = {
      {"multipose",
       "detect.movenet",
       {{"input_size", "256"}},
       "MoveNet MultiPose on the whole frame at 256 (at most 6 people)"},
      {"multipose-512",
       "detect.movenet",
       {{"input_size", "512"}},
       "MoveNet MultiPose at 512: smaller people, a quarter of the speed"},
      {"tiles",
       "detect.tiles",
       {{"columns", "2"}, {"rows", "2"}, {"tile_input_size", "256"}, {"frame_input_size", "256"}},
       "MultiPose on 2 x 2 overlapping tiles and the whole frame, merged"},
      {"topdown",
       "detect.topdown",
       {{"pose_model", "lightning"}, {"detect_every", "10"}},
       "CenterNet boxes every 10 frames, MoveNet Lightning per person on crops that follow them"},
      {"topdown-flow",
       "detect.topdown",
       {{"pose_model", "lightning"}, {"detect_every", "10"}, {"keypoint_every", "3"}},
       "topdown with each person's keypoint pass every 3 frames, optical flow between (live)"},
      {"topdown-live",
       "detect.topdown",
       {{"pose_model", "lightning"},
        {"detect_every", "10"},
        {"keypoint_every", "3"},
        {"detector_in_background", "true"}},
       "topdown-flow with the person detector on a thread of its own: no frame waits for it "
       "(live; what it finds depends on timing)"},
      {"topdown-thunder",
       "detect.topdown",
       {{"pose_model", "thunder"}, {"detect_every", "10"}},
       "the same with MoveNet Thunder (256 px crops): better keypoints, slower"},
      {"topdown-blaze",
       "detect.topdown",
       {{"pose_model", "blazepose-full"}, {"detect_every", "10"}},
       "the same with BlazePose full (256 px crops, 33 landmarks, the pose flag as the person "
       "test): more people found (docs/detection-strategies.md), slower per crop"},
      {"topdown-tiles",
       "detect.topdown",
       {{"pose_model", "lightning"},
        {"detect_every", "10"},
        {"detector_tiles", "2"},
        {"detector_whole_frame", "true"}},
       "topdown with CenterNet on 2 square tiles plus the whole frame (wide frames: more small "
       "people proposed, at a lower precision; docs/detection-strategies.md)"},
  };
  return presets;
}

std::string detector_names() {
  std::string names;
  for (const auto& p : detector_presets()) names += (names.empty() ? "" : ", ") + p.name;
  return names;
}

const DetectorPreset& detector_preset(std::string_view name) {
  for (const auto& p : detector_presets())
    if (p.name == name) return p;
  throw std::invalid_argument("unknown detector '" + std::string(name) + "'; choose one of " +
                              detector_names());
}

}  // namespace mocap::cli
