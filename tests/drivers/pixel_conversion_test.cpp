// The camera pixel formats converted to ImageBuffer: exact values on small hand-made images.

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "pixel_conversion.hpp"

namespace mocap::aravis {
namespace {

std::vector<std::byte> bytes(std::initializer_list<int> values) {
  std::vector<std::byte> out;
  for (int v : values) out.push_back(static_cast<std::byte>(v));
  return out;
}

std::array<int, 3> rgb_at(const ImageBuffer& image, int x, int y) {
  const std::byte* p = image.data() + static_cast<std::size_t>(y) * image.stride() + 3 * x;
  return {static_cast<int>(p[0]), static_cast<int>(p[1]), static_cast<int>(p[2])};
}

TEST(PixelConversion, KnowsTheGenicamCodesAndNamesUnknownOnes) {
  EXPECT_EQ(camera_format_from_code(0x01080001u), CameraFormat::mono8);
  EXPECT_EQ(camera_format_from_code(0x01080009u), CameraFormat::bayer_rg8);
  EXPECT_FALSE(camera_format_from_code(0x01100005u));  // Mono12
  EXPECT_EQ(describe_pfnc(0x01100005u), "PixelFormat 0x01100005");
  EXPECT_EQ(describe_pfnc(0x0108000bu), "BayerBG8");
}

TEST(PixelConversion, Mono8IsCopiedToGray8) {
  const auto in = bytes({1, 2, 3, 4, 5, 6});
  const ImageBuffer out = convert_image(in, 3, 2, CameraFormat::mono8);
  ASSERT_EQ(out.format(), PixelFormat::gray8);
  ASSERT_EQ(out.width(), 3);
  ASSERT_EQ(out.height(), 2);
  EXPECT_EQ(static_cast<int>(out.data()[out.stride() + 2]), 6);
}

TEST(PixelConversion, Rgb8AndBgr8KeepTheirOrder) {
  const auto in = bytes({10, 20, 30, 40, 50, 60});
  EXPECT_EQ(convert_image(in, 2, 1, CameraFormat::rgb8).format(), PixelFormat::rgb8);
  const ImageBuffer bgr = convert_image(in, 2, 1, CameraFormat::bgr8);
  EXPECT_EQ(bgr.format(), PixelFormat::bgr8);
  EXPECT_EQ(rgb_at(bgr, 1, 0), (std::array{40, 50, 60}));
}

// A flat colour seen through each of the four Bayer patterns comes out as that colour everywhere.
TEST(PixelConversion, EveryBayerPatternRecoversAFlatColour) {
  constexpr int r = 200, g = 100, b = 50, w = 6, h = 4;
  const std::array<std::pair<CameraFormat, std::array<int, 4>>, 4> patterns = {{
      {CameraFormat::bayer_rg8, {r, g, g, b}},
      {CameraFormat::bayer_gr8, {g, r, b, g}},
      {CameraFormat::bayer_bg8, {b, g, g, r}},
      {CameraFormat::bayer_gb8, {g, b, r, g}},
  }};
  for (const auto& [format, sites] : patterns) {
    std::vector<std::byte> mosaic;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x)
        mosaic.push_back(
            static_cast<std::byte>(sites[static_cast<std::size_t>((x & 1) + 2 * (y & 1))]));
    }
    const ImageBuffer out = convert_image(mosaic, w, h, format);
    ASSERT_EQ(out.format(), PixelFormat::rgb8) << name(format);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x)
        EXPECT_EQ(rgb_at(out, x, y), (std::array{r, g, b})) << name(format);
    }
  }
}

TEST(PixelConversion, Yuv422GreyAndOrder) {
  // Y=235 U=V=128 is white, Y=16 black (BT.601 limited range); UYVY and YUYV differ only in order.
  const auto uyvy = bytes({128, 235, 128, 16});
  const auto yuyv = bytes({235, 128, 16, 128});
  for (const auto& [in, format] :
       {std::pair{uyvy, CameraFormat::yuv422_uyvy}, std::pair{yuyv, CameraFormat::yuv422_yuyv}}) {
    const ImageBuffer out = convert_image(in, 2, 1, format);
    EXPECT_EQ(rgb_at(out, 0, 0), (std::array{255, 255, 255})) << name(format);
    EXPECT_EQ(rgb_at(out, 1, 0), (std::array{0, 0, 0})) << name(format);
  }
}

TEST(PixelConversion, ShortBuffersAreRefusedNamingTheFormat) {
  const auto in = bytes({1, 2, 3});
  try {
    convert_image(in, 2, 2, CameraFormat::bayer_gb8);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("BayerGB8"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mocap::aravis
