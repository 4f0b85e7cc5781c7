#include "detect/image_tensor.hpp"

#include <algorithm>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace mocap::detect {
namespace {

cv::Mat frame_view(const ImageBuffer& frame) {
  if (frame.empty() || frame.width() <= 0 || frame.height() <= 0)
    throw std::invalid_argument("empty frame");
  const PixelFormat f = frame.format();
  const int type = f == PixelFormat::gray8                              ? CV_8UC1
                   : f == PixelFormat::rgba8 || f == PixelFormat::bgra8 ? CV_8UC4
                                                                        : CV_8UC3;
  return cv::Mat(frame.height(), frame.width(), type, const_cast<std::byte*>(frame.data()),
                 static_cast<std::size_t>(frame.stride()));
}

// Spreads an 8-bit image of the tensor's size over the three float planes of image n, RGB.
void to_planes(const cv::Mat& image, PixelFormat format, Tensor& batch, int n) {
  const bool bgr = format == PixelFormat::bgr8 || format == PixelFormat::bgra8;
  const int channels = image.channels();
  float* r = batch.values.data() + (static_cast<std::size_t>(n) * 3 + 0) * batch.plane();
  float* g = r + batch.plane();
  float* b = g + batch.plane();
  std::size_t i = 0;
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* p = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x, ++i, p += channels) {
      if (channels == 1) {
        r[i] = g[i] = b[i] = p[0];
      } else {
        r[i] = p[bgr ? 2 : 0];
        g[i] = p[1];
        b[i] = p[bgr ? 0 : 2];
      }
    }
  }
}

void check_slot(const Tensor& batch, int n) {
  if (batch.channels != 3 || n < 0 || n >= batch.batch ||
      batch.values.size() != static_cast<std::size_t>(batch.batch) * 3 * batch.plane())
    throw std::invalid_argument("image tensor slot out of range");
}

}  // namespace

SquareRegion square_around(const Box2D& box, float padding) {
  return {box.x + box.width / 2, box.y + box.height / 2, std::max(box.width, box.height) * padding};
}

Tensor image_batch(int batch, int height, int width) {
  Tensor t{batch, 3, height, width, {}};
  t.values.assign(static_cast<std::size_t>(batch) * 3 * t.plane(), 0.0f);
  return t;
}

void fill_region(const ImageBuffer& frame, const SquareRegion& region, Tensor& batch, int n) {
  check_slot(batch, n);
  if (!(region.side > 1.0f)) throw std::invalid_argument("crop region smaller than a pixel");
  const cv::Mat src = frame_view(frame);
  // Output pixel centre (u + 0.5) maps to frame x0 + (u + 0.5) · s − 0.5 in OpenCV's convention.
  const double s = region.side / batch.width;
  const double x0 = region.cx - region.side / 2, y0 = region.cy - region.side / 2;
  const cv::Matx23d to_frame(s, 0, x0 + 0.5 * s - 0.5, 0, s, y0 + 0.5 * s - 0.5);
  cv::Mat crop;
  cv::warpAffine(src, crop, to_frame, cv::Size(batch.width, batch.height),
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  to_planes(crop, frame.format(), batch, n);
}

void fill_stretched(const ImageBuffer& frame, Tensor& batch, int n) {
  check_slot(batch, n);
  cv::Mat resized;
  cv::resize(frame_view(frame), resized, cv::Size(batch.width, batch.height), 0, 0,
             cv::INTER_LINEAR);
  to_planes(resized, frame.format(), batch, n);
}

}  // namespace mocap::detect
