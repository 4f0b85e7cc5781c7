// Both network runtimes (cv::dnn, XNNPACK) against TensorFlow.js on the other networks of the
// model package: MoveNet single-pose Lightning and Thunder, MB3-CenterNet and NanoDet, fed windows
// of the MoveNet reference frame (tests/detect/data/runtime_reference.json, made by
// tools/reference/make_runtime_reference.sh). Outputs are compared by shape, statistics and 64+
// sampled values each. Single-pose MoveNet also runs fed after its batch-of-one input reshuffles
// with both Lightning windows in one batch. cv::dnn cannot import NanoDet (OpenCV 4.6's TF importer
// takes no NCHW transposes): it refuses it by name.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detect/graph_runner.hpp"
#include "detect/model_files.hpp"

namespace mocap::detect {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kReference = fs::path("tests") / "detect" / "data" / "runtime_reference.json";
const fs::path kFrame =
    fs::path("..") / "shared" / "docs" / "models" / "movenet-multipose" / "vtest-f300.png";

// Tolerances, from the differences measured on these cases (docs/models.md): both runtimes agree
// with TF.js to 3e-4 of each output's range and 6e-5 on the means; held at about 3× that.
constexpr double kRelativeTolerance = 1e-3;  // of the output's value range, per value
constexpr double kMeanTolerance = 2e-4;      // of the range, on the mean

fs::path model_json(const std::string& name) { return model_cache_dir() / name / (name + ".json"); }

// The case's window of the frame, scaled and laid out as the reference fed it.
std::vector<float> window(const cv::Mat& rgb, const json& c) {
  const int x = c.at("window_x_y_size")[0], y = c.at("window_x_y_size")[1],
            s = c.at("window_x_y_size")[2];
  const float scale = c.at("input").at("scale").get<float>();
  const bool nchw = c.at("input").at("layout") == "NCHW";
  const cv::Mat roi = rgb(cv::Rect(x, y, s, s));
  std::vector<float> out(static_cast<std::size_t>(s) * s * 3);
  for (int r = 0; r < s; ++r)
    for (int col = 0; col < s; ++col)
      for (int ch = 0; ch < 3; ++ch) {
        const float v = static_cast<float>(roi.at<cv::Vec3b>(r, col)[ch]) * scale;
        const std::size_t pixel = static_cast<std::size_t>(r) * s + col;
        out[nchw ? static_cast<std::size_t>(ch) * s * s + pixel : pixel * 3 + ch] = v;
      }
  return out;
}

std::vector<std::string> output_names(const json& c) {
  std::vector<std::string> names;
  for (const json& o : c.at("outputs")) names.push_back(o.at("node"));
  return names;
}

// The largest difference of `got` to the reference output, relative to its value range.
double compare(const GraphTensor& got, const json& want) {
  EXPECT_EQ(got.shape, want.at("shape").get<std::vector<std::int64_t>>());
  if (got.values.size() != got.size() ||
      got.shape != want.at("shape").get<std::vector<std::int64_t>>())
    return INFINITY;
  const double lo = want.at("min"), hi = want.at("max");
  const double range = std::max(hi - lo, 1e-6);
  const auto [gmin, gmax] = std::minmax_element(got.values.begin(), got.values.end());
  double sum = 0;
  for (const float v : got.values) sum += v;
  double worst = std::max(std::fabs(*gmin - lo), std::fabs(*gmax - hi)) / range;
  EXPECT_LT(
      std::fabs(sum / static_cast<double>(got.values.size()) - want.at("mean").get<double>()) /
          range,
      kMeanTolerance)
      << want.at("node");
  for (const json& sample : want.at("samples_index_value")) {
    const auto index = sample[0].get<std::size_t>();
    worst = std::max(worst, std::fabs(got.values.at(index) - sample[1].get<double>()) / range);
  }
  return worst;
}

class RuntimeGolden : public ::testing::TestWithParam<Backend> {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(kReference) || !fs::exists(kFrame)) {
      skip_ = "reference data absent: " + kReference.string() + " or " + kFrame.string();
      return;
    }
    std::ifstream in(kReference);
    reference_ = json::parse(in);
    cv::cvtColor(cv::imread(kFrame.string()), frame_, cv::COLOR_BGR2RGB);
  }

  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    if (GetParam() == Backend::xnnpack && !xnnpack_available())
      GTEST_SKIP() << "this build has no XNNPACK runtime";
  }

  // The reference cases of `model`; skips when the model is not in the cache.
  static std::vector<json> cases(const std::string& model) {
    std::vector<json> out;
    for (const json& c : reference_.at("cases"))
      if (c.at("model") == model) out.push_back(c);
    return out;
  }

  std::unique_ptr<GraphRunner> runner(const json& c, const std::string& input_node = {}) const {
    RunnerOptions options;
    options.backend = GetParam();
    options.threads = 1;
    options.input_node = input_node;
    return make_graph_runner(model_json(c.at("model")), output_names(c), options);
  }

  void check_model(const std::string& model) {
    if (!fs::exists(model_json(model))) GTEST_SKIP() << "model absent: " << model_json(model);
    const auto all = cases(model);
    ASSERT_FALSE(all.empty());
    const auto network = runner(all[0]);
    for (const json& c : all) {
      const std::vector<float> input = window(frame_, c);
      const auto shape = c.at("input").at("shape").get<std::vector<std::int64_t>>();
      std::vector<GraphTensor> outputs;
      network->run({shape, input}, outputs);
      ASSERT_EQ(outputs.size(), c.at("outputs").size());
      for (std::size_t i = 0; i < outputs.size(); ++i) {
        const double worst = compare(outputs[i], c.at("outputs")[i]);
        EXPECT_LT(worst, kRelativeTolerance) << c.at("outputs")[i].at("node");
        std::cout << "  " << backend_name(GetParam()) << " " << c.at("id").get<std::string>() << " "
                  << c.at("outputs")[i].at("node").get<std::string>() << ": max |diff| / range "
                  << worst << "\n";
      }
    }
  }

  static inline std::string skip_;
  static inline json reference_;
  static inline cv::Mat frame_;
};

