// detect::KeypointFlow: points on a real vtest frame follow a known shift of the picture to a
// fraction of a pixel; points whose content is gone (the picture replaced) fail the
// forward-backward check; the first frame, a frame of another size and reset() have nothing to
// come from; bad arguments are refused.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detect/keypoint_flow.hpp"

namespace mocap::detect {
namespace {

namespace fs = std::filesystem;

const fs::path kFrame =
    fs::path("..") / "shared" / "docs" / "models" / "movenet-multipose" / "vtest-f300.png";

ImageBuffer buffer(const cv::Mat& image, PixelFormat format) {
  auto owner = std::make_shared<cv::Mat>(image.clone());
  return ImageBuffer(owner->cols, owner->rows, static_cast<int>(owner->step[0]), format, owner,
                     reinterpret_cast<const std::byte*>(owner->data));
}

// The frame moved by (dx, dy) pixels.
cv::Mat shifted(const cv::Mat& frame, double dx, double dy) {
  cv::Mat moved;
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::warpAffine(frame, moved, m, frame.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return moved;
}

// Corners of the frame's middle, where there is texture to follow (people, the sign, paving).
std::vector<FlowPoint> corners(const cv::Mat& frame) {
  cv::Mat gray;
  cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  std::vector<cv::Point2f> found;
  cv::goodFeaturesToTrack(gray, found, 40, 0.05, 10);
  std::vector<FlowPoint> points;
  for (const cv::Point2f& p : found)
    if (p.x > 40 && p.y > 40 && p.x < frame.cols - 40 && p.y < frame.rows - 40)
      points.push_back({p.x, p.y});
  return points;
}

TEST(KeypointFlow, PointsFollowAKnownShiftAndVanishedContentFails) {
  if (!fs::exists(kFrame)) GTEST_SKIP() << "reference frame absent: " << kFrame;
  const cv::Mat frame = cv::imread(kFrame.string());
  const std::vector<FlowPoint> from = corners(frame);
  ASSERT_GE(from.size(), 10u);
  const std::vector<float> limit(from.size(), 1.0f);
  std::vector<FlowPoint> moved(from.size());
  std::vector<std::uint8_t> ok(from.size());

  KeypointFlow flow;
  flow.next_frame(buffer(frame, PixelFormat::bgr8));
  EXPECT_FALSE(flow.ready());  // nothing before the first frame
  flow.track(from, limit, moved, ok);
  for (std::uint8_t o : ok) EXPECT_EQ(o, 0);

  flow.next_frame(buffer(shifted(frame, 3.5, -2.0), PixelFormat::bgr8));
  ASSERT_TRUE(flow.ready());
  flow.track(from, limit, moved, ok);
  int followed = 0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    if (!ok[i]) continue;
    ++followed;
    EXPECT_NEAR(moved[i].x, from[i].x + 3.5f, 0.3f) << i;
    EXPECT_NEAR(moved[i].y, from[i].y - 2.0f, 0.3f) << i;
  }
  EXPECT_GE(followed, static_cast<int>(from.size() * 8 / 10));

  // The picture turned upside down: what the points showed is elsewhere or gone.
  cv::Mat flipped;
  cv::flip(shifted(frame, 3.5, -2.0), flipped, 0);
  flow.next_frame(buffer(flipped, PixelFormat::bgr8));
  std::vector<FlowPoint> from_shifted;
  for (const FlowPoint& p : from) from_shifted.push_back({p.x + 3.5f, p.y - 2.0f});
  flow.track(from_shifted, limit, moved, ok);
  int kept = 0;
  for (std::size_t i = 0; i < from.size(); ++i)
    if (ok[i] && std::hypot(moved[i].x - from_shifted[i].x, moved[i].y - from_shifted[i].y) < 1)
      ++kept;  // a point that still finds itself must be one whose patch looks alike flipped
  EXPECT_LE(kept, static_cast<int>(from.size() / 4));
}

TEST(KeypointFlow, GreyAndColourFramesGiveTheSamePoints) {
  if (!fs::exists(kFrame)) GTEST_SKIP() << "reference frame absent: " << kFrame;
  const cv::Mat frame = cv::imread(kFrame.string());
  const std::vector<FlowPoint> from = corners(frame);
  const std::vector<float> limit(from.size(), 1.0f);
  std::vector<FlowPoint> colour(from.size()), grey(from.size());
  std::vector<std::uint8_t> ok_colour(from.size()), ok_grey(from.size());
  KeypointFlow a, b;
  cv::Mat rgb, gray, gray_shifted;
  cv::cvtColor(frame, rgb, cv::COLOR_BGR2RGB);
  a.next_frame(buffer(rgb, PixelFormat::rgb8));
  cv::cvtColor(shifted(rgb, 1.0, 1.0), rgb, cv::COLOR_RGB2BGR);
  a.next_frame(buffer(rgb, PixelFormat::bgr8));
  a.track(from, limit, colour, ok_colour);
  cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  b.next_frame(buffer(gray, PixelFormat::gray8));
  b.next_frame(buffer(shifted(gray, 1.0, 1.0), PixelFormat::gray8));
  b.track(from, limit, grey, ok_grey);
  for (std::size_t i = 0; i < from.size(); ++i) {
    EXPECT_EQ(ok_colour[i], ok_grey[i]) << i;
    if (ok_colour[i] && ok_grey[i]) {
      EXPECT_NEAR(colour[i].x, grey[i].x, 0.05f) << i;
    }
  }
}

TEST(KeypointFlow, ANewSizeOrAResetHasNothingToComeFrom) {
  KeypointFlow flow;
  const cv::Mat small(64, 80, CV_8UC3, cv::Scalar(20, 40, 60));
  const cv::Mat large(96, 120, CV_8UC3, cv::Scalar(20, 40, 60));
  flow.next_frame(buffer(small, PixelFormat::bgr8));
  flow.next_frame(buffer(small, PixelFormat::bgr8));
  EXPECT_TRUE(flow.ready());
  flow.next_frame(buffer(large, PixelFormat::bgr8));
  EXPECT_FALSE(flow.ready());
  flow.next_frame(buffer(large, PixelFormat::bgr8));
  EXPECT_TRUE(flow.ready());
  flow.reset();
  EXPECT_FALSE(flow.ready());
}

TEST(KeypointFlow, BadArgumentsAreRefused) {
  EXPECT_THROW(KeypointFlow({3, 3}), std::invalid_argument);
  KeypointFlow flow;
  EXPECT_THROW(flow.next_frame(ImageBuffer()), std::invalid_argument);
  const std::vector<FlowPoint> from(3);
  const std::vector<float> limit(2, 1.0f);
  std::vector<FlowPoint> moved(3);
  std::vector<std::uint8_t> ok(3);
  EXPECT_THROW(flow.track(from, limit, moved, ok), std::invalid_argument);
}

}  // namespace
}  // namespace mocap::detect
