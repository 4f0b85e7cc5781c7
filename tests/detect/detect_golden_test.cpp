// The C++ ports of MoveNet single-pose (Lightning, Thunder), BlazePose's landmark models (lite,
// full, heavy) and MB3-CenterNet (TF.js model run by
// each network runtime, cv::dnn and XNNPACK; post-processing in C++) against the outputs
// TensorFlow.js computed from the same models and pixels, the graph's own post-processing included
// (tests/data/detection/tfjs_reference.json, made by tools/reference/make_detect_reference.sh; see
// tests/data/detection/README.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detect/centernet.hpp"
#include "detect/model_files.hpp"
#include "detect/singlepose.hpp"

namespace mocap::detect {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kFrame =
    fs::path("..") / "shared" / "docs" / "models" / "movenet-multipose" / "vtest-f300.png";
const fs::path kReference = fs::path("tests") / "data" / "detection" / "tfjs_reference.json";

// Heads: both runtimes and TF.js agree to a few 1e-4 (float32 sums in another order); decoded
// keypoints (normalised to the crop) and CenterNet boxes (input pixels) as closely as the heads
// allow.
constexpr double kHeadTolerance = 1e-3;
constexpr double kKeypointTolerance = 2e-4;
constexpr double kScoreTolerance = 2e-4;
constexpr double kBoxTolerance = 0.02;  // pixels of the 512 × 512 input
// BlazePose: landmarks in pixels of the 256-px crop (z too), visibility and presence logits, and
// the pose flag.
constexpr double kLandmarkTolerance = 0.01;
constexpr double kLogitTolerance = 2e-3;
constexpr double kFlagTolerance = 2e-4;

class DetectGolden : public ::testing::TestWithParam<Backend> {
 protected:
  static void SetUpTestSuite() {
    for (const char* name : {"movenet-lightning", "movenet-thunder", "centernet"}) {
      try {
        cached_model_json(name);
      } catch (const ModelMissing& e) {
        skip_ = e.what();
        return;
      }
    }
    if (!fs::exists(kFrame)) {
      skip_ = "reference frame absent: " + kFrame.string();
      return;
    }
    std::ifstream in(kReference);
    reference_ = json::parse(in);
    cv::cvtColor(cv::imread(kFrame.string()), frame_rgb_, cv::COLOR_BGR2RGB);
  }

  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    if (GetParam() == Backend::xnnpack && !xnnpack_available())
      GTEST_SKIP() << "this build has no XNNPACK runtime";
  }

  RunnerOptions runtime() const {
    RunnerOptions options;
    options.backend = GetParam();
    options.threads = 1;
    return options;
  }

  // The case's window of the frame as image n of `batch` (NHWC, RGB 0..255).
  static void fill(const json& c, GraphTensor& batch, int n) {
    const auto w = c.at("window_x_y_size");
    const int size = w[2];
    const cv::Mat window = frame_rgb_(cv::Rect(w[0], w[1], size, size));
    float* out = batch.values.data() + static_cast<std::size_t>(n) * size * size * 3;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x, out += 3)
        for (int ch = 0; ch < 3; ++ch) out[ch] = window.at<cv::Vec3b>(y, x)[ch];
  }

  static std::vector<json> cases(const std::string& model) {
    std::vector<json> out;
    for (const json& c : reference_.at("cases"))
      if (c.at("model") == model) out.push_back(c);
    return out;
  }

  static inline std::string skip_;
  static inline json reference_;
  static inline cv::Mat frame_rgb_;
};

// Largest difference between the heads of image n at the reference's cells (NHWC both).
double head_difference(const std::vector<GraphTensor>& heads, const json& ref, int n) {
  double worst = 0;
  for (std::size_t h = 0; h < heads.size(); ++h) {
    const json& r = ref.at(h);
    const GraphTensor& t = heads[h];
    EXPECT_EQ(t.shape.at(3), r.at("shape_nhwc")[3].get<std::int64_t>());
    const auto width = static_cast<std::size_t>(t.shape[2]);
    const auto channels = static_cast<std::size_t>(t.shape[3]);
    const std::size_t image = static_cast<std::size_t>(n) * t.shape[1] * width * channels;
    for (std::size_t i = 0; i < r.at("cells_yx").size(); ++i) {
      const std::size_t y = r.at("cells_yx")[i][0], x = r.at("cells_yx")[i][1];
      for (std::size_t ch = 0; ch < channels; ++ch) {
        const double want = r.at("values_at_cells")[i][ch];
        worst =
            std::max(worst, std::fabs(t.values[image + (y * width + x) * channels + ch] - want));
      }
    }
  }
  return worst;
}

