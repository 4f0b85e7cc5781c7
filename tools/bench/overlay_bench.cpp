// mocap-bench-overlay: what the overlay's video costs. Frames of a real video (scaled to each size
// asked for) are written by each writer: OpenCV's cv::VideoWriter (MPEG-4 Part 2 "mp4v", an index
// at the end: what the overlay used before), and video::Mp4Writer (a fragmented MP4 that plays at
// every moment, fragmented) in MPEG-4 Part 2 and in H.264 (libx264) at three presets with one
// encoder thread, and at the default preset with FFmpeg's choice of threads. Per writer and size:
// encode ms per frame (median, mean; the conversion to the encoder's pixel format included,
// decoding and scaling the input not), file size, and the frames OpenCV decodes back. Then reading
// the video again by frame index (video::FrameReader, what the overlay does for files) against
// reading it once in order (video::VideoSource), ms per frame. Prints Markdown tables.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "cli_args.hpp"
#include "video/frame_reader.hpp"
#include "video/mp4_writer.hpp"
#include "video/video_source.hpp"

namespace mocap::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

double mean(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

cv::Mat as_mat(const ImageBuffer& image) {
  return cv::Mat(image.height(), image.width(), CV_8UC3, const_cast<std::byte*>(image.data()),
                 image.stride());
}

ImageBuffer wrap(cv::Mat mat) {
  auto owner = std::make_shared<cv::Mat>(std::move(mat));
  const auto* bytes = reinterpret_cast<const std::byte*>(owner->data);
  const int w = owner->cols, h = owner->rows, stride = static_cast<int>(owner->step[0]);
  return ImageBuffer(w, h, stride, PixelFormat::bgr8, std::move(owner), bytes);
}

// A writer under test: opened for a size, given frames, closed.
struct Writer {
  std::string name;
  std::function<void(const std::string&, cv::Size, double)> open;
  std::function<void(const ImageBuffer&)> write;
  std::function<void()> close;
};

std::vector<Writer> writers() {
  std::vector<Writer> out;
  auto opencv = std::make_shared<cv::VideoWriter>();
  out.push_back({"cv::VideoWriter mp4v (index at the end)",
                 [opencv](const std::string& path, cv::Size size, double fps) {
                   opencv->open(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'),
                                fps, size, true);
                   if (!opencv->isOpened()) throw std::runtime_error("cannot write " + path);
                 },
                 [opencv](const ImageBuffer& frame) { opencv->write(as_mat(frame)); },
                 [opencv] { opencv->release(); }});
  struct Variant {
    std::string name;
    video::Mp4Codec codec;
    int threads;
    std::string preset;
  };
  std::vector<Variant> variants = {{"Mp4Writer MPEG-4, 1 thread", video::Mp4Codec::mpeg4, 1, ""}};
  if (video::h264_available()) {
    for (const char* preset : {"ultrafast", "superfast", "veryfast"})
      variants.push_back({std::string("Mp4Writer H.264 ") + preset + ", 1 thread",
                          video::Mp4Codec::h264, 1, preset});
    variants.push_back(
        {"Mp4Writer H.264 veryfast, FFmpeg's threads", video::Mp4Codec::h264, 0, "veryfast"});
  }
  for (const Variant& v : variants) {
    auto writer = std::make_shared<std::unique_ptr<video::Mp4Writer>>();
    out.push_back({v.name,
                   [writer, v](const std::string& path, cv::Size size, double fps) {
                     video::Mp4WriterOptions options;
                     options.fps = fps;
                     options.codec = v.codec;
                     options.threads = v.threads;
                     if (!v.preset.empty()) options.h264_preset = v.preset;
                     *writer =
                         std::make_unique<video::Mp4Writer>(path, size.width, size.height, options);
                   },
                   [writer](const ImageBuffer& frame) { (*writer)->write(frame); },
                   [writer] {
                     (*writer)->close();
                     writer->reset();
                   }});
  }
  return out;
}

int decode_count(const std::string& path) {
  cv::VideoCapture video(path, cv::CAP_FFMPEG);
  int frames = 0;
  for (cv::Mat frame; video.grab(); ++frames) {
  }
  return frames;
}

void encode_table(const std::string& input, int frames, const std::vector<cv::Size>& sizes,
                  const fs::path& dir) {
  std::cout << "\n## Encoding " << frames << " frames of " << input << "\n\n"
            << "| writer | size | encode ms/frame (median) | mean | file KiB | KiB/frame | frames "
               "decoded back |\n|---|---|---:|---:|---:|---:|---:|\n";
  for (const cv::Size size : sizes) {
    for (Writer& writer : writers()) {
      video::VideoSource source(input);
      const double fps = source.fps() > 0 ? source.fps() : 25.0;
      const std::string path = (dir / ("bench_" + std::to_string(size.width) + "x" +
                                       std::to_string(size.height) + ".mp4"))
                                   .string();
      writer.open(path, size, fps);
      std::vector<double> ms;
      for (int k = 0; k < frames; ++k) {
        auto frame = source.read();
        if (!frame) break;
        cv::Mat scaled;
        cv::resize(as_mat(frame->image), scaled, size, 0, 0, cv::INTER_AREA);
        const ImageBuffer picture = wrap(std::move(scaled));
        const auto start = Clock::now();
        writer.write(picture);
        ms.push_back(ms_since(start));
      }
      const auto start = Clock::now();
      writer.close();
      const double close_ms = ms_since(start);
      ms.back() += close_ms;  // what the encoder held back is paid at the end
      const double kib = static_cast<double>(fs::file_size(path)) / 1024.0;
      char line[256];
      std::snprintf(line, sizeof line, "| %s | %dx%d | %.2f | %.2f | %.0f | %.1f | %d |\n",
                    writer.name.c_str(), size.width, size.height, median(ms), mean(ms), kib,
                    kib / static_cast<double>(ms.size()), decode_count(path));
      std::cout << line << std::flush;
      fs::remove(path);
    }
  }
}

// Reading again by index, as the overlay does: in order (every index once), and in the overlay's
// pattern under a windowed fit (the same frames, each asked for once, in order, after the
// source has read them all: identical to in order for the reader).
void read_table(const std::string& input, int frames) {
  std::cout << "\n## Reading " << input << " again\n\n"
            << "| reader | frames | ms/frame (median) | mean |\n|---|---:|---:|---:|\n";
  auto row = [](const char* name, const std::vector<double>& ms) {
    char line[160];
    std::snprintf(line, sizeof line, "| %s | %zu | %.2f | %.2f |\n", name, ms.size(), median(ms),
                  mean(ms));
    std::cout << line << std::flush;
  };
  {
    video::VideoSource source(input);
    std::vector<double> ms;
    for (int k = 0; k < frames; ++k) {
      const auto start = Clock::now();
      if (!source.read()) break;
      ms.push_back(ms_since(start));
    }
    row("VideoSource::read, in order (the source node)", ms);
  }
  {
    video::FrameReader reader(input);
    std::vector<double> ms;
    for (int k = 0; k < frames; ++k) {
      const auto start = Clock::now();
      if (!reader.frame(k)) break;
      ms.push_back(ms_since(start));
    }
    row("FrameReader::frame(k), k = 0, 1, 2, ...", ms);
  }
  {
    video::FrameReader reader(input);
    std::vector<double> ms;
    for (int k = 0; k < frames; k += 2) {
      const auto start = Clock::now();
      if (!reader.frame(k)) break;
      ms.push_back(ms_since(start));
    }
    row("FrameReader::frame(k), every other k (one passed over)", ms);
  }
}

}  // namespace
}  // namespace mocap::bench

