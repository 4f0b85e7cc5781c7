#include "pixel_conversion.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace mocap::aravis {
namespace {

enum class Kind { mono, bayer_gr, bayer_rg, bayer_gb, bayer_bg, rgb, bgr, uyvy, yuyv };
// How pixel values lie in the bytes (see the header).
enum class Packing { bytes, words, gige_packed, bit_stream };

struct FormatInfo {
  CameraFormat format;
  std::string_view name;
  Kind kind;
  int bits;  // significant bits of a value
  Packing packing;
};

using F = CameraFormat;
using K = Kind;
using P = Packing;
constexpr FormatInfo kFormats[] = {
    {F::mono8, "Mono8", K::mono, 8, P::bytes},
    {F::bayer_gr8, "BayerGR8", K::bayer_gr, 8, P::bytes},
    {F::bayer_rg8, "BayerRG8", K::bayer_rg, 8, P::bytes},
    {F::bayer_gb8, "BayerGB8", K::bayer_gb, 8, P::bytes},
    {F::bayer_bg8, "BayerBG8", K::bayer_bg, 8, P::bytes},
    {F::rgb8, "RGB8", K::rgb, 8, P::bytes},
    {F::bgr8, "BGR8", K::bgr, 8, P::bytes},
    {F::yuv422_uyvy, "YUV422Packed", K::uyvy, 8, P::bytes},
    {F::yuv422_yuyv, "YUV422_YUYV_Packed", K::yuyv, 8, P::bytes},
    {F::mono10, "Mono10", K::mono, 10, P::words},
    {F::mono12, "Mono12", K::mono, 12, P::words},
    {F::mono14, "Mono14", K::mono, 14, P::words},
    {F::mono16, "Mono16", K::mono, 16, P::words},
    {F::mono10_packed, "Mono10Packed", K::mono, 10, P::gige_packed},
    {F::mono12_packed, "Mono12Packed", K::mono, 12, P::gige_packed},
    {F::mono10p, "Mono10p", K::mono, 10, P::bit_stream},
    {F::mono12p, "Mono12p", K::mono, 12, P::bit_stream},
    {F::bayer_gr10, "BayerGR10", K::bayer_gr, 10, P::words},
    {F::bayer_rg10, "BayerRG10", K::bayer_rg, 10, P::words},
    {F::bayer_gb10, "BayerGB10", K::bayer_gb, 10, P::words},
    {F::bayer_bg10, "BayerBG10", K::bayer_bg, 10, P::words},
    {F::bayer_gr12, "BayerGR12", K::bayer_gr, 12, P::words},
    {F::bayer_rg12, "BayerRG12", K::bayer_rg, 12, P::words},
    {F::bayer_gb12, "BayerGB12", K::bayer_gb, 12, P::words},
    {F::bayer_bg12, "BayerBG12", K::bayer_bg, 12, P::words},
    {F::bayer_gr16, "BayerGR16", K::bayer_gr, 16, P::words},
    {F::bayer_rg16, "BayerRG16", K::bayer_rg, 16, P::words},
    {F::bayer_gb16, "BayerGB16", K::bayer_gb, 16, P::words},
    {F::bayer_bg16, "BayerBG16", K::bayer_bg, 16, P::words},
    {F::bayer_gr10_packed, "BayerGR10Packed", K::bayer_gr, 10, P::gige_packed},
    {F::bayer_rg10_packed, "BayerRG10Packed", K::bayer_rg, 10, P::gige_packed},
    {F::bayer_gb10_packed, "BayerGB10Packed", K::bayer_gb, 10, P::gige_packed},
    {F::bayer_bg10_packed, "BayerBG10Packed", K::bayer_bg, 10, P::gige_packed},
    {F::bayer_gr12_packed, "BayerGR12Packed", K::bayer_gr, 12, P::gige_packed},
    {F::bayer_rg12_packed, "BayerRG12Packed", K::bayer_rg, 12, P::gige_packed},
    {F::bayer_gb12_packed, "BayerGB12Packed", K::bayer_gb, 12, P::gige_packed},
    {F::bayer_bg12_packed, "BayerBG12Packed", K::bayer_bg, 12, P::gige_packed},
    {F::bayer_gr10p, "BayerGR10p", K::bayer_gr, 10, P::bit_stream},
    {F::bayer_rg10p, "BayerRG10p", K::bayer_rg, 10, P::bit_stream},
    {F::bayer_gb10p, "BayerGB10p", K::bayer_gb, 10, P::bit_stream},
    {F::bayer_bg10p, "BayerBG10p", K::bayer_bg, 10, P::bit_stream},
    {F::bayer_gr12p, "BayerGR12p", K::bayer_gr, 12, P::bit_stream},
    {F::bayer_rg12p, "BayerRG12p", K::bayer_rg, 12, P::bit_stream},
    {F::bayer_gb12p, "BayerGB12p", K::bayer_gb, 12, P::bit_stream},
    {F::bayer_bg12p, "BayerBG12p", K::bayer_bg, 12, P::bit_stream},
};

const FormatInfo& info(CameraFormat format) {
  for (const FormatInfo& f : kFormats) {
    if (f.format == format) return f;
  }
  throw std::invalid_argument("unknown camera format");  // only a value cast from a bad code
}

// Bits each pixel occupies in the buffer: PFNC keeps it in bits 16..23 of the code.
std::size_t occupied_bits(CameraFormat format) {
  return (static_cast<std::uint32_t>(format) >> 16) & 0xffu;
}

}  // namespace

