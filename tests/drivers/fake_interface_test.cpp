// Real video frames sent through the camera path: Aravis' in-process fake camera fills its
// buffers with frames of ../shared/data/eval/opencv_samples/vtest_part0.avi, and what comes out
// of mocap_aravis must be those frames, byte for byte, in order.

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "camera.hpp"
#include "detect/model_files.hpp"
#include "detect/movenet_detector.hpp"

namespace mocap::aravis {
namespace {

using namespace std::chrono_literals;

constexpr const char* kVideo = "../shared/data/eval/opencv_samples/vtest_part0.avi";

std::vector<cv::Mat> read_rgb_frames(int count) {
  cv::VideoCapture video(kVideo);
  std::vector<cv::Mat> frames;
  for (cv::Mat bgr; static_cast<int>(frames.size()) < count && video.read(bgr);) {
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    frames.push_back(rgb);
  }
  return frames;
}

std::string fake_device_id() {
  enable_fake_interface();
  for (const DeviceInfo& d : list_devices()) {
    if (d.protocol == "Fake" || d.id.rfind("Fake_", 0) == 0) return d.id;
  }
  return {};
}

// Which video frame these pixels are, or -1.
int frame_index(const ImageBuffer& image, const std::vector<cv::Mat>& frames) {
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const cv::Mat& f = frames[i];
    if (f.cols != image.width() || f.rows != image.height()) continue;
    bool same = true;
    for (int y = 0; same && y < f.rows; ++y) {
      same = std::memcmp(f.ptr(y), image.data() + static_cast<std::size_t>(y) * image.stride(),
                         static_cast<std::size_t>(f.cols) * 3) == 0;
    }
    if (same) return static_cast<int>(i);
  }
  return -1;
}

TEST(FakeInterface, VideoFramesArriveIntactAndInOrder) {
  if (!std::filesystem::exists(kVideo)) GTEST_SKIP() << kVideo << " not found";
  const std::vector<cv::Mat> video = read_rgb_frames(8);
  ASSERT_EQ(video.size(), 8u);
  const std::string id = fake_device_id();
  ASSERT_FALSE(id.empty()) << "Aravis' Fake interface shows no camera";

  std::atomic<std::size_t> next{0};
  CameraSettings s;
  s.id = id;
  s.pixel_format = "RGB8";
  s.region = Region{0, 0, video[0].cols, video[0].rows};
  s.frame_rate = 50;
  s.fake_fill = [&](std::span<std::byte> pixels, int width, int height) {
    const cv::Mat& f = video[next++ % video.size()];
    const std::size_t bytes = f.total() * f.elemSize();
    if (width == f.cols && height == f.rows && pixels.size() >= bytes)
      std::memcpy(pixels.data(), f.data, bytes);
  };
  Camera camera(s);
  std::vector<int> seen;
  for (int i = 0; i < 20 && seen.size() < 12; ++i) {
    if (const auto frame = camera.next(2s)) {
      ASSERT_EQ(frame->image.format(), PixelFormat::rgb8);
      seen.push_back(frame_index(frame->image, video));
    }
  }
  ASSERT_EQ(seen.size(), 12u);
  for (std::size_t i = 0; i < seen.size(); ++i) {
    ASSERT_GE(seen[i], 0) << "frame " << i << " is not a frame of the video";
    if (i > 0) {
      EXPECT_EQ(seen[i], (seen[i - 1] + 1) % static_cast<int>(video.size())) << "frame " << i;
    }
  }
}

// The detector (issue 5) on frames that came through the camera: it finds the pedestrians of the
// video, exactly as it does on the video's own frames.
TEST(FakeInterface, TheDetectorFindsPeopleInFramesFromTheCamera) {
  if (!std::filesystem::exists(kVideo)) GTEST_SKIP() << kVideo << " not found";
  std::filesystem::path model;
  try {
    model = detect::movenet_model_json();
  } catch (const detect::ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  const std::vector<cv::Mat> video = read_rgb_frames(1);
  ASSERT_EQ(video.size(), 1u);
  const cv::Mat& f = video[0];
  CameraSettings s;
  s.id = fake_device_id();
  ASSERT_FALSE(s.id.empty()) << "Aravis' Fake interface shows no camera";
  s.pixel_format = "RGB8";
  s.region = Region{0, 0, f.cols, f.rows};
  s.fake_fill = [&](std::span<std::byte> pixels, int, int) {
    std::memcpy(pixels.data(), f.data, std::min(pixels.size(), f.total() * f.elemSize()));
  };
  Camera camera(s);
  const auto frame = camera.next(5s);
  ASSERT_TRUE(frame);

  // The settings of the detector's own test on this video: small, distant people need 512.
  detect::MovenetDetector detector(model,
                                   {.input_size = 512, .thresholds = {.min_person_score = 0.2f}});
  const ImageBuffer original(f.cols, f.rows, static_cast<int>(f.step), PixelFormat::rgb8,
                             std::shared_ptr<const void>(),
                             reinterpret_cast<const std::byte*>(f.data));
  const auto from_camera = detector.detect(frame->image);
  const auto from_video = detector.detect(original);
  EXPECT_GE(from_camera.size(), 2u) << "vtest shows several pedestrians";
  ASSERT_EQ(from_camera.size(), from_video.size());
  for (std::size_t i = 0; i < from_camera.size(); ++i) {
    EXPECT_FLOAT_EQ(from_camera[i].score, from_video[i].score);
  }
}

}  // namespace
}  // namespace mocap::aravis
