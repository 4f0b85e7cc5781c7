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

// The defaults (docs/detection-strategies.md): for a file, find people first: top-down with
// BlazePose full in the crops (recall on video.avi 0.366 against 0.251 with MoveNet lightning, at
// least as high on vtest.avi, vtest_part0 and the COCO stills, precision >= 0.95 on each;
// 0.80-0.87x its frames/s end to end; graphs/monocular_video.yaml carries it). For a live source,
// keep the rate: MultiPose 256, the only strategy measured to keep vtest's 10 frames/s live
// (2026-11-26: top-down runs at 4-5 frames/s under the shared machine's load, topdown-flow at about
// twice that but finds fewer people correctly). Each is a one-line change.
inline constexpr std::string_view kFileDetector = "topdown-blaze";
inline constexpr std::string_view kLiveDetector = "multipose";

// "a, b, c": the names, for help texts and errors.
std::string detector_names();

}  // namespace mocap::cli