void check_singlepose(SinglePoseModel model, const RunnerOptions& runtime,
                      const std::vector<json>& refs,
                      const std::function<void(const json&, GraphTensor&, int)>& fill) {
  SinglePoseNetwork network(model, cached_model_json(model_name(model)), runtime);
  EXPECT_EQ(network.backend(), runtime.backend);
  const int size = network.input_size();
  // All the model's cases in one batch: the batch must not change a crop's result.
  GraphTensor batch;
  batch.shape = {static_cast<std::int64_t>(refs.size()), size, size, 3};
  batch.values.assign(batch.size(), 0.0f);
  for (std::size_t n = 0; n < refs.size(); ++n) fill(refs[n], batch, static_cast<int>(n));
  const std::vector<GraphTensor> heads = network.run_heads(batch);
  for (std::size_t n = 0; n < refs.size(); ++n) {
    SCOPED_TRACE(refs[n].at("id").get<std::string>());
    EXPECT_LT(head_difference(heads, refs[n].at("heads"), static_cast<int>(n)), kHeadTolerance);
    const SinglePoseKeypoints got =
        decode_singlepose(heads[0], heads[1], heads[2], heads[3], static_cast<int>(n));
    const json& want = refs[n].at("output_Identity_1x1x17x3");
    double worst_xy = 0, worst_score = 0;
    for (int k = 0; k < kMovenetKeypoints; ++k) {
      worst_xy = std::max({worst_xy, std::fabs(got[k][0] - want[k][0].get<double>()),
                           std::fabs(got[k][1] - want[k][1].get<double>())});
      worst_score = std::max(worst_score, std::fabs(got[k][2] - want[k][2].get<double>()));
    }
    EXPECT_LT(worst_xy, kKeypointTolerance);
    EXPECT_LT(worst_score, kScoreTolerance);
    std::cout << "  " << refs[n].at("id").get<std::string>() << ": keypoints max |diff| "
              << worst_xy << ", scores " << worst_score << "\n";
  }
}

TEST_P(DetectGolden, LightningMatchesTfjsInOneBatch) {
  check_singlepose(SinglePoseModel::lightning, runtime(), cases("movenet-lightning"), fill);
}

TEST_P(DetectGolden, ThunderMatchesTfjsInOneBatch) {
  check_singlepose(SinglePoseModel::thunder, runtime(), cases("movenet-thunder"), fill);
}

