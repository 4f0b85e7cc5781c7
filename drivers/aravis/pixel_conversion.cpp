#include "pixel_conversion.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace mocap::aravis {
namespace {

constexpr std::array kFormats = {
    CameraFormat::mono8,     CameraFormat::bayer_gr8,   CameraFormat::bayer_rg8,
    CameraFormat::bayer_gb8, CameraFormat::bayer_bg8,   CameraFormat::rgb8,
    CameraFormat::bgr8,      CameraFormat::yuv422_uyvy, CameraFormat::yuv422_yuyv,
};

}  // namespace

std::size_t image_bytes(int width, int height, CameraFormat format) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  switch (format) {
    case CameraFormat::rgb8:
    case CameraFormat::bgr8:
      return pixels * 3;
    case CameraFormat::yuv422_uyvy:
    case CameraFormat::yuv422_yuyv:
      return pixels * 2;
    default:
      return pixels;
  }
}

namespace {

void copy_rows(std::span<const std::byte> src, ImageBuffer& out, int row_bytes) {
  const auto dst = out.pixels_for_writing();
  for (int y = 0; y < out.height(); ++y) {
    std::memcpy(dst.data() + static_cast<std::size_t>(y) * out.stride(),
                src.data() + static_cast<std::size_t>(y) * row_bytes,
                static_cast<std::size_t>(row_bytes));
  }
}

// Colour channel (0 R, 1 G, 2 B) of the sensor site (x, y) for a 2x2 pattern whose top-left
// site is `origin` (e.g. RG: R at (0,0), G at (1,0) and (0,1), B at (1,1)).
struct BayerPattern {
  std::array<int, 4> channel;  // sites (0,0), (1,0), (0,1), (1,1)
  int at(int x, int y) const { return channel[static_cast<std::size_t>((x & 1) + 2 * (y & 1))]; }
};

BayerPattern pattern_of(CameraFormat format) {
  switch (format) {
    case CameraFormat::bayer_rg8:
      return {{0, 1, 1, 2}};
    case CameraFormat::bayer_gr8:
      return {{1, 0, 2, 1}};
    case CameraFormat::bayer_bg8:
      return {{2, 1, 1, 0}};
    default:
      return {{1, 2, 0, 1}};  // GB
  }
}

// Bilinear demosaicing: each channel of a pixel is the mean of the sites of that channel in its
// 3x3 neighbourhood (its own site alone for its own channel). Clamping at the borders still
// leaves every channel at least one site, since any 2x2 block holds all of them.
void demosaic(std::span<const std::byte> src, int width, int height, BayerPattern pattern,
              ImageBuffer& out) {
  const auto dst = out.pixels_for_writing();
  const auto site = [&](int x, int y) {
    return static_cast<int>(src[static_cast<std::size_t>(y) * width + x]);
  };
  for (int y = 0; y < height; ++y) {
    std::byte* row = dst.data() + static_cast<std::size_t>(y) * out.stride();
    for (int x = 0; x < width; ++x) {
      std::array<int, 3> sum{}, count{};
      const int own = pattern.at(x, y);
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int sx = std::clamp(x + dx, 0, width - 1), sy = std::clamp(y + dy, 0, height - 1);
          const int c = pattern.at(sx, sy);
          if (c == own && (sx != x || sy != y)) continue;
          sum[static_cast<std::size_t>(c)] += site(sx, sy);
          ++count[static_cast<std::size_t>(c)];
        }
      }
      for (std::size_t c = 0; c < 3; ++c) {
        const int value = count[c] > 0 ? (sum[c] + count[c] / 2) / count[c] : 0;
        row[3 * static_cast<std::size_t>(x) + c] = static_cast<std::byte>(value);
      }
    }
  }
}

std::byte clamp_byte(int value) { return static_cast<std::byte>(std::clamp(value, 0, 255)); }

// BT.601 limited range, in integers (scaled by 256).
void yuv_to_rgb(int y, int u, int v, std::byte* rgb) {
  const int c = 298 * (y - 16), d = u - 128, e = v - 128;
  rgb[0] = clamp_byte((c + 409 * e + 128) >> 8);
  rgb[1] = clamp_byte((c - 100 * d - 208 * e + 128) >> 8);
  rgb[2] = clamp_byte((c + 516 * d + 128) >> 8);
}

