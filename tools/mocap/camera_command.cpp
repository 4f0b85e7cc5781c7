// `mocap camera list|grab`: the GigE Vision / USB3 Vision cameras Aravis sees, and a quick grab
// to files: PNG (OpenCV's imwrite, the default) or PGM/PPM (grey/colour, written directly).

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"

namespace mocap::cli {
namespace {

int list(int argc, char** argv) {
  Args args("mocap camera list", "Lists every camera Aravis finds (GigE Vision, USB3 Vision).");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const auto devices = aravis::list_devices();
  if (devices.empty()) {
    std::cout << "no cameras found\n";
    return 0;
  }
  std::cout << std::left << std::setw(32) << "id" << std::setw(16) << "vendor" << std::setw(20)
            << "model" << std::setw(16) << "serial" << std::setw(18) << "address"
            << "protocol\n";
  for (const auto& d : devices) {
    std::cout << std::setw(32) << d.id << std::setw(16) << d.vendor << std::setw(20) << d.model
              << std::setw(16) << d.serial << std::setw(18) << d.address << d.protocol << "\n";
  }
  return 0;
}

// P5 (grey) or P6 (RGB; BGR is swapped on the way out).
void write_netpbm(const ImageBuffer& image, const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary);
  const bool grey = image.format() == PixelFormat::gray8;
  out << (grey ? "P5" : "P6") << "\n" << image.width() << " " << image.height() << "\n255\n";
  const int channels = grey ? 1 : 3;
  std::vector<char> row(static_cast<std::size_t>(image.width() * channels));
  for (int y = 0; y < image.height(); ++y) {
    const std::byte* src = image.data() + static_cast<std::size_t>(y) * image.stride();
    std::memcpy(row.data(), src, row.size());
    if (image.format() == PixelFormat::bgr8) {
      for (std::size_t x = 0; x < row.size(); x += 3) std::swap(row[x], row[x + 2]);
    }
    out.write(row.data(), static_cast<std::streamsize>(row.size()));
  }
  if (!out.flush()) throw std::runtime_error("cannot write " + path.string());
}

// PNG through OpenCV: grey as 8-bit grey, colour as RGB (OpenCV wants BGR in memory).
void write_png(const ImageBuffer& image, const std::filesystem::path& path) {
  const bool grey = image.format() == PixelFormat::gray8;
  const cv::Mat view(image.height(), image.width(), grey ? CV_8UC1 : CV_8UC3,
                     const_cast<std::byte*>(image.data()),
                     static_cast<std::size_t>(image.stride()));
  cv::Mat bgr;
  if (image.format() == PixelFormat::rgb8) cv::cvtColor(view, bgr, cv::COLOR_RGB2BGR);
  if (!cv::imwrite(path.string(), bgr.empty() ? view : bgr))
    throw std::runtime_error("cannot write " + path.string());
}

aravis::CameraSettings settings_from(const Args& args) {
  aravis::CameraSettings s;
  s.id = args.get("id");
  s.frame_rate = args.number("fps");
  s.exposure_us = args.number("exposure-us");
  if (args.has("gain")) s.gain = args.number("gain");
  s.pixel_format = args.get("pixel-format");
  const long width = args.integer("width"), height = args.integer("height");
  if (width > 0 && height > 0) {
    s.region =
        aravis::Region{static_cast<int>(args.integer("x")), static_cast<int>(args.integer("y")),
                       static_cast<int>(width), static_cast<int>(height)};
  }
  s.buffers = static_cast<int>(args.integer("buffers"));
  return s;
}

void print_summary(const aravis::Camera& camera, long frames, std::int64_t first_ns,
                   std::int64_t last_ns, double wall_s) {
  const auto c = camera.counters();
  const double span_s = static_cast<double>(last_ns - first_ns) * 1e-9;
  std::cout << "grabbed " << frames << " frames in " << std::fixed << std::setprecision(2) << wall_s
            << " s: " << (frames > 1 && span_s > 0 ? (frames - 1) / span_s : 0.0)
            << " fps (capture times), " << frames / wall_s << " fps (wall clock, with start-up)\n"
            << "drops: " << c.incomplete << " incomplete, " << c.skipped_ids << " lost, "
            << c.underruns << " without a buffer\n";
}

int grab(int argc, char** argv) {
  Args args("mocap camera grab --frames N --out DIR [--id ID] [options]",
            "Grabs N frames from a camera into DIR as PNG (or PGM/PPM) files and prints the "
            "achieved frame rate and the drops. Formats of more than 8 bits are saved as their "
            "top 8 bits.");
  args.option("id", "ID", "camera id, serial or address (default: the first found)", "")
      .option("frames", "N", "frames to save", "10")
      .option("out", "DIR", "folder for frame_000000.png ...")
      .option("format", "png|pnm", "png, or pnm: PGM for grey, PPM for colour", "png")
      .option("fps", "F", "frame rate (0: the camera's)", "0")
      .option("x", "N", "region left", "0")
      .option("y", "N", "region top", "0")
      .option("width", "N", "region width (0: the camera's)", "0")
      .option("height", "N", "region height (0: the camera's)", "0")
      .option("exposure-us", "US", "exposure time (0: the camera's)", "0")
      .option("gain", "G", "gain (default: the camera's)")
      .option("pixel-format", "NAME", "Mono8, BayerRG8, RGB8, ... (default: the camera's)", "")
      .option("buffers", "N", "stream buffers (0: half a second of frames)", "0")
      .option("timeout-ms", "MS", "give up when no frame arrives for this long", "5000");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("out")) throw InputError("--out", "a folder for the frames is required");
  const long frames = args.integer("frames");
  if (frames < 1) throw InputError("--frames", "expected at least 1");
  const std::filesystem::path out = args.get("out");
  std::filesystem::create_directories(out);
  const auto timeout = std::chrono::milliseconds(args.integer("timeout-ms"));
  const std::string format = args.get("format");
  if (format != "png" && format != "pnm") throw InputError("--format", "expected png or pnm");