TEST_P(RuntimeGolden, MovenetLightningHeadsMatchTfjs) { check_model("movenet-lightning"); }
TEST_P(RuntimeGolden, MovenetThunderHeadsMatchTfjs) { check_model("movenet-thunder"); }
TEST_P(RuntimeGolden, CenternetHeadsMatchTfjs) { check_model("centernet"); }
TEST_P(RuntimeGolden, NanodetOutputsMatchTfjsOrAreRefusedByName) {
  if (GetParam() != Backend::opencv) return check_model("nanodet");
  if (!fs::exists(model_json("nanodet"))) GTEST_SKIP() << "model absent";
  try {
    runner(cases("nanodet").at(0));
    FAIL() << "cv::dnn was expected to refuse NanoDet";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("nanodet.json"), std::string::npos) << what;
    EXPECT_NE(what.find("Transpose"), std::string::npos) << what;
  }
}

// Fed after the batch-of-one input reshuffles, single-pose MoveNet runs several crops at once. It
// is fed at `sub` (x - [0, 0, 0], so the same values): at `stack`, cv::dnn 4.6 fails on a batch
// of two in that subtraction.
TEST_P(RuntimeGolden, MovenetLightningRunsABatchOfTwoCrops) {
  if (!fs::exists(model_json("movenet-lightning"))) GTEST_SKIP() << "model absent";
  const auto both = cases("movenet-lightning");
  ASSERT_EQ(both.size(), 2u);
  const auto network = runner(both[0], "StatefulPartitionedCall/sub");
  std::vector<float> input = window(frame_, both[0]);
  const std::vector<float> second = window(frame_, both[1]);
  input.insert(input.end(), second.begin(), second.end());
  const std::vector<std::int64_t> shape = {2, 192, 192, 3};
  std::vector<GraphTensor> outputs;
  network->run({shape, input}, outputs);
  ASSERT_EQ(outputs.size(), 4u);
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    for (std::size_t n = 0; n < 2; ++n) {
      GraphTensor one;
      one.shape = outputs[i].shape;
      one.shape[0] = 1;
      const std::size_t size = one.size();
      one.values.assign(outputs[i].values.begin() + static_cast<long>(n * size),
                        outputs[i].values.begin() + static_cast<long>((n + 1) * size));
      EXPECT_LT(compare(one, both[n].at("outputs")[i]), kRelativeTolerance);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Runtimes, RuntimeGolden,
                         ::testing::Values(Backend::opencv, Backend::xnnpack),
                         [](const auto& p) { return std::string(backend_name(p.param)); });

}  // namespace
}  // namespace mocap::detect
