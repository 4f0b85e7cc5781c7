#include "video/video_source.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/core/version.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/input_error.hpp"

namespace mocap::video {
namespace {

namespace fs = std::filesystem;

std::int64_t realtime_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool all_digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Natural order: "img2.png" before "img10.png" (digit runs compare by value).
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) &&
        std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ei = i, ej = j;
      while (ei < a.size() && std::isdigit(static_cast<unsigned char>(a[ei]))) ++ei;
      while (ej < b.size() && std::isdigit(static_cast<unsigned char>(b[ej]))) ++ej;
      // Compare without leading zeros: first by length, then digit by digit.
      std::size_t si = i, sj = j;
      while (si + 1 < ei && a[si] == '0') ++si;
      while (sj + 1 < ej && b[sj] == '0') ++sj;
      if (ei - si != ej - sj) return ei - si < ej - sj;
      const int c = a.compare(si, ei - si, b, sj, ej - sj);
      if (c != 0) return c < 0;
      i = ei;
      j = ej;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j || (a.size() - i == b.size() - j && a < b);
}

ImageBuffer wrap(std::shared_ptr<cv::Mat> mat) {
  if (mat->type() != CV_8UC3) {
    throw std::runtime_error("video: decoded frame is not 8-bit BGR");
  }
  const auto* bytes = reinterpret_cast<const std::byte*>(mat->data);
  const int width = mat->cols, height = mat->rows, stride = static_cast<int>(mat->step[0]);
  return ImageBuffer(width, height, stride, PixelFormat::bgr8, std::move(mat), bytes);
}

// Frames a container announces that a complete file may still fall short of (rounding in the
// header's duration, a last frame the decoder holds back).
constexpr std::int64_t kFrameCountSlack = 2;
// Beyond the slack, up to this fraction of the announced frames may be missing at the end: damaged
// frames in the middle that FFmpeg could not decode and passed over (it says nothing else about
// them). More is taken for a file cut short.
constexpr double kUndecodableFraction = 0.1;

}  // namespace

std::string_view name(SourceKind kind) {
  switch (kind) {
    case SourceKind::file:
      return "file";
    case SourceKind::device:
      return "device";
    case SourceKind::network:
      return "network";
    case SourceKind::image_folder:
      return "image folder";
  }
  return "?";
}

SourceKind classify(const std::string& source) {
  const std::string s = lower(source);
  for (const char* scheme :
       {"rtsp://", "rtsps://", "http://", "https://", "rtmp://", "udp://", "tcp://", "srt://"}) {
    if (s.rfind(scheme, 0) == 0) return SourceKind::network;
  }
  if (all_digits(s) || (s.rfind("/dev/video", 0) == 0)) return SourceKind::device;
  std::error_code ec;
  if (fs::is_directory(source, ec)) return SourceKind::image_folder;
  return SourceKind::file;
}

bool decoder_threads_supported() {
#if CV_VERSION_MAJOR > 4 || (CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR >= 7)
  return true;
#else
  return false;
#endif
}

