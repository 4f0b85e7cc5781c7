#include "viz/image_convert.hpp"

#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace mocap::viz {
namespace {

int mat_type(PixelFormat format) {
  switch (format) {
    case PixelFormat::gray8:
      return CV_8UC1;
    case PixelFormat::rgb8:
    case PixelFormat::bgr8:
      return CV_8UC3;
    case PixelFormat::rgba8:
    case PixelFormat::bgra8:
      return CV_8UC4;
  }
  throw std::invalid_argument("image: unknown pixel format");
}

}  // namespace

cv::Mat as_mat(ImageBuffer& image) {
  return cv::Mat(image.height(), image.width(), mat_type(image.format()),
                 image.pixels_for_writing().data(), static_cast<std::size_t>(image.stride()));
}

cv::Mat view_of(const ImageBuffer& image) {
  // OpenCV has no read-only Mat; nothing below writes through this view.
  return cv::Mat(image.height(), image.width(), mat_type(image.format()),
                 const_cast<std::byte*>(image.data()), static_cast<std::size_t>(image.stride()));
}

cv::Mat to_bgr(const ImageBuffer& image) {
  const cv::Mat view = view_of(image);
  cv::Mat out;
  switch (image.format()) {
    case PixelFormat::bgr8:
      return view;
    case PixelFormat::gray8:
      cv::cvtColor(view, out, cv::COLOR_GRAY2BGR);
      break;
    case PixelFormat::rgb8:
      cv::cvtColor(view, out, cv::COLOR_RGB2BGR);
      break;
    case PixelFormat::rgba8:
      cv::cvtColor(view, out, cv::COLOR_RGBA2BGR);
      break;
    case PixelFormat::bgra8:
      cv::cvtColor(view, out, cv::COLOR_BGRA2BGR);
      break;
  }
  return out;
}

}  // namespace mocap::viz
