#include "viz/overlay_output.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "core/input_error.hpp"
#include "video/mp4_writer.hpp"
#include "viz/image_convert.hpp"

namespace mocap::viz {

struct OverlayOutput::Impl {
  OverlayOutputOptions options;
  std::optional<video::Mp4Writer> video;  // created with the first picture
  int width = 0, height = 0;
  std::int64_t pictures = 0;
  std::chrono::steady_clock::time_point last_write{};
  double rate = 0.0;  // pictures per second, smoothed
  std::int64_t pngs = 0;

  // An exponential average of the intervals between pictures: how fast the whole graph runs.
  void measure_rate() {
    const auto now = std::chrono::steady_clock::now();
    if (last_write != std::chrono::steady_clock::time_point{}) {
      const double seconds = std::chrono::duration<double>(now - last_write).count();
      if (seconds > 0.0) rate = rate > 0.0 ? 0.9 * rate + 0.1 / seconds : 1.0 / seconds;
    }
    last_write = now;
  }
  void write_png(const cv::Mat& bgr, std::int64_t frame) {
    char name[64];
    std::snprintf(name, sizeof name, "overlay_%06lld.png", static_cast<long long>(frame));
    const std::string path = (std::filesystem::path(options.png_dir) / name).string();
    bool written = false;
    try {
      written = cv::imwrite(path, bgr);
    } catch (const cv::Exception& e) {
      throw InputError(path, std::string("cannot write the PNG: ") + e.what());
    }
    if (!written) throw InputError(path, "cannot write the PNG");
    ++pngs;
  }
};

OverlayOutput::OverlayOutput(OverlayOutputOptions options) : impl_(std::make_unique<Impl>()) {
  if (!(options.fps > 0.0) || !std::isfinite(options.fps))
    throw std::invalid_argument("overlay output: the frame rate must be positive");
  if (options.png_every < 0) throw std::invalid_argument("overlay output: png_every must be >= 0");
  if (options.png_every > 0) {
    if (options.png_dir.empty())
      throw std::invalid_argument("overlay output: PNGs asked for without a folder (png_dir)");
    std::error_code ec;
    std::filesystem::create_directories(options.png_dir, ec);
    if (ec) throw InputError(options.png_dir, "cannot create the PNG folder: " + ec.message());
  }
  if (const auto parent = std::filesystem::path(options.video).parent_path(); !parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    if (ec) throw InputError(options.video, "cannot create its folder: " + ec.message());
  }
  impl_->options = std::move(options);
}

OverlayOutput::~OverlayOutput() = default;
OverlayOutput::OverlayOutput(OverlayOutput&&) noexcept = default;
OverlayOutput& OverlayOutput::operator=(OverlayOutput&&) noexcept = default;

void OverlayOutput::write(const ImageBuffer& picture, std::int64_t frame) {
  Impl& o = *impl_;
  if (o.pictures == 0) {
    o.width = picture.width();
    o.height = picture.height();
    // The file is made only now: a run that fails before its first picture leaves an existing
    // video as it was.
    if (!o.options.video.empty()) {
      video::Mp4WriterOptions writer{o.options.fps};
      writer.h264_preset = o.options.h264_preset;
      o.video.emplace(o.options.video, o.width, o.height, writer);
    }
  }
  if (picture.width() != o.width || picture.height() != o.height) {
    throw std::invalid_argument("overlay output: picture size changed during the run");
  }
  if (o.video) o.video->write(picture);
  if (o.options.png_every > 0 && o.pictures % o.options.png_every == 0)
    o.write_png(to_bgr(picture), frame);
  ++o.pictures;
  o.measure_rate();
}

void OverlayOutput::close() {
  if (impl_ && impl_->video) impl_->video->close();
}

std::int64_t OverlayOutput::pictures() const { return impl_->pictures; }
std::int64_t OverlayOutput::pngs() const { return impl_->pngs; }
double OverlayOutput::pictures_per_second() const { return impl_->rate; }

}  // namespace mocap::viz
