// The graphs shipped in graphs/ run the detectors `mocap reconstruct` chooses by default for the
// same input (tools/mocap/detector_presets.hpp): a user who starts from a graph file gets what
// the command measured and documents, and a change of default cannot leave a graph behind.

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "detector_presets.hpp"
#include "graph/graph_spec.hpp"

namespace mocap::test {
namespace {

// Every detector node of the graph (type detect.*) against the preset: the same node type and
// the same parameters, no more and no fewer.
void expect_detectors(const std::string& graph_file, std::string_view preset_name) {
  SCOPED_TRACE(graph_file + " against the preset " + std::string(preset_name));
  const graph::GraphSpec spec = graph::load_graph_file(graph_file);
  const cli::DetectorPreset& preset = cli::detector_preset(preset_name);
  const std::map<std::string, std::string> wanted(preset.params.begin(), preset.params.end());
  int detectors = 0;
  for (const graph::NodeSpec& node : spec.nodes) {
    if (node.type.rfind("detect.", 0) != 0) continue;
    ++detectors;
    EXPECT_EQ(node.type, preset.type) << "node '" << node.name << "'";
    std::map<std::string, std::string> params;
    for (const auto& [name, value] : node.params) params[name] = value.text;
    EXPECT_EQ(params, wanted) << "node '" << node.name << "' (" << node.where.str() << ")";
  }
  EXPECT_GT(detectors, 0) << "no detector node";
}

TEST(ShippedGraphs, FilesUseTheFileDefault) {
  expect_detectors("graphs/monocular_video.yaml", cli::kFileDetector);
  expect_detectors("graphs/multiview_video.yaml", cli::kFileDetector);
  expect_detectors("graphs/multiview_processes.yaml", cli::kFileDetector);
}

TEST(ShippedGraphs, OneLiveCameraUsesTheLiveDefault) {
  expect_detectors("graphs/live_webcam.yaml", cli::kLiveDetector);
  expect_detectors("graphs/live_webcam_view.yaml", cli::kLiveDetector);
  expect_detectors("graphs/live_gige.yaml", cli::kLiveDetector);
}

TEST(ShippedGraphs, SeveralLiveCamerasUseTheirDefault) {
  expect_detectors("graphs/live_multiview_webcam.yaml", cli::kLiveMultiviewDetector);
  expect_detectors("graphs/live_multiview_gige.yaml", cli::kLiveMultiviewDetector);
}

}  // namespace
}  // namespace mocap::test
