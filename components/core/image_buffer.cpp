#include "core/image_buffer.hpp"

#include <stdexcept>
#include <string>
#include <vector>

namespace mocap {

int bytes_per_pixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::gray8:
      return 1;
    case PixelFormat::rgb8:
    case PixelFormat::bgr8:
      return 3;
    case PixelFormat::rgba8:
    case PixelFormat::bgra8:
      return 4;
  }
  return 0;
}

std::string_view name(PixelFormat format) {
  switch (format) {
    case PixelFormat::gray8:
      return "gray8";
    case PixelFormat::rgb8:
      return "rgb8";
    case PixelFormat::bgr8:
      return "bgr8";
    case PixelFormat::rgba8:
      return "rgba8";
    case PixelFormat::bgra8:
      return "bgra8";
  }
  return "unknown";
}

std::optional<PixelFormat> pixel_format_from_code(std::uint8_t code) {
  if (code < 1 || code > 5) return std::nullopt;
  return static_cast<PixelFormat>(code);
}

std::optional<PixelFormat> pixel_format_from_name(std::string_view text) {
  for (std::uint8_t code = 1; code <= 5; ++code) {
    const auto format = static_cast<PixelFormat>(code);
    if (name(format) == text) return format;
  }
  return std::nullopt;
}

ImageBuffer::ImageBuffer(int width, int height, PixelFormat format)
    : width_(width), height_(height), stride_(width * bytes_per_pixel(format)), format_(format) {
  if (width < 0 || height < 0) throw std::invalid_argument("ImageBuffer: negative size");
  auto storage = std::make_shared<std::vector<std::byte>>(size_bytes());
  bytes_ = storage->data();
  owner_ = std::move(storage);
}

ImageBuffer::ImageBuffer(int width, int height, int stride, PixelFormat format,
                         std::shared_ptr<const void> owner, const std::byte* bytes)
    : width_(width),
      height_(height),
      stride_(stride),
      format_(format),
      owner_(std::move(owner)),
      bytes_(bytes) {
  if (width < 0 || height < 0 || stride < width * bytes_per_pixel(format)) {
    throw std::invalid_argument("ImageBuffer: stride " + std::to_string(stride) +
                                " too small for width " + std::to_string(width));
  }
  if (bytes == nullptr && height > 0 && width > 0) {
    throw std::invalid_argument("ImageBuffer: no bytes");
  }
}

std::span<std::byte> ImageBuffer::pixels_for_writing() {
  // The bytes are const for every consumer; the producer owns them until it sends the image.
  return {const_cast<std::byte*>(bytes_), size_bytes()};
}

}  // namespace mocap
