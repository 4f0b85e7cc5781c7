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

// Image n of the batch: rows × columns × 3 floats.
float* slot(GraphTensor& batch, int n) {
  return batch.values.data() + static_cast<std::size_t>(n) *
                                   static_cast<std::size_t>(batch.shape[1] * batch.shape[2]) * 3;
}

// Writes an 8-bit image of the tensor's size into image n, RGB interleaved.
void to_rgb(const cv::Mat& image, PixelFormat format, GraphTensor& batch, int n) {
  const bool bgr = format == PixelFormat::bgr8 || format == PixelFormat::bgra8;
  const int channels = image.channels();
  float* out = slot(batch, n);
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* p = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x, p += channels, out += 3) {
      if (channels == 1) {
        out[0] = out[1] = out[2] = p[0];
      } else {
        out[0] = p[bgr ? 2 : 0];
        out[1] = p[1];
        out[2] = p[bgr ? 0 : 2];
      }
    }
  }
}

void check_slot(const GraphTensor& batch, int n) {
  if (batch.shape.size() != 4 || batch.shape[3] != 3 || n < 0 || n >= batch.shape[0] ||
      batch.values.size() != batch.size())
    throw std::invalid_argument("image tensor slot out of range");
}

cv::Size image_size(const GraphTensor& batch) {
  return {static_cast<int>(batch.shape[2]), static_cast<int>(batch.shape[1])};
}

}  // namespace

SquareRegion square_around(const Box2D& box, float padding) {
  return {box.x + box.width / 2, box.y + box.height / 2, std::max(box.width, box.height) * padding};
}

void image_batch(GraphTensor& batch, int count, int height, int width) {
  batch.shape = {count, height, width, 3};
  batch.values.assign(batch.size(), 0.0f);
}

void fill_region(const ImageBuffer& frame, const SquareRegion& region, GraphTensor& batch, int n) {
  check_slot(batch, n);
  if (!(region.side > 1.0f)) throw std::invalid_argument("crop region smaller than a pixel");
  const cv::Mat src = frame_view(frame);
  const cv::Size size = image_size(batch);
  // Output pixel centre (u + 0.5) maps to frame x0 + (u + 0.5) · s − 0.5 in OpenCV's convention.
  const double s = region.side / size.width;
  const double x0 = region.cx - region.side / 2, y0 = region.cy - region.side / 2;
  const cv::Matx23d to_frame(s, 0, x0 + 0.5 * s - 0.5, 0, s, y0 + 0.5 * s - 0.5);
  cv::Mat crop;
  cv::warpAffine(src, crop, to_frame, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_CONSTANT, cv::Scalar::all(0));
  to_rgb(crop, frame.format(), batch, n);
}

void fill_stretched(const ImageBuffer& frame, GraphTensor& batch, int n) {
  check_slot(batch, n);
  cv::Mat resized;
  cv::resize(frame_view(frame), resized, image_size(batch), 0, 0, cv::INTER_LINEAR);
  to_rgb(resized, frame.format(), batch, n);
}

}  // namespace mocap::detect