std::size_t image_bytes(int width, int height, CameraFormat format) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  return (pixels * occupied_bits(format) + 7) / 8;
}

int value_bits(CameraFormat format) { return info(format).bits; }

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

BayerPattern pattern_of(Kind kind) {
  switch (kind) {
    case Kind::bayer_rg:
      return {{0, 1, 1, 2}};
    case Kind::bayer_gr:
      return {{1, 0, 2, 1}};
    case Kind::bayer_bg:
      return {{2, 1, 1, 0}};
    default:
      return {{1, 2, 0, 1}};  // GB
  }
}

// Values of more than 8 bits to one byte each, keeping the top 8 bits (see the header).
std::vector<std::byte> to_8_bits(std::span<const std::byte> src, std::size_t pixels,
                                 const FormatInfo& f) {
  std::vector<std::byte> out(pixels);
  const int shift = f.bits - 8;
  const auto byte_at = [&](std::size_t i) {
    return i < src.size() ? static_cast<unsigned>(src[i]) : 0u;
  };
  for (std::size_t k = 0; k < pixels; ++k) {
    unsigned value = 0;
    switch (f.packing) {
      case Packing::words:
        value = std::min((byte_at(2 * k) | byte_at(2 * k + 1) << 8) >> shift, 255u);
        break;
      case Packing::gige_packed:  // the high 8 bits are a whole byte: 0 or 2 of each group
        value = byte_at(3 * (k / 2) + (k % 2 == 0 ? 0 : 2));
        break;
      case Packing::bit_stream: {
        const std::size_t bit = k * static_cast<std::size_t>(f.bits), at = bit / 8;
        const unsigned word = byte_at(at) | byte_at(at + 1) << 8 | byte_at(at + 2) << 16;
        value = ((word >> (bit % 8)) & ((1u << f.bits) - 1u)) >> shift;
        break;
      }
      case Packing::bytes:
        value = byte_at(k);
        break;
    }
    out[k] = static_cast<std::byte>(value);
  }
  return out;
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
  for (const FormatInfo& f : kFormats) {
    if (static_cast<std::uint32_t>(f.format) == pfnc) return f.format;
  }
  return std::nullopt;
}

std::string_view name(CameraFormat format) {
  for (const FormatInfo& f : kFormats) {
    if (f.format == format) return f.name;
  }
  return "?";
}

PixelFormat converted_format(CameraFormat format) {
  const Kind kind = info(format).kind;
  if (kind == Kind::mono) return PixelFormat::gray8;
  if (kind == Kind::bgr) return PixelFormat::bgr8;
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
  const FormatInfo& f = info(format);
  std::vector<std::byte> eight_bits;
  if (f.packing != Packing::bytes) {
    eight_bits = to_8_bits(bytes, static_cast<std::size_t>(width) * height, f);
    bytes = eight_bits;
  }
  switch (f.kind) {
    case Kind::mono:
      copy_rows(bytes, out, width);
      break;
    case Kind::rgb:
    case Kind::bgr:
      copy_rows(bytes, out, 3 * width);
      break;
    case Kind::uyvy:
    case Kind::yuyv:
      convert_yuv422(bytes, width, height, f.kind == Kind::yuyv, out);
      break;
    default:
      demosaic(bytes, width, height, pattern_of(f.kind), out);
  }
  return out;
}

}  // namespace mocap::aravis
