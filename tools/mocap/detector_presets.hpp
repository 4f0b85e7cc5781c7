#pragma once
// The detection strategies by name, as graph nodes: what `mocap reconstruct --detector NAME` puts
// in the graph and what mocap-bench-video measures (docs/detection-strategies.md).

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mocap::cli {

struct DetectorPreset {
  std::string name;  // e.g. "topdown"
  std::string type;  // the node type, e.g. "detect.topdown"
  std::vector<std::pair<std::string, std::string>> params;
  std::string doc;  // one line for --help
};

const std::vector<DetectorPreset>& detector_presets();
// Throws std::invalid_argument listing the names when `name` is unknown.
const DetectorPreset& detector_preset(std::string_view name);

// The defaults: for a file, find people first; for a live source, keep the rate. Still today's
// MultiPose at 256 (graphs/monocular_video.yaml): the measurement that should choose them is not
// complete (docs/detection-strategies.md); changing one is a one-line change here and in the graph.
inline constexpr std::string_view kFileDetector = "multipose";
inline constexpr std::string_view kLiveDetector = "multipose";

// "a, b, c": the names, for help texts and errors.
std::string detector_names();

}  // namespace mocap::cli