bool is_image_file_name(std::string_view file_name) {
  const std::string ext = lower(fs::path(file_name).extension().string());
  for (const char* e : {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm", ".webp"})
    if (ext == e) return true;
  return false;
}

struct VideoSource::Impl {
  std::string source;
  SourceOptions options;
  SourceKind kind = SourceKind::file;
  cv::VideoCapture capture;
  std::vector<fs::path> images;  // image folders
  int width = 0, height = 0;
  double fps = 0.0;
  std::int64_t frame_count = -1;
  std::int64_t next_index = 0;  // index of the next frame read() returns
  double last_media_time = -1.0;
  std::int64_t undecodable = 0;  // announced frames not decoded, known at the end
  std::optional<Frame> first;    // decoded while opening, returned by the first read()

  [[noreturn]] void fail(const std::string& what) const { throw InputError(source, what); }

  void open() {
    kind = classify(source);
    switch (kind) {
      case SourceKind::image_folder:
        open_folder();
        break;
      case SourceKind::device:
        open_device();
        break;
      case SourceKind::network:
        open_stream();
        break;
      case SourceKind::file:
        open_file();
        break;
    }
    // The first frame proves that the input decodes (FFmpeg opens some garbage as a container).
    first = decode();
    if (!first) fail("no frame could be decoded (empty, truncated or not a video)");
    width = first->image.width();
    height = first->image.height();
  }

  void open_folder() {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(source, ec)) {
      if (entry.is_regular_file(ec) && is_image_file_name(entry.path().filename().string()))
        images.push_back(entry.path());
    }
    if (ec) fail("cannot list the folder: " + ec.message());
    if (images.empty())
      fail("no images in this folder (.png, .jpg, .bmp, .tif, .ppm, .pgm, .webp)");
    std::sort(images.begin(), images.end(), [](const fs::path& a, const fs::path& b) {
      return natural_less(a.filename().string(), b.filename().string());
    });
    fps = options.folder_fps > 0 ? options.folder_fps : 30.0;
    frame_count = static_cast<std::int64_t>(images.size());
  }

  void open_device() {
    std::string path = source;
    if (all_digits(source)) path = "/dev/video" + source;
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      fail("no such camera device (unplugged? `ls /dev/video*` lists the cameras present)");
    }
    capture.open(path, cv::CAP_V4L2);
    if (!capture.isOpened())
      fail(
          "cannot open the camera device (not a video capture device, busy, or no permission: "
          "is the user in group 'video'?)");
    // One driver buffer: a slow reader gets the newest frame, not one queued long ago.
    capture.set(cv::CAP_PROP_BUFFERSIZE, 1);
    if (options.width > 0) capture.set(cv::CAP_PROP_FRAME_WIDTH, options.width);
    if (options.height > 0) capture.set(cv::CAP_PROP_FRAME_HEIGHT, options.height);
    if (options.fps > 0) capture.set(cv::CAP_PROP_FPS, options.fps);
    fps = capture.get(cv::CAP_PROP_FPS);
  }

  std::vector<int> ffmpeg_params(bool network) const {
    // Built by push_back: GCC 12 warns (falsely) on insert() of an initializer list here.
    std::vector<int> params;
    if (network) {
      for (const int p : {static_cast<int>(cv::CAP_PROP_OPEN_TIMEOUT_MSEC), options.timeout_ms,
                          static_cast<int>(cv::CAP_PROP_READ_TIMEOUT_MSEC), options.timeout_ms})
        params.push_back(p);
    }
#if CV_VERSION_MAJOR > 4 || (CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR >= 7)
    if (options.decoder_threads > 0) {
      params.push_back(cv::CAP_PROP_N_THREADS);
      params.push_back(options.decoder_threads);
    }
#endif
    return params;
  }

  void open_stream() {
    capture.open(source, cv::CAP_FFMPEG, ffmpeg_params(true));
    if (!capture.isOpened())
      fail("cannot open the network stream (unreachable, refused, or not a video; waited " +
           std::to_string(options.timeout_ms) + " ms)");
    fps = capture.get(cv::CAP_PROP_FPS);
    // A file served over HTTP announces its frames like a file on disk: a stream that stops
    // before them is cut short (end_of_input). A live stream announces none.
    const double count = capture.get(cv::CAP_PROP_FRAME_COUNT);
    frame_count = count > 0 && count < 1e9 ? static_cast<std::int64_t>(count) : -1;
  }

  void open_file() {
    std::error_code ec;
    if (!fs::exists(source, ec)) fail("no such file");
    if (!fs::is_regular_file(source, ec)) fail("not a regular file");
    if (fs::file_size(source, ec) == 0) fail("empty file");
    capture.open(source, cv::CAP_FFMPEG, ffmpeg_params(false));
    if (!capture.isOpened())
      fail("not a video this build can read (unknown container or codec, or damaged)");
    fps = capture.get(cv::CAP_PROP_FPS);
    if (!(fps > 0 && fps < 1000)) fps = 0.0;
    const double count = capture.get(cv::CAP_PROP_FRAME_COUNT);
    frame_count = count > 0 && count < 1e9 ? static_cast<std::int64_t>(count) : -1;
  }

  // Presentation time of the frame just read: the container's when it moves forward, else
  // counted from the frame rate.
  double media_time(std::int64_t index) {
    double t = -1.0;
    if (kind == SourceKind::file) t = capture.get(cv::CAP_PROP_POS_MSEC) / 1000.0;
    const double counted = fps > 0 ? static_cast<double>(index) / fps : 0.0;
    if (!(t > last_media_time)) t = std::max(counted, last_media_time + 1e-6);
    if (index == 0 && kind != SourceKind::file) t = 0.0;
    last_media_time = t;
    return t;
  }

  // When a device captured the frame just read: V4L2 reports its buffer's timestamp (CLOCK_
  // MONOTONIC, milliseconds) as the position; it is moved to CLOCK_REALTIME. Anything
  // implausible falls back to now.
  std::int64_t capture_time(std::int64_t now_ns) const {
    if (kind != SourceKind::device) return now_ns;
    const double ms = capture.get(cv::CAP_PROP_POS_MSEC);
    const double steady_ms = std::chrono::duration<double, std::milli>(
                                 std::chrono::steady_clock::now().time_since_epoch())
                                 .count();
    const double age_ms = steady_ms - ms;
    if (ms > 0 && age_ms >= 0 && age_ms < 1000)
      return now_ns - static_cast<std::int64_t>(age_ms * 1e6);
    return now_ns;
  }

  // Decodes the next frame (nullopt at the end, errors as documented).
  std::optional<Frame> decode() {
    Frame frame;
    frame.index = next_index;
    if (kind == SourceKind::image_folder) {
      if (next_index >= static_cast<std::int64_t>(images.size())) return std::nullopt;
      const fs::path& file = images[static_cast<std::size_t>(next_index)];
      auto mat = std::make_shared<cv::Mat>(cv::imread(file.string(), cv::IMREAD_COLOR));
      if (mat->empty()) throw InputError(file.string(), "not an image OpenCV can read (damaged?)");
      if (width > 0 && (mat->cols != width || mat->rows != height)) {
        throw InputError(file.string(), "is " + std::to_string(mat->cols) + "x" +
                                            std::to_string(mat->rows) +
                                            ", the folder's first image " + std::to_string(width) +
                                            "x" + std::to_string(height) +
                                            ": the images of a folder must share one size");
      }
      frame.capture_ns = realtime_now_ns();
      frame.image = wrap(std::move(mat));
    } else {
      auto mat = std::make_shared<cv::Mat>();
      if (!capture.read(*mat) || mat->empty()) {
        end_of_input();
        return std::nullopt;
      }
      frame.capture_ns = capture_time(realtime_now_ns());
      if (mat->type() == CV_8UC1) cv::cvtColor(*mat, *mat, cv::COLOR_GRAY2BGR);
      frame.image = wrap(std::move(mat));
    }
    frame.media_time_s = media_time(next_index);
    ++next_index;
    return frame;
  }

  bool grab() {
    if (kind == SourceKind::image_folder) {
      if (next_index >= static_cast<std::int64_t>(images.size())) return false;
    } else if (!capture.grab()) {
      end_of_input();
      return false;
    }
    media_time(next_index);
    ++next_index;
    return true;
  }

  // A capture that stops: the normal end of a file or stream, or an error.
  void end_of_input() {
    if (kind == SourceKind::device)
      fail("the camera device stopped delivering frames after " + std::to_string(next_index) +
           " (unplugged?)");
    if ((kind == SourceKind::file || kind == SourceKind::network) && frame_count > 0 &&
        next_index + kFrameCountSlack < frame_count) {
      const std::int64_t missing = frame_count - next_index;
      if (static_cast<double>(missing) > kUndecodableFraction * static_cast<double>(frame_count)) {
        fail(std::string(kind == SourceKind::network ? "the stream stopped early (connection lost "
                                                       "or the file cut short)"
                                                     : "truncated or damaged") +
             ": decoding stopped after " + std::to_string(next_index) + " of the " +
             std::to_string(frame_count) + " frames its container announces");
      }
      undecodable = missing;
    }
  }
};