void convert_yuv422(std::span<const std::byte> src, int width, int height, bool yuyv,
                    ImageBuffer& out) {
  const auto dst = out.pixels_for_writing();
  // Byte offsets of Y0, U, Y1, V inside each 4-byte group of two pixels.
  const std::array<int, 4> at = yuyv ? std::array{0, 1, 2, 3} : std::array{1, 0, 3, 2};
  for (int y = 0; y < height; ++y) {
    const std::byte* in = src.data() + static_cast<std::size_t>(y) * width * 2;
    std::byte* row = dst.data() + static_cast<std::size_t>(y) * out.stride();
    for (int x = 0; x < width; ++x) {
      const std::byte* group = in + static_cast<std::size_t>(x / 2) * 4;
      const int luma = static_cast<int>(group[at[static_cast<std::size_t>(x % 2 == 0 ? 0 : 2)]]);
      yuv_to_rgb(luma, static_cast<int>(group[at[1]]), static_cast<int>(group[at[3]]),
                 row + 3 * static_cast<std::size_t>(x));
    }
  }
}

}  // namespace

std::optional<CameraFormat> camera_format_from_code(std::uint32_t pfnc) {
  for (const CameraFormat f : kFormats) {
    if (static_cast<std::uint32_t>(f) == pfnc) return f;
  }
  return std::nullopt;
}

std::string_view name(CameraFormat format) {
  switch (format) {
    case CameraFormat::mono8:
      return "Mono8";
    case CameraFormat::bayer_gr8:
      return "BayerGR8";
    case CameraFormat::bayer_rg8:
      return "BayerRG8";
    case CameraFormat::bayer_gb8:
      return "BayerGB8";
    case CameraFormat::bayer_bg8:
      return "BayerBG8";
    case CameraFormat::rgb8:
      return "RGB8";
    case CameraFormat::bgr8:
      return "BGR8";
    case CameraFormat::yuv422_uyvy:
      return "YUV422Packed";
    case CameraFormat::yuv422_yuyv:
      return "YUV422_YUYV_Packed";
  }
  return "?";
}

PixelFormat converted_format(CameraFormat format) {
  if (format == CameraFormat::mono8) return PixelFormat::gray8;
  if (format == CameraFormat::bgr8) return PixelFormat::bgr8;
  return PixelFormat::rgb8;
}

std::string describe_pfnc(std::uint32_t pfnc) {
  if (const auto f = camera_format_from_code(pfnc)) return std::string(name(*f));
  char text[32];
  std::snprintf(text, sizeof text, "PixelFormat 0x%08x", static_cast<unsigned>(pfnc));
  return text;
}

ImageBuffer convert_image(std::span<const std::byte> bytes, int width, int height,
                          CameraFormat format) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("empty camera image");
  const bool yuv = format == CameraFormat::yuv422_uyvy || format == CameraFormat::yuv422_yuyv;
  if (yuv && width % 2 != 0)
    throw std::invalid_argument(std::string(name(format)) + " needs an even width");
  const std::size_t needed = image_bytes(width, height, format);
  if (bytes.size() < needed) {
    throw std::invalid_argument(std::string(name(format)) + " image of " + std::to_string(width) +
                                "x" + std::to_string(height) + " needs " + std::to_string(needed) +
                                " bytes, got " + std::to_string(bytes.size()));
  }
  ImageBuffer out(width, height, converted_format(format));
  switch (format) {
    case CameraFormat::mono8:
      copy_rows(bytes, out, width);
      break;
    case CameraFormat::rgb8:
    case CameraFormat::bgr8:
      copy_rows(bytes, out, 3 * width);
      break;
    case CameraFormat::yuv422_uyvy:
    case CameraFormat::yuv422_yuyv:
      convert_yuv422(bytes, width, height, format == CameraFormat::yuv422_yuyv, out);
      break;
    default:
      demosaic(bytes, width, height, pattern_of(format), out);
  }
  return out;
}

}  // namespace mocap::aravis
