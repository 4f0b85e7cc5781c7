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

// The defaults (docs/detection-strategies.md): for a file, find people first: top-down (recall
// 0.80 against 0.02 for MultiPose 256 and 0.54 for 512 on vtest, faster than 512;
// graphs/monocular_video.yaml carries it). For a live source, keep the rate: MultiPose 256, the
// only strategy measured to keep vtest's 10 frames/s live (2026-11-26: top-down runs at 4-5
// frames/s under the shared machine's load, topdown-flow at about twice that but finds fewer
// people correctly). Each is a one-line change.
inline constexpr std::string_view kFileDetector = "topdown";
inline constexpr std::string_view kLiveDetector = "multipose";

// "a, b, c": the names, for help texts and errors.
std::string detector_names();

}  // namespace mocap::cli