VideoSource::VideoSource(std::string source, SourceOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->source = std::move(source);
  impl_->options = options;
  impl_->open();
}

VideoSource::~VideoSource() = default;
VideoSource::VideoSource(VideoSource&&) noexcept = default;
VideoSource& VideoSource::operator=(VideoSource&&) noexcept = default;

std::optional<Frame> VideoSource::read() {
  if (impl_->first) {
    std::optional<Frame> f = std::move(impl_->first);
    impl_->first.reset();
    return f;
  }
  return impl_->decode();
}

bool VideoSource::skip() {
  if (impl_->first) {
    impl_->first.reset();
    return true;
  }
  return impl_->grab();
}

const std::string& VideoSource::source() const { return impl_->source; }
SourceKind VideoSource::kind() const { return impl_->kind; }
bool VideoSource::live() const {
  return impl_->kind == SourceKind::device || impl_->kind == SourceKind::network;
}
int VideoSource::width() const { return impl_->width; }
int VideoSource::height() const { return impl_->height; }
double VideoSource::fps() const { return impl_->fps; }
std::int64_t VideoSource::frame_count() const { return impl_->frame_count; }
std::int64_t VideoSource::frames_undecodable() const { return impl_->undecodable; }
std::int64_t VideoSource::frames_read() const { return impl_->next_index - (impl_->first ? 1 : 0); }

}  // namespace mocap::video
