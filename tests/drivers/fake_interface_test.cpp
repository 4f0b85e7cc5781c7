// Real video frames sent through the camera path: Aravis' in-process fake camera fills its
// buffers with frames of ../shared/data/eval/opencv_samples/vtest_part0.avi, and what comes out
// of mocap_aravis must be those frames, byte for byte, in order.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <tuple>

#include "camera.hpp"
#include "detect/model_files.hpp"
#include "detect/movenet_detector.hpp"
#include "drivers/pixel_packing.hpp"
#include "pixel_conversion.hpp"

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

// Formats the fake camera's GenICam file does not list (YUV422, 10/12-bit, packed) go through
// the whole camera path too: the test writes the code into the fake camera's pixel format
// register (CameraSettings::fake_pixel_format) and fills every frame with its own bytes in that
// format. What comes out must be what the format means (8 bits: the top bits of each value).
struct StreamedImage {
  std::optional<Frame> frame;
  std::string pixel_format;
};

constexpr int kWidth = 64, kHeight = 48;

StreamedImage stream_one(std::uint32_t pfnc, const std::string& genicam_name,
                         std::vector<std::byte> bytes) {
  CameraSettings s;
  s.id = fake_device_id();
  if (s.id.empty()) throw std::runtime_error("Aravis' Fake interface shows no camera");
  s.region = Region{0, 0, kWidth, kHeight};
  s.frame_rate = 50;
  if (genicam_name.empty()) {
    s.fake_pixel_format = pfnc;
  } else {
    s.pixel_format = genicam_name;
  }
  s.fake_fill = [bytes = std::move(bytes)](std::span<std::byte> pixels, int, int) {
    std::memcpy(pixels.data(), bytes.data(), std::min(pixels.size(), bytes.size()));
  };
  Camera camera(s);
  StreamedImage result{camera.next(5s), camera.pixel_format()};
  return result;
}

int gray_at(const ImageBuffer& image, int x, int y) {
  return static_cast<int>(image.data()[static_cast<std::size_t>(y) * image.stride() + x]);
}

std::vector<std::uint16_t> ramp(int bits) {
  std::vector<std::uint16_t> values;
  for (int i = 0; i < kWidth * kHeight; ++i)
    values.push_back(static_cast<std::uint16_t>((i * 37 + 11) % (1 << bits)));
  return values;
}

TEST(FakeInterface, Yuv422FramesArriveAsRgb) {
  for (const auto& [format, yuyv] :
       {std::pair{CameraFormat::yuv422_uyvy, false}, std::pair{CameraFormat::yuv422_yuyv, true}}) {
    // Grey (U = V = 128) with a luma ramp: R = G = B = 255/219 (Y - 16), BT.601 limited range.
    std::vector<std::byte> bytes;
    std::vector<int> luma;
    for (int i = 0; i < kWidth * kHeight; i += 2) {
      const int y0 = 16 + (i * 7) % 220, y1 = 16 + (i * 11 + 3) % 220;
      luma.push_back(y0);
      luma.push_back(y1);
      const std::array<int, 4> group =
          yuyv ? std::array{y0, 128, y1, 128} : std::array{128, y0, 128, y1};
      for (const int v : group) bytes.push_back(static_cast<std::byte>(v));
    }
    const StreamedImage got = stream_one(static_cast<std::uint32_t>(format), "", bytes);
    ASSERT_TRUE(got.frame) << name(format);
    EXPECT_EQ(got.pixel_format, name(format));
    const ImageBuffer& image = got.frame->image;
    ASSERT_EQ(image.format(), PixelFormat::rgb8);
    ASSERT_EQ(image.width(), kWidth);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const int want = std::clamp(
            (298 * (luma[static_cast<std::size_t>(y * kWidth + x)] - 16) + 128) >> 8, 0, 255);
        const std::byte* p = image.data() + static_cast<std::size_t>(y) * image.stride() + 3 * x;
        ASSERT_EQ(static_cast<int>(p[0]), want) << name(format) << " at " << x << "," << y;
        ASSERT_EQ(static_cast<int>(p[1]), want) << name(format) << " at " << x << "," << y;
        ASSERT_EQ(static_cast<int>(p[2]), want) << name(format) << " at " << x << "," << y;
      }
    }
  }
}

TEST(FakeInterface, DeepMonoFramesArriveAsTheirTopEightBits) {
  const std::vector<std::tuple<CameraFormat, std::string, int, std::vector<std::byte>>> cases = {
      {CameraFormat::mono16, "Mono16", 16, test::pack_words(ramp(16))},  // listed by the fake
      {CameraFormat::mono10, "", 10, test::pack_words(ramp(10))},
      {CameraFormat::mono12, "", 12, test::pack_words(ramp(12))},
      {CameraFormat::mono10_packed, "", 10, test::pack_gige(ramp(10), 10)},
      {CameraFormat::mono12_packed, "", 12, test::pack_gige(ramp(12), 12)},
      {CameraFormat::mono10p, "", 10, test::pack_bit_stream(ramp(10), 10)},
      {CameraFormat::mono12p, "", 12, test::pack_bit_stream(ramp(12), 12)},
  };
  for (const auto& [format, genicam, bits, bytes] : cases) {
    const StreamedImage got = stream_one(static_cast<std::uint32_t>(format), genicam, bytes);
    ASSERT_TRUE(got.frame) << name(format);
    EXPECT_EQ(got.pixel_format, name(format));
    const ImageBuffer& image = got.frame->image;
    ASSERT_EQ(image.format(), PixelFormat::gray8) << name(format);
    const auto values = ramp(bits);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        ASSERT_EQ(gray_at(image, x, y),
                  values[static_cast<std::size_t>(y * kWidth + x)] >> (bits - 8))
            << name(format) << " at " << x << "," << y;
      }
    }
  }
}

TEST(FakeInterface, DeepBayerFramesArriveDemosaicedFromTheirTopBits) {
  const auto values = ramp(12);
  std::vector<std::byte> top;
  for (const std::uint16_t v : values) top.push_back(static_cast<std::byte>(v >> 4));
  const ImageBuffer want = convert_image(top, kWidth, kHeight, CameraFormat::bayer_rg8);
  for (const auto& [format, bytes] :
       {std::pair{CameraFormat::bayer_rg12, test::pack_words(values)},
        std::pair{CameraFormat::bayer_rg12_packed, test::pack_gige(values, 12)},
        std::pair{CameraFormat::bayer_rg12p, test::pack_bit_stream(values, 12)}}) {
    const StreamedImage got = stream_one(static_cast<std::uint32_t>(format), "", bytes);
    ASSERT_TRUE(got.frame) << name(format);
    const ImageBuffer& image = got.frame->image;
    ASSERT_EQ(image.format(), PixelFormat::rgb8) << name(format);
    for (int y = 0; y < kHeight; ++y) {
      EXPECT_EQ(std::memcmp(image.data() + static_cast<std::size_t>(y) * image.stride(),
                            want.data() + static_cast<std::size_t>(y) * want.stride(), 3 * kWidth),
                0)
          << name(format) << " row " << y;
    }
  }
}

// A format the driver cannot convert is refused when the camera is opened, by its code.
TEST(FakeInterface, AnUnsupportedFormatIsNamed) {
  try {
    stream_one(0x020c001eu, "", {});  // YUV411Packed
    FAIL() << "YUV411 accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("0x020c001e"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not supported"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mocap::aravis
