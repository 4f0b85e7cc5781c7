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
// find people and keep the rate: top-down with keypoints carried by optical flow between passes
// and the person detector in the background (vtest replayed at 25 fps: 5.0-5.2 people per frame
// at 21.5-24.3 frames/s, p95 111-188 ms, against topdown-flow's 5.2-5.3 at 17.6-18.4 and
// MultiPose's 0.6 at 24.5-25; 2026-11-26).
// Several live cameras keep MultiPose: each view runs its own detector on the same 2 cores, and
// the multi-camera live runs were measured with it (topdown-live was not). Each is a one-line
// change here; the graphs in graphs/ carry the same detectors, which
// tests/tools/shipped_graphs_test.cpp checks.
inline constexpr std::string_view kFileDetector = "topdown-blaze";
inline constexpr std::string_view kLiveDetector = "topdown-live";
inline constexpr std::string_view kLiveMultiviewDetector = "multipose";

// "a, b, c": the names, for help texts and errors.
std::string detector_names();

}  // namespace mocap::cli