// BlazePose lite, full or heavy on its two windows in one batch: the raw landmarks and flag against
// TF.js's, then decode_blazepose's COCO-17 keypoints against the reference's own landmarks.
void check_blazepose(SinglePoseModel model, const RunnerOptions& runtime,
                     const std::vector<json>& refs,
                     const std::function<void(const json&, GraphTensor&, int)>& fill) {
  try {
    cached_model_json(model_name(model));
  } catch (const ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  ASSERT_EQ(refs.size(), 2u) << "no reference for " << model_name(model)
                             << " (tools/reference/make_detect_reference.sh)";
  SinglePoseNetwork network(model, cached_model_json(model_name(model)), runtime);
  EXPECT_EQ(network.backend(), runtime.backend);
  const int size = network.input_size();
  GraphTensor batch;
  batch.shape = {static_cast<std::int64_t>(refs.size()), size, size, 3};
  batch.values.assign(batch.size(), 0.0f);
  for (std::size_t n = 0; n < refs.size(); ++n) fill(refs[n], batch, static_cast<int>(n));
  const std::vector<GraphTensor> heads = network.run_heads(batch);
  ASSERT_EQ(heads.size(), 2u);
  const std::vector<SinglePose> poses = network.run(batch);
  for (std::size_t n = 0; n < refs.size(); ++n) {
    SCOPED_TRACE(refs[n].at("id").get<std::string>());
    const json& want = refs[n].at("output_ld_3d_1x195");
    ASSERT_EQ(want.size(), std::size_t{kBlazePoseLandmarks} * 5);
    const float* got = heads[0].values.data() + n * want.size();
    double worst_xyz = 0, worst_logit = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
      const double d = std::fabs(got[i] - want[i].get<double>());
      (i % 5 < 3 ? worst_xyz : worst_logit) = std::max(i % 5 < 3 ? worst_xyz : worst_logit, d);
    }
    EXPECT_LT(worst_xyz, kLandmarkTolerance);
    EXPECT_LT(worst_logit, kLogitTolerance);
    const double flag = refs[n].at("output_poseflag").get<double>();
    // (The flag is low here, 0.01-0.07: these windows are MoveNet's, a 100-px walker in a 256-px
    // window, not the person-filling crop BlazePose expects; topdown_detector_test checks the
    // flag on the crops top-down cuts.)
    EXPECT_NEAR(poses[n].presence, flag, kFlagTolerance);
    for (int k = 0; k < kMovenetKeypoints; ++k) {
      const std::size_t l = static_cast<std::size_t>(kBlazePoseToCoco[k]) * 5;
      const auto& [y, x, score] = poses[n].keypoints[k];
      EXPECT_NEAR(x, want[l].get<double>() / size, kLandmarkTolerance / size) << k;
      EXPECT_NEAR(y, want[l + 1].get<double>() / size, kLandmarkTolerance / size) << k;
      EXPECT_NEAR(score, 1.0 / (1.0 + std::exp(-want[l + 3].get<double>())), kScoreTolerance) << k;
    }
    ASSERT_EQ(poses[n].body_landmarks, kBlazePoseBody);
    for (int k = 0; k < kBlazePoseBody; ++k) {  // the body landmarks and their presence
      const std::size_t l = static_cast<std::size_t>(k) * 5;
      const auto& [y, x, presence] = poses[n].body[static_cast<std::size_t>(k)];
      EXPECT_NEAR(x, want[l].get<double>() / size, kLandmarkTolerance / size) << k;
      EXPECT_NEAR(y, want[l + 1].get<double>() / size, kLandmarkTolerance / size) << k;
      EXPECT_NEAR(presence, 1.0 / (1.0 + std::exp(-want[l + 4].get<double>())), kScoreTolerance)
          << k;
    }
    std::cout << "  " << refs[n].at("id").get<std::string>() << ": landmarks max |diff| "
              << worst_xyz << " px, logits " << worst_logit << ", flag " << poses[n].presence
              << " (TF.js " << flag << ")\n";
  }
}

TEST_P(DetectGolden, BlazePoseLiteMatchesTfjsInOneBatch) {
  check_blazepose(SinglePoseModel::blazepose_lite, runtime(), cases("blazepose-lite"), fill);
}

TEST_P(DetectGolden, BlazePoseFullMatchesTfjsInOneBatch) {
  check_blazepose(SinglePoseModel::blazepose_full, runtime(), cases("blazepose-full"), fill);
}

TEST_P(DetectGolden, BlazePoseHeavyMatchesTfjsInOneBatch) {
  check_blazepose(SinglePoseModel::blazepose_heavy, runtime(), cases("blazepose-heavy"), fill);
}

// run() goes through the crops in passes of 8, 4, 2, 1 (3 crops: 2 + 1); each crop's keypoints
// are those of one pass over the whole batch.
TEST_P(DetectGolden, LightningRunInPassesEqualsOneBatch) {
  const auto refs = cases("movenet-lightning");
  ASSERT_EQ(refs.size(), 2u);
  SinglePoseNetwork network(SinglePoseModel::lightning,
                            cached_model_json(model_name(SinglePoseModel::lightning)), runtime());
  GraphTensor batch;
  batch.shape = {3, 192, 192, 3};
  batch.values.assign(batch.size(), 0.0f);
  fill(refs[0], batch, 0);
  fill(refs[1], batch, 1);
  fill(refs[0], batch, 2);
  const std::vector<SinglePose> passes = network.run(batch);
  ASSERT_EQ(passes.size(), 3u);
  const std::vector<GraphTensor> heads = network.run_heads(batch);
  for (int n = 0; n < 3; ++n) {
    const SinglePoseKeypoints whole = decode_singlepose(heads[0], heads[1], heads[2], heads[3], n);
    for (int k = 0; k < kMovenetKeypoints; ++k)
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(passes[static_cast<std::size_t>(n)].keypoints[k][i], whole[k][i], 1e-5)
            << n << " " << k;
  }
}

