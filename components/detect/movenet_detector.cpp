#include "detect/movenet_detector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace mocap::detect {
namespace {

constexpr int kSizeMultiple = 32;

int round_up(int value, int multiple) { return (value + multiple - 1) / multiple * multiple; }

void check_input_size(int input_size) {
  if (input_size < kSizeMultiple || input_size % kSizeMultiple)
    throw std::invalid_argument("MoveNet input size " + std::to_string(input_size) +
                                " is not a positive multiple of 32");
}

int cv_type(PixelFormat format) {
  return format == PixelFormat::gray8                                   ? CV_8UC1
         : format == PixelFormat::rgba8 || format == PixelFormat::bgra8 ? CV_8UC4
                                                                        : CV_8UC3;
}

// The colour conversion to RGB, or -1 when the pixels are RGB already.
int to_rgb_code(PixelFormat format) {
  switch (format) {
    case PixelFormat::gray8:
      return cv::COLOR_GRAY2RGB;
    case PixelFormat::bgr8:
      return cv::COLOR_BGR2RGB;
    case PixelFormat::rgba8:
      return cv::COLOR_RGBA2RGB;
    case PixelFormat::bgra8:
      return cv::COLOR_BGRA2RGB;
    case PixelFormat::rgb8:
      break;
  }
  return -1;
}

RunnerOptions runner_options(const MovenetOptions& options) {
  RunnerOptions r;
  r.backend = options.backend;
  r.threads = options.threads;
  return r;
}

}  // namespace

MovenetInput prepare_movenet_input(const ImageBuffer& image, int input_size) {
  check_input_size(input_size);
  if (image.empty() || image.width() <= 0 || image.height() <= 0)
    throw std::invalid_argument("MoveNet: empty image");
  const cv::Mat view(image.height(), image.width(), cv_type(image.format()),
                     const_cast<std::byte*>(image.data()),
                     static_cast<std::size_t>(image.stride()));
  const double scale = static_cast<double>(input_size) / std::max(image.width(), image.height());
  const int w = std::max(1, static_cast<int>(std::lround(image.width() * scale)));
  const int h = std::max(1, static_cast<int>(std::lround(image.height() * scale)));
  cv::Mat resized;
  cv::resize(view, resized, cv::Size(w, h), 0, 0, cv::INTER_LINEAR);

  MovenetInput input;
  input.tensor =
      ImageBuffer(round_up(w, kSizeMultiple), round_up(h, kSizeMultiple), PixelFormat::rgb8);
  const auto pixels = input.tensor.pixels_for_writing();  // zero-filled: the padding is black
  cv::Mat tensor(input.tensor.height(), input.tensor.width(), CV_8UC3, pixels.data(),
                 static_cast<std::size_t>(input.tensor.stride()));
  cv::Mat roi = tensor(cv::Rect(0, 0, w, h));
  if (const int code = to_rgb_code(image.format()); code >= 0)
    cv::cvtColor(resized, roi, code);
  else
    resized.copyTo(roi);
  input.mapping = {input.tensor.width(),
                   input.tensor.height(),
                   static_cast<float>(w) / static_cast<float>(image.width()),
                   static_cast<float>(h) / static_cast<float>(image.height()),
                   0.0f,
                   0.0f};
  return input;
}

MovenetDetector::MovenetDetector(const std::filesystem::path& model_json,
                                 const MovenetOptions& options)
    : options_((check_input_size(options.input_size), options)),
      network_(model_json, runner_options(options)) {}

std::vector<MovenetPerson> MovenetDetector::detect(const ImageBuffer& image) {
  const MovenetInput input = prepare_movenet_input(image, options_.input_size);
  network_.run(input.tensor, heads_);
  return select_people(decode_movenet(heads_), input.mapping, options_.thresholds);
}

}  // namespace mocap::detect