int main(int argc, char** argv) {
  using namespace mocap;
  cli::Args args("mocap-bench-overlay [options]",
                 "What the overlay's MP4 costs per writer and size, and reading a video again by "
                 "frame index (Markdown tables).");
  args.option("video", "FILE", "input video", "../shared/data/eval/opencv_samples/vtest_part0.avi")
      .option("frames", "N", "frames to write per writer and size", "200")
      .option("sizes", "WxH,...", "picture sizes", "768x576,1280x720")
      .option("dir", "DIR", "where the test files go (removed after)", "/tmp");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  std::vector<cv::Size> sizes;
  std::string list = args.get("sizes");
  for (std::size_t start = 0; start < list.size();) {
    const std::size_t end = std::min(list.find(',', start), list.size());
    const std::string item = list.substr(start, end - start);
    const std::size_t x = item.find('x');
    if (x == std::string::npos) {
      std::cerr << "--sizes: expected WxH, got '" << item << "'\n";
      return 2;
    }
    sizes.emplace_back(std::stoi(item.substr(0, x)), std::stoi(item.substr(x + 1)));
    start = end + 1;
  }
  try {
    const int frames = std::stoi(args.get("frames"));
    bench::encode_table(args.get("video"), frames, sizes, args.get("dir"));
    bench::read_table(args.get("video"), frames);
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-overlay: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
