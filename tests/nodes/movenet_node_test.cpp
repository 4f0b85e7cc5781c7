// The detector nodes in a graph (detect.movenet, detect.topdown, detect.tiles): video frames in,
// COCO-17 people out with the frames' headers, more than MultiPose's 6 per frame where there are
// more, on both network runtimes; detect.movenet also from several workers (in frame order, none
// lost); a missing model, a bad parameter or an unknown runtime stops the graph with an error
// naming the node and the fix.

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <mutex>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "detect/graph_runner.hpp"
#include "detect/model_files.hpp"
#include "graph/registry.hpp"
#include "sink_test_util.hpp"

namespace mocap::nodes {
namespace {

using namespace mocap::graph;
namespace fs = std::filesystem;

const fs::path kFrame =
    fs::path("..") / "shared" / "docs" / "models" / "movenet-multipose" / "vtest-f300.png";

// The rig name of the camera the frames come from: the detectors' people must say it.
const std::string kCamera = "cam_left";

// unit.image_file: one PNG sent `count` times as bgr8 frames.
class ImageFileSource : public Node {
 public:
  static void contract(Contract& c) {
    c.output<VideoFrame>("frames");
    c.required_param<std::string>("path", "image file");
    c.param<int>("count", 1, "frames to send", {1, 1000});
    c.param<int>("copies", 1, "the image this many times side by side", {1, 4});
  }
  void open(Context& ctx) override {
    const cv::Mat image = cv::imread(ctx.param<std::string>("path"));
    if (image.empty()) throw std::runtime_error("cannot read " + ctx.param<std::string>("path"));
    image_ = std::make_shared<cv::Mat>();
    cv::repeat(image, 1, ctx.param<int>("copies"), *image_);
    count_ = ctx.param<int>("count");
  }
  void process(Context& ctx) override {
    if (sent_ == count_) return ctx.finish();
    VideoFrame frame;
    frame.header = {"camera0", static_cast<std::uint64_t>(sent_), 1000 + sent_, sent_};
    frame.camera = kCamera;
    frame.image =
        ImageBuffer(image_->cols, image_->rows, static_cast<int>(image_->step[0]),
                    PixelFormat::bgr8, image_, reinterpret_cast<const std::byte*>(image_->data));
    ctx.send("frames", std::move(frame));
    ++sent_;
  }

