// mocap-bench-movenet: MoveNet MultiPose latency by input size and thread count on one real
// frame: network forward (cv::dnn or XNNPACK), decoding, and the input preparation, as medians and
// minima over timed runs after warm-up. Prints a Markdown table. (mocap-bench-networks compares the
// runtimes on every network.)

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_args.hpp"
#include "detect/model_files.hpp"
#include "detect/movenet_detector.hpp"

namespace {

using namespace mocap;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Timing {
  std::vector<double> prepare, forward, decode;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double minimum(const std::vector<double>& v) {
  return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end());
}

Timing time_size(detect::MovenetNetwork& net, const ImageBuffer& frame, int size, int warmup,
                 int runs) {
  Timing t;
  for (int i = 0; i < warmup + runs; ++i) {
    auto start = Clock::now();
    const detect::MovenetInput input = detect::prepare_movenet_input(frame, size);
    const double prepare = ms_since(start);
    start = Clock::now();
    const detect::MovenetHeads heads = net.run(input.tensor);
    const double forward = ms_since(start);
    start = Clock::now();
    [[maybe_unused]] const auto rows = detect::decode_movenet(heads);
    const double decode = ms_since(start);
    if (i < warmup) continue;
    t.prepare.push_back(prepare);
    t.forward.push_back(forward);
    t.decode.push_back(decode);
  }
  return t;
}

std::vector<int> int_list(const std::string& text) {
  std::vector<int> values;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) values.push_back(std::stoi(item));
  return values;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-movenet [options]",
                 "MoveNet MultiPose latency by input size and thread count");
  args.option("image", "PNG", "frame to detect on",
              "../shared/docs/models/movenet-multipose/vtest-f300.png")
      .option("sizes", "LIST", "input long sides, multiples of 32", "192,256,384,512")
      .option("threads", "LIST", "network threads", "1,2")
      .option("backend", "NAME", "network runtime: auto, xnnpack, opencv", "auto")
      .option("warmup", "N", "untimed runs per size", "3")
      .option("runs", "N", "timed runs per size", "30");
  int exit_code = 0;
  if (!args.parse(argc - 1, argv + 1, exit_code)) return exit_code;
  try {
    const cv::Mat bgr = cv::imread(args.get("image"));
    if (bgr.empty()) throw std::runtime_error("cannot read " + args.get("image"));
    auto owner = std::make_shared<cv::Mat>(bgr);
    const ImageBuffer frame(bgr.cols, bgr.rows, static_cast<int>(bgr.step[0]), PixelFormat::bgr8,
                            owner, reinterpret_cast<const std::byte*>(owner->data));
    const detect::Backend backend =
        detect::resolve_backend(detect::parse_backend(args.get("backend")));
    std::printf("runtime %s; frame %dx%d\n\n", std::string(detect::backend_name(backend)).c_str(),
                frame.width(), frame.height());
    std::printf(
        "| input (WxH) | threads | forward median | forward min | decode median | prepare median "
        "|\n");
    std::printf("|---|---|---|---|---|---|\n");
    for (const int threads : int_list(args.get("threads"))) {
      detect::RunnerOptions options;
      options.backend = backend;
      options.threads = threads;
      auto start = Clock::now();
      detect::MovenetNetwork net(detect::movenet_model_json(), options);
      std::fprintf(stderr, "model load with %d thread(s): %.0f ms\n", threads, ms_since(start));
      for (const int size : int_list(args.get("sizes"))) {
        const auto input = detect::prepare_movenet_input(frame, size);
        const Timing t = time_size(net, frame, size, static_cast<int>(args.integer("warmup")),
                                   static_cast<int>(args.integer("runs")));
        std::printf("| %dx%d | %d | %.1f ms | %.1f ms | %.2f ms | %.2f ms |\n",
                    input.tensor.width(), input.tensor.height(), threads, median(t.forward),
                    minimum(t.forward), median(t.decode), median(t.prepare));
        std::fflush(stdout);
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-movenet: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
