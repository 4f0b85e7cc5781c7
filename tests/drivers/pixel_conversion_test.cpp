// The camera pixel formats converted to ImageBuffer: exact values on small hand-made images.

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "pixel_conversion.hpp"
#include "pixel_packing.hpp"

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
  EXPECT_EQ(camera_format_from_code(0x01100005u), CameraFormat::mono12);
  EXPECT_EQ(describe_pfnc(0x01100005u), "Mono12");
  EXPECT_EQ(describe_pfnc(0x010c0006u), "Mono12Packed");
  EXPECT_EQ(describe_pfnc(0x010a0046u), "Mono10p");
  EXPECT_EQ(describe_pfnc(0x010c0059u), "BayerRG12p");
  EXPECT_FALSE(camera_format_from_code(0x020c001eu));  // YUV411Packed
  EXPECT_EQ(describe_pfnc(0x020c001eu), "PixelFormat 0x020c001e");
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

// Values of 10 to 16 bits keep their top 8 bits, in every packing: the same values give the
// same 8-bit image whichever way the camera packs them.
TEST(PixelConversion, DeepFormatsKeepTheTopEightBits) {
  constexpr int w = 5, h = 3;  // odd: packed pixels run on across rows
  for (const int bits : {10, 12, 14, 16}) {
    std::vector<std::uint16_t> values;
    std::vector<int> expected;
    for (int i = 0; i < w * h; ++i) {
      const auto v = static_cast<std::uint16_t>((i * 2731 + 97) % (1 << bits));
      values.push_back(v);
      expected.push_back(v >> (bits - 8));
    }
    std::vector<std::pair<CameraFormat, std::vector<std::byte>>> cases;
    const auto words = test::pack_words(values);
    if (bits == 10) {
      cases = {{CameraFormat::mono10, words},
               {CameraFormat::mono10_packed, test::pack_gige(values, 10)},
               {CameraFormat::mono10p, test::pack_bit_stream(values, 10)}};
    } else if (bits == 12) {
      cases = {{CameraFormat::mono12, words},
               {CameraFormat::mono12_packed, test::pack_gige(values, 12)},
               {CameraFormat::mono12p, test::pack_bit_stream(values, 12)}};
    } else {
      cases = {{bits == 14 ? CameraFormat::mono14 : CameraFormat::mono16, words}};
    }
    for (const auto& [format, in] : cases) {
      // Exactly the bytes the geometry needs (the packer may pad the last group of 3 bytes).
      const std::size_t needed = image_bytes(w, h, format);
      ASSERT_GE(in.size(), needed) << name(format);
      ASSERT_LT(in.size(), needed + 2) << name(format);
      EXPECT_EQ(value_bits(format), bits) << name(format);
      const ImageBuffer out = convert_image({in.data(), needed}, w, h, format);
      ASSERT_EQ(out.format(), PixelFormat::gray8) << name(format);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          EXPECT_EQ(static_cast<int>(out.data()[static_cast<std::size_t>(y) * out.stride() + x]),
                    expected[static_cast<std::size_t>(y * w + x)])
              << name(format) << " at " << x << "," << y;
        }
      }
    }
  }
}

// A deep Bayer image is demosaiced like the 8-bit image of its top bits.
TEST(PixelConversion, DeepBayerIsDemosaicedLikeItsTopBits) {
  constexpr int w = 6, h = 4;
  std::vector<std::uint16_t> values;
  std::vector<std::byte> eight;
  for (int i = 0; i < w * h; ++i) {
    values.push_back(static_cast<std::uint16_t>((i * 977 + 13) % 4096));
    eight.push_back(static_cast<std::byte>(values.back() >> 4));
  }
  const ImageBuffer want = convert_image(eight, w, h, CameraFormat::bayer_rg8);
  for (const auto& [format, in] :
       {std::pair{CameraFormat::bayer_rg12, test::pack_words(values)},
        std::pair{CameraFormat::bayer_rg12_packed, test::pack_gige(values, 12)},
        std::pair{CameraFormat::bayer_rg12p, test::pack_bit_stream(values, 12)}}) {
    const ImageBuffer out = convert_image(in, w, h, format);
    ASSERT_EQ(out.format(), PixelFormat::rgb8) << name(format);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) EXPECT_EQ(rgb_at(out, x, y), rgb_at(want, x, y)) << name(format);
    }
  }
  std::vector<std::uint16_t> sixteen;
  for (const std::uint16_t v : values) sixteen.push_back(static_cast<std::uint16_t>(v << 4));
  const ImageBuffer out16 =
      convert_image(test::pack_words(sixteen), w, h, CameraFormat::bayer_rg16);
  EXPECT_EQ(rgb_at(out16, 3, 2), rgb_at(want, 3, 2));
}

TEST(PixelConversion, ShortBuffersAreRefusedNamingTheFormat) {
  const auto in = bytes({1, 2, 3});
  try {
    convert_image(in, 2, 2, CameraFormat::bayer_gb8);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("BayerGB8"), std::string::npos) << e.what();
  }
  const auto packed = test::pack_bit_stream({1, 2, 3, 4}, 10);  // 5 bytes: 4 pixels
  EXPECT_THROW(convert_image({packed.data(), 4}, 2, 2, CameraFormat::mono10p),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::aravis
