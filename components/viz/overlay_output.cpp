#include "viz/overlay_output.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/input_error.hpp"
#include "viz/image_convert.hpp"

namespace mocap::viz {

struct OverlayOutput::Impl {
  OverlayOutputOptions options;
  cv::VideoWriter video;
  cv::Size size;
  std::int64_t pictures = 0;
  std::int64_t pngs = 0;

  void open_video(cv::Size picture_size) {
    size = picture_size;
    if (options.video.empty()) return;
    if (!video.open(options.video, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'),
                    options.fps, size, true)) {
      throw InputError(options.video, "cannot open the video for writing (MP4, codec mp4v)");
    }
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
  const cv::Mat bgr = to_bgr(picture);
  if (o.pictures == 0) o.open_video(bgr.size());
  if (bgr.size() != o.size) {
    throw std::invalid_argument("overlay output: picture size changed during the run");
  }
  if (o.video.isOpened()) o.video.write(bgr);
  if (o.options.png_every > 0 && o.pictures % o.options.png_every == 0) o.write_png(bgr, frame);
  ++o.pictures;
}

void OverlayOutput::close() {
  if (!impl_ || !impl_->video.isOpened()) return;
  impl_->video.release();
  // VideoWriter reports no write errors; an empty file after frames were written is one.
  std::error_code ec;
  if (std::filesystem::file_size(impl_->options.video, ec) == 0 || ec)
    throw InputError(impl_->options.video, "the video file is empty after writing (disk full?)");
}

std::int64_t OverlayOutput::pictures() const { return impl_->pictures; }
std::int64_t OverlayOutput::pngs() const { return impl_->pngs; }

}  // namespace mocap::viz
