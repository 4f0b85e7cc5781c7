// graphs/multiview_video.yaml as shipped, run by the real `mocap run`: a short real video
// (OpenCV's vtest, 15 frames) as both of its views, Pose2Sim's rig at the video's size. Not
// about accuracy (both views are one camera's images, so people cannot be associated across them
// and are dropped as seen by one view): the graph runs, the detectors find people in both views,
// every set is complete, poses.jsonl has one whole line per set.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/files.hpp"
#include "support/mocap_process.hpp"
#include "support/models.hpp"
#include "support/shared_data.hpp"

namespace mocap::test {
namespace {

constexpr int kFrames = 15;

TEST(MultiViewVideoGraph, RunsWithCompleteSetsAndWholeOutput) {
  const std::string video = "eval/opencv_samples/vtest_part0.avi";
  const std::string demo_rig = "eval/pose2sim_demo/calibration/Calib_qualisys.toml";
  MOCAP_REQUIRE_SHARED(video);
  MOCAP_REQUIRE_SHARED(demo_rig);
  try {
    detect::cached_model_json("blazepose-full");
  } catch (const detect::ModelMissing&) {
    GTEST_SKIP() << "BlazePose full absent: tools/setup.sh --models-only";
  }
  TempDir dir;
  std::string rig = read_file((shared_data() / demo_rig).string());
  for (std::size_t at; (at = rig.find("size = [ 1088.0, 1920.0]")) != std::string::npos;)
    rig.replace(at, 24, "size = [ 768.0, 576.0]");
  write_file(dir.file("rig.toml"), rig);
  const std::string path = (shared_data() / video).string(), out = dir.file("out");
  std::filesystem::create_directories(out);
  const std::string frames = std::to_string(kFrames);
  Mocap run(dir, "graph", {"run",   "graphs/multiview_video.yaml",
                           "--set", "cam_01.path=" + path,
                           "--set", "cam_02.path=" + path,
                           "--set", "cam_01.count=" + frames,
                           "--set", "cam_02.count=" + frames,
                           "--set", "solve.rig=" + dir.file("rig.toml"),
                           "--set", "solve.fps=10",
                           "--set", "jsonl.path=" + out + "/poses.jsonl",
                           "--set", "bvh.dir=" + out,
                           "--set", "trc.path=" + out + "/person_{id}.trc"});
  const auto code = run.wait(std::chrono::seconds(120));
  const std::string err = run.err();
  ASSERT_EQ(code, 0) << err;
  // Every set joined complete (the statistics' line under the solver).
  EXPECT_NE(err.find("joined " + frames + " sets (" + frames + " complete)"), std::string::npos)
      << err;
  // The detectors found people in both views; one camera's images twice cannot be associated.
  EXPECT_NE(err.find("single-view detections dropped"), std::string::npos) << err;
  const auto lines = read_lines(out + "/poses.jsonl");
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kFrames));
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const nlohmann::json j = nlohmann::json::parse(lines[i]);  // whole: throws on a cut line
    EXPECT_EQ(j.at("frame").get<int>(), static_cast<int>(i));
  }
}

}  // namespace
}  // namespace mocap::test