 private:
  std::shared_ptr<cv::Mat> image_;
  int count_ = 0, sent_ = 0;
};
MOCAP_REGISTER_NODE("unit.image_file", ImageFileSource)

// unit.capture_people2d: keeps every People2D it receives for the test to look at.
std::mutex captured_mutex;
std::vector<People2D> captured;

class CapturePeople2D : public Node {
 public:
  static void contract(Contract& c) { c.input<People2D>("in"); }
  void process(Context& ctx) override {
    const std::lock_guard lock(captured_mutex);
    captured.push_back(ctx.input<People2D>("in"));
  }
};
MOCAP_REGISTER_NODE("unit.capture_people2d", CapturePeople2D)

// `copies` of the reference frame side by side, `frames` times.
std::string graph_yaml(const std::string& detector_params,
                       const std::string& type = "detect.movenet", int copies = 1, int frames = 2) {
  return R"(
nodes:
  src: { type: unit.image_file, params: { path: )" +
         kFrame.string() + ", count: " + std::to_string(frames) +
         ", copies: " + std::to_string(copies) + R"( } }
  det: { type: )" +
         type + ", params: { " + detector_params + R"( } }
  out: { type: unit.capture_people2d }
edges:
  - [src.frames, det.in]
  - [det.out, out.in]
)";
}

TEST(MovenetNode, SendsCoco17PeopleInFramePixelsWithTheFrameHeaders) {
  try {
    detect::movenet_model_json();
  } catch (const detect::ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  if (!fs::exists(kFrame)) GTEST_SKIP() << "reference frame absent: " << kFrame;
  captured.clear();
  const RunResult result =
      testing::run_graph(graph_yaml("input_size: 512, min_person_score: 0.2, warm_up: false"));
  ASSERT_TRUE(result.ok) << result.error;
  ASSERT_EQ(captured.size(), 2u);
  for (std::size_t i = 0; i < captured.size(); ++i) {
    const People2D& people = captured[i];
    EXPECT_EQ(people.header.frame, static_cast<std::int64_t>(i));
    EXPECT_EQ(people.header.capture_ns, 1000 + static_cast<std::int64_t>(i));
    EXPECT_EQ(people.camera, kCamera);
    EXPECT_EQ(people.layout, LayoutId::coco17);
    ASSERT_EQ(people.people.size(), 6u);  // the six pedestrians (scores 0.36 .. 0.21)
    for (const Person2D& p : people.people) {
      EXPECT_EQ(p.id, -1);
      ASSERT_EQ(p.joints.size(), 17u);
      EXPECT_GT(p.box.height, 50.0f);  // 65-90 px tall people in the 768x576 frame
      EXPECT_LT(p.box.height, 150.0f);
    }
  }
}

// Two copies on alternate frames, each runtime: every frame's people, in frame order, the same
// as one copy finds.
TEST(MovenetNode, WorkersKeepFrameOrderAndLoseNothingOnBothRuntimes) {
  try {
    detect::movenet_model_json();
  } catch (const detect::ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  if (!fs::exists(kFrame)) GTEST_SKIP() << "reference frame absent: " << kFrame;
  for (const std::string backend : {"opencv", "xnnpack"}) {
    if (backend == "xnnpack" && !detect::xnnpack_available()) continue;
    SCOPED_TRACE(backend);
    captured.clear();
    const RunResult result = testing::run_graph(
        graph_yaml("input_size: 256, min_person_score: 0.05, warm_up: false, workers: 2, "
                   "backend: " +
                       backend,
                   "detect.movenet", 1, 7));
    ASSERT_TRUE(result.ok) << result.error;
    ASSERT_EQ(captured.size(), 7u);
    for (std::size_t i = 0; i < captured.size(); ++i) {
      EXPECT_EQ(captured[i].header.frame, static_cast<std::int64_t>(i));
      EXPECT_EQ(captured[i].header.capture_ns, 1000 + static_cast<std::int64_t>(i));
      ASSERT_EQ(captured[i].people.size(), captured[0].people.size());
      ASSERT_FALSE(captured[i].people.empty());
      EXPECT_FLOAT_EQ(captured[i].people[0].box.x, captured[0].people[0].box.x);
    }
  }
}

TEST(MovenetNode, AnUnknownRuntimeStopsTheGraphNamingTheChoices) {
  try {
    detect::movenet_model_json();
  } catch (const detect::ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  if (!fs::exists(kFrame)) GTEST_SKIP() << "reference frame absent: " << kFrame;
  const RunResult result = testing::run_graph(graph_yaml("backend: tflite"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("'det'"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("auto, xnnpack or opencv"), std::string::npos) << result.error;
}

TEST(MovenetNode, AMissingModelStopsTheGraphNamingTheSetupCommand) {
  if (!fs::exists(kFrame)) GTEST_SKIP() << "reference frame absent: " << kFrame;
  const RunResult result = testing::run_graph(graph_yaml("model: /nonexistent/movenet.json"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("'det'"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("tools/setup.sh --models-only"), std::string::npos) << result.error;
}

TEST(MovenetNode, RefusesAnInputSizeThatIsNotAMultipleOf32) {
  try {
    detect::movenet_model_json();
  } catch (const detect::ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  if (!fs::exists(kFrame)) GTEST_SKIP() << "reference frame absent: " << kFrame;
  const RunResult result = testing::run_graph(graph_yaml("input_size: 250"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("multiple of 32"), std::string::npos) << result.error;
}

bool models_present() {
  try {
    for (const char* name : {"movenet-multipose", "movenet-lightning", "centernet"})
      detect::cached_model_json(name);
    return fs::exists(kFrame);
  } catch (const detect::ModelMissing&) {
    return false;
  }
}

// The runtimes this build has.
std::vector<std::string> runtimes() {
  if (detect::xnnpack_available()) return {"opencv", "xnnpack"};
  return {"opencv"};
}

// Two copies of the frame side by side: twelve pedestrians, more than MultiPose's 6 per image.
// XNNPACK on two workers sharing the crops.
TEST(TopDownNode, FindsMoreThanSixPeopleInFramePixelsOnBothRuntimes) {
  if (!models_present()) GTEST_SKIP() << "models or reference frame absent";
  for (const std::string& backend : runtimes()) {
    SCOPED_TRACE(backend);
    captured.clear();
    // XNNPACK also on two workers, warmed up; cv::dnn cold (its warm-up is slow under the
    // sanitizers).
    const RunResult result = testing::run_graph(
        graph_yaml("detect_every: 1, backend: " + backend +
                       (backend == "xnnpack" ? ", workers: 2, warm_up: true" : ", warm_up: false"),
                   "detect.topdown", /*copies=*/2));
    ASSERT_TRUE(result.ok) << result.error;
    ASSERT_EQ(captured.size(), 2u);
    for (std::size_t i = 0; i < captured.size(); ++i) {
      const People2D& people = captured[i];
      EXPECT_EQ(people.header.frame, static_cast<std::int64_t>(i));
      EXPECT_EQ(people.camera, kCamera);
      EXPECT_EQ(people.layout, LayoutId::coco17);
      EXPECT_GT(people.people.size(), 6u);
      int left = 0, right = 0;
      for (const Person2D& p : people.people) {
        ASSERT_EQ(p.joints.size(), 17u);
        EXPECT_GT(p.box.height, 40.0f);
        EXPECT_LT(p.box.height, 150.0f);
        (p.box.x + p.box.width / 2 < 768 ? left : right) += 1;
      }
      EXPECT_GE(left, 4);  // the pedestrians of both copies
      EXPECT_GE(right, 4);
    }
  }
}

TEST(TilesNode, FindsMoreThanSixPeopleOnBothRuntimes) {
  if (!models_present()) GTEST_SKIP() << "models or reference frame absent";
  for (const std::string& backend : runtimes()) {
    SCOPED_TRACE(backend);
    captured.clear();
    const RunResult result = testing::run_graph(graph_yaml(
        "columns: 2, rows: 1, tile_input_size: 512, frame_input_size: 0, min_person_score: 0.2, "
        "backend: " +
            backend,
        "detect.tiles", /*copies=*/2));
    ASSERT_TRUE(result.ok) << result.error;
    ASSERT_EQ(captured.size(), 2u);
    EXPECT_EQ(captured[0].camera, kCamera);
    EXPECT_GT(captured[0].people.size(), 6u);
  }
}

TEST(TopDownNode, BadParametersAndMissingModelsNameTheNodeAndTheFix) {
  if (!fs::exists(kFrame)) GTEST_SKIP() << "reference frame absent: " << kFrame;
  RunResult result = testing::run_graph(graph_yaml("pose_model: sideways", "detect.topdown"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("'det'"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("lightning|thunder|blazepose-lite"), std::string::npos)
      << result.error;
  result = testing::run_graph(graph_yaml("box_model_file: /nonexistent/c.json", "detect.topdown"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("tools/setup.sh --models-only"), std::string::npos) << result.error;
  result = testing::run_graph(graph_yaml("model: /nonexistent/m.json", "detect.tiles"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("tools/setup.sh --models-only"), std::string::npos) << result.error;
  result = testing::run_graph(graph_yaml("backend: tflite", "detect.topdown"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("auto, xnnpack or opencv"), std::string::npos) << result.error;
}

}  // namespace
}  // namespace mocap::nodes