TEST_P(DetectGolden, CenternetPersonBoxesMatchTfjs) {
  CenternetNetwork network(cached_model_json("centernet"), runtime());
  EXPECT_EQ(network.backend(), GetParam());
  for (const json& c : cases("centernet")) {
    SCOPED_TRACE(c.at("id").get<std::string>());
    GraphTensor image;
    image.shape = {1, kCenternetInput, kCenternetInput, 3};
    image.values.assign(image.size(), 0.0f);
    fill(c, image, 0);
    const std::vector<GraphTensor>& heads = network.run(image);
    EXPECT_LT(head_difference(heads, c.at("heads"), 0), kHeadTolerance);
    const json& want = c.at("person_rows_x0_y0_x1_y1_score_class");
    const auto got = decode_centernet(heads[0], heads[1], kCenternetPersonClass, 0.05f, -1);
    ASSERT_GE(got.size(), want.size());
    double worst_box = 0, worst_score = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
      const Box2D& b = got[i].box;
      const auto& w = want[i];
      worst_box = std::max({worst_box, std::fabs(b.x - w[0].get<double>()),
                            std::fabs(b.y - w[1].get<double>()),
                            std::fabs(b.x + b.width - w[2].get<double>()),
                            std::fabs(b.y + b.height - w[3].get<double>())});
      worst_score = std::max(worst_score, std::fabs(got[i].score - w[4].get<double>()));
    }
    EXPECT_LT(worst_box, kBoxTolerance);
    EXPECT_LT(worst_score, kScoreTolerance);
    std::cout << "  " << c.at("id").get<std::string>() << ": " << want.size()
              << " person rows, boxes max |diff| " << worst_box << " px, scores " << worst_score
              << "\n";
  }
}

INSTANTIATE_TEST_SUITE_P(Runtimes, DetectGolden,
                         ::testing::Values(Backend::opencv, Backend::xnnpack),
                         [](const auto& p) { return std::string(backend_name(p.param)); });

TEST(DetectModels, AWrongModelFileIsRefusedNamingItAndTheFetchCommand) {
  std::string centernet;
  try {
    centernet = cached_model_json("centernet").string();
  } catch (const ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  for (const Backend backend : {Backend::automatic, Backend::opencv, Backend::xnnpack}) {
    if (backend == Backend::xnnpack && !xnnpack_available()) continue;
    SCOPED_TRACE(backend_name(backend));
    RunnerOptions options;
    options.backend = backend;
    try {
      SinglePoseNetwork network(SinglePoseModel::lightning, centernet, options);
      FAIL() << "a CenterNet file loaded as MoveNet Lightning";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(centernet), std::string::npos) << what;
      EXPECT_NE(what.find("tools/setup.sh --models-only"), std::string::npos) << what;
    }
  }
}

TEST(DetectModels, AMissingModelNamesTheFetchCommand) {
  const char* old = std::getenv("MOCAP_MODEL_DIR");
  const std::string saved = old ? old : "";
  setenv("MOCAP_MODEL_DIR", "/nonexistent/models", 1);
  try {
    cached_model_json("movenet-thunder");
    ADD_FAILURE() << "no error";
  } catch (const ModelMissing& e) {
    EXPECT_NE(std::string(e.what()).find("tools/setup.sh --models-only"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/models/movenet-thunder"), std::string::npos);
  }
  if (old)
    setenv("MOCAP_MODEL_DIR", saved.c_str(), 1);
  else
    unsetenv("MOCAP_MODEL_DIR");
}

}  // namespace
}  // namespace mocap::detect
