// The C++ ports of MoveNet single-pose (Lightning, Thunder) and MB3-CenterNet (TF.js model ->
// cv::dnn, post-processing in C++) against the outputs TensorFlow.js computed from the same models
// and pixels (tests/data/detection/tfjs_reference.json, made by
// tools/reference/make_detect_reference.sh; see tests/data/detection/README.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
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

// Heads: cv::dnn and TF.js agree to a few 1e-4 (float32 sums in another order); decoded keypoints
// (normalised to the crop) and CenterNet boxes (input pixels) as closely as the heads allow.
constexpr double kHeadTolerance = 1e-3;
constexpr double kKeypointTolerance = 2e-4;
constexpr double kScoreTolerance = 2e-4;
constexpr double kBoxTolerance = 0.02;  // pixels of the 512 × 512 input

class DetectGolden : public ::testing::Test {
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
  }

  // The case's window of the frame as one image of `batch`.
  static void fill(const json& c, Tensor& batch, int n) {
    const auto w = c.at("window_x_y_size");
    const int size = w[2];
    const cv::Mat window = frame_rgb_(cv::Rect(w[0], w[1], size, size));
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
        for (int ch = 0; ch < 3; ++ch)
          batch.values[((static_cast<std::size_t>(n) * 3 + ch) * size + y) * size + x] =
              window.at<cv::Vec3b>(y, x)[ch];
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

// Largest difference between the heads at the reference's cells (NCHW here, NHWC there).
double head_difference(const std::vector<Tensor>& heads, const json& ref, int n) {
  double worst = 0;
  for (std::size_t h = 0; h < heads.size(); ++h) {
    const json& r = ref.at(h);
    const Tensor& t = heads[h];
    EXPECT_EQ(t.channels, r.at("shape_nhwc")[3].get<int>());
    for (std::size_t i = 0; i < r.at("cells_yx").size(); ++i) {
      const int y = r.at("cells_yx")[i][0], x = r.at("cells_yx")[i][1];
      for (int ch = 0; ch < t.channels; ++ch) {
        const double want = r.at("values_at_cells")[i][ch];
        worst = std::max(worst, std::fabs(t.at(n, ch)[y * t.width + x] - want));
      }
    }
  }
  return worst;
}

void check_singlepose(SinglePoseModel model, const std::vector<json>& refs,
                      const std::function<void(const json&, Tensor&, int)>& fill) {
  SinglePoseNetwork network(model, cached_model_json(model_name(model)));
  const int size = network.input_size();
  // All the model's cases in one batch: the batch must not change a crop's result.
  Tensor batch{static_cast<int>(refs.size()), 3, size, size, {}};
  batch.values.assign(static_cast<std::size_t>(batch.batch) * 3 * size * size, 0.0f);
  for (std::size_t n = 0; n < refs.size(); ++n) fill(refs[n], batch, static_cast<int>(n));
  const std::vector<Tensor> heads = network.run_heads(batch);
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

TEST_F(DetectGolden, LightningMatchesTfjsInOneBatch) {
  check_singlepose(SinglePoseModel::lightning, cases("movenet-lightning"), fill);
}

TEST_F(DetectGolden, ThunderMatchesTfjsInOneBatch) {
  check_singlepose(SinglePoseModel::thunder, cases("movenet-thunder"), fill);
}

TEST_F(DetectGolden, CenternetPersonBoxesMatchTfjs) {
  CenternetNetwork network(cached_model_json("centernet"));
  for (const json& c : cases("centernet")) {
    SCOPED_TRACE(c.at("id").get<std::string>());
    Tensor image{1, 3, kCenternetInput, kCenternetInput, {}};
    image.values.assign(3 * kCenternetInput * kCenternetInput, 0.0f);
    fill(c, image, 0);
    const std::vector<Tensor> heads = network.run(image);
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

TEST(DetectModels, AWrongModelFileIsRefusedNamingItAndTheFetchCommand) {
  std::string centernet;
  try {
    centernet = cached_model_json("centernet").string();
  } catch (const ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  try {
    SinglePoseNetwork network(SinglePoseModel::lightning, centernet);
    FAIL() << "a CenterNet file loaded as MoveNet Lightning";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(centernet), std::string::npos) << what;
    EXPECT_NE(what.find("tools/setup.sh --models-only"), std::string::npos) << what;
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
