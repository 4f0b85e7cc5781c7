#pragma once
// An image that can be shared without copying: width, height, row stride, pixel format and
// immutable bytes kept alive by a shared owner. The owner may be this buffer's own allocation, a
// received ZeroMQ frame or (later) a cv::Mat, so any of them wraps the others without a copy:
//   cv::Mat view(h, w, CV_8UC3, const_cast<std::byte*>(img.data()), img.stride());

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

namespace mocap {

enum class PixelFormat : std::uint8_t { gray8 = 1, rgb8 = 2, bgr8 = 3, rgba8 = 4, bgra8 = 5 };

int bytes_per_pixel(PixelFormat format);
std::string_view name(PixelFormat format);
std::optional<PixelFormat> pixel_format_from_name(std::string_view name);
std::optional<PixelFormat> pixel_format_from_code(std::uint8_t code);

class ImageBuffer {
 public:
  ImageBuffer() = default;
  // A new zero-filled image with tightly packed rows; fill it through pixels_for_writing() before
  // it is sent.
  ImageBuffer(int width, int height, PixelFormat format);
  // Wraps bytes owned elsewhere; `bytes` must stay valid while `owner` lives and hold
  // stride * height bytes. Throws std::invalid_argument on inconsistent geometry.
  ImageBuffer(int width, int height, int stride, PixelFormat format,
              std::shared_ptr<const void> owner, const std::byte* bytes);

  int width() const { return width_; }
  int height() const { return height_; }
  int stride() const { return stride_; }  // bytes from one row to the next
  PixelFormat format() const { return format_; }
  bool empty() const { return bytes_ == nullptr; }
  const std::byte* data() const { return bytes_; }
  std::size_t size_bytes() const { return static_cast<std::size_t>(stride_) * height_; }
  std::span<const std::byte> bytes() const { return {bytes_, size_bytes()}; }
  const std::shared_ptr<const void>& owner() const { return owner_; }

  // Only for the producer, before the image is shared: every copy of a buffer sees the same bytes.
  std::span<std::byte> pixels_for_writing();

 private:
  int width_ = 0, height_ = 0, stride_ = 0;
  PixelFormat format_ = PixelFormat::rgb8;
  std::shared_ptr<const void> owner_;
  const std::byte* bytes_ = nullptr;
};

}  // namespace mocap
