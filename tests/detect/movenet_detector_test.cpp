// The MoveNet detector: frames of any size and pixel format become a padded RGB tensor whose
// sides are multiples of 32, and on the reference frame it finds the people TF.js found, in the
// frame's pixels.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detect/model_files.hpp"
#include "detect/movenet_detector.hpp"

namespace mocap::detect {
namespace {

namespace fs = std::filesystem;
const fs::path kReferenceDir = fs::path("..") / "shared" / "docs" / "models" / "movenet-multipose";

ImageBuffer wrap(const cv::Mat& mat, PixelFormat format) {
  auto owner = std::make_shared<cv::Mat>(mat);
  return ImageBuffer(mat.cols, mat.rows, static_cast<int>(mat.step[0]), format, owner,
                     reinterpret_cast<const std::byte*>(owner->data));
}

cv::Mat view(const ImageBuffer& image) {
  return cv::Mat(image.height(), image.width(), CV_8UC3, const_cast<std::byte*>(image.data()),
                 static_cast<std::size_t>(image.stride()));
}

TEST(MovenetInput, ScalesTheLongSidePadsToMultiplesOf32AndFeedsRgb) {
  const cv::Mat blue(360, 640, CV_8UC3, cv::Scalar(255, 0, 0));  // BGR
  const MovenetInput in = prepare_movenet_input(wrap(blue, PixelFormat::bgr8), 256);
  ASSERT_EQ(in.tensor.width(), 256);
  ASSERT_EQ(in.tensor.height(), 160);  // 144 rows of picture, 16 of black padding
  EXPECT_EQ(in.tensor.format(), PixelFormat::rgb8);
  EXPECT_EQ(view(in.tensor).at<cv::Vec3b>(143, 255), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(view(in.tensor).at<cv::Vec3b>(144, 0), cv::Vec3b(0, 0, 0));
  EXPECT_FLOAT_EQ(in.mapping.scale_x, 0.4f);
  EXPECT_FLOAT_EQ(in.mapping.scale_y, 0.4f);
  EXPECT_EQ(in.mapping.tensor_height, 160);
}

TEST(MovenetInput, RefusesSizesThatAreNotMultiplesOf32) {
  const cv::Mat grey(48, 64, CV_8UC1, cv::Scalar(7));
  EXPECT_THROW(prepare_movenet_input(wrap(grey, PixelFormat::gray8), 250), std::invalid_argument);
  EXPECT_EQ(prepare_movenet_input(wrap(grey, PixelFormat::gray8), 64).tensor.height(), 64);
}

// The reference input was made with cv::resize(INTER_LINEAR) from the frame; so is ours.
TEST(MovenetInput, ReproducesTheReferenceTensorByteForByte) {
  if (!fs::exists(kReferenceDir / "vtest-f300.png")) GTEST_SKIP() << "reference data absent";
  const cv::Mat frame = cv::imread((kReferenceDir / "vtest-f300.png").string());
  const MovenetInput in = prepare_movenet_input(wrap(frame, PixelFormat::bgr8), 256);
  cv::Mat want = cv::imread((kReferenceDir / "vtest-f300-input-256x192.png").string());
  cv::cvtColor(want, want, cv::COLOR_BGR2RGB);
  ASSERT_EQ(view(in.tensor).size(), want.size());
  EXPECT_EQ(cv::norm(view(in.tensor), want, cv::NORM_INF), 0.0);
}

TEST(MovenetDetector, FindsTheSixPedestriansOfTheReferenceFrameAt512) {
  fs::path model;
  try {
    model = movenet_model_json();
  } catch (const ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  if (!fs::exists(kReferenceDir / "reference.json")) GTEST_SKIP() << "reference data absent";
  const nlohmann::json reference =
      nlohmann::json::parse(std::ifstream(kReferenceDir / "reference.json"));
  const nlohmann::json& want = reference.at("cases")[1].at("instances_sorted_by_score");
  ASSERT_EQ(reference.at("cases")[1].at("id"), "vtest_f300_512x384");

  MovenetDetector detector(
      model,
      {.input_size = 512, .thresholds = {.min_person_score = 0.2f, .min_keypoint_score = 0.0f}});
  const cv::Mat frame = cv::imread((kReferenceDir / "vtest-f300.png").string());
  const auto people = detector.detect(wrap(frame, PixelFormat::bgr8));
  ASSERT_EQ(people.size(), 6u);  // scores 0.36 .. 0.21
  for (std::size_t i = 0; i < people.size(); ++i) {
    EXPECT_NEAR(people[i].score, want[i].at("score").get<double>(), 2e-5);
    for (int k = 0; k < kMovenetKeypoints; ++k) {
      const auto& xy = want[i].at("keypoints")[k].at("orig_px_xy");
      EXPECT_NEAR(people[i].keypoints[k].x, xy[0].get<double>(), 0.1);  // reference: 0.1 px steps
      EXPECT_NEAR(people[i].keypoints[k].y, xy[1].get<double>(), 0.1);
    }
  }
}

}  // namespace
}  // namespace mocap::detect