  aravis::Camera camera(settings_from(args));
  const auto region = camera.region();
  std::cerr << "camera '" << camera.info().id << "': " << region.width << "x" << region.height
            << " " << camera.pixel_format() << " at " << camera.frame_rate() << " fps, "
            << camera.buffer_count() << " buffers\n";
  const auto start = std::chrono::steady_clock::now();
  std::int64_t first_ns = 0, last_ns = 0;
  for (long i = 0; i < frames; ++i) {
    const auto frame = camera.next(timeout);
    if (!frame) {
      throw std::runtime_error("camera '" + camera.info().id + "': no frame for " +
                               std::to_string(timeout.count()) + " ms after " + std::to_string(i) +
                               " frames" + (camera.control_lost() ? " (control lost)" : ""));
    }
    if (i == 0) first_ns = frame->capture_ns;
    last_ns = frame->capture_ns;
    char name[32];
    const char* extension = format == "png"                               ? "png"
                            : frame->image.format() == PixelFormat::gray8 ? "pgm"
                                                                          : "ppm";
    std::snprintf(name, sizeof name, "frame_%06ld.%s", i, extension);
    if (format == "png") {
      write_png(frame->image, out / name);
    } else {
      write_netpbm(frame->image, out / name);
    }
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  print_summary(camera, frames, first_ns, last_ns, wall_s);
  return 0;
}

}  // namespace

int camera_command(int argc, char** argv) {
  static constexpr Subcommand kSubcommands[] = {
      {"list", "every camera Aravis finds: vendor, model, serial, address", list},
      {"grab", "save N frames of a camera and print the achieved rate and drops", grab},
  };
  return run_subcommand("camera", kSubcommands, argc, argv);
}

}  // namespace mocap::cli
