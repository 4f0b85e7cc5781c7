// mocap-bench-networks: the 2D networks' forward time per model, input size, runtime (cv::dnn,
// XNNPACK) and thread count, all configurations in one run, interleaved round by round so that
// the machine's load hits them alike. Input: a window of a real frame resized to the network's
// input. Prints a Markdown table of medians (and the first run, which builds the runtime).
// BlazePose's landmark models (the top-down crops) also run several crops per forward
// (--batches: detect.topdown's crops_per_pass), timed per crop in wall and in this thread's CPU
// time (which the other processes of a shared machine disturb less). The detection strategies
// built from these networks are measured by mocap-bench-detect.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_args.hpp"
#include "detect/graph_runner.hpp"
#include "detect/model_files.hpp"

namespace {

using namespace mocap;
using namespace mocap::detect;
using Clock = std::chrono::steady_clock;

// A network of the model package and the outputs a detector reads from it.
struct Network {
  std::string name;  // also the folder in the model cache
  std::vector<std::string> outputs;
  bool nchw = false;  // the placeholder is [1, 3, H, W]
  float scale = 1.0f;
};

const std::string kSp = "StatefulPartitionedCall/";
const std::vector<Network> kNetworks = {
    {"movenet-multipose",
     {kSp + "center_0/conv2d_4/BiasAdd", kSp + "box_scale_0/conv2d_5/BiasAdd",
      kSp + "box_offset_0/conv2d_6/BiasAdd", kSp + "kpt_heatmap_0/conv2d_7/BiasAdd",
      kSp + "kpt_regress_0/conv2d_8/BiasAdd", kSp + "kpt_offset_0/conv2d_9/BiasAdd"}},
    {"movenet-lightning",
     {kSp + "center_0/conv2d_4/BiasAdd", kSp + "kpt_heatmap_0/conv2d_5/BiasAdd",
      kSp + "kpt_regress_0/conv2d_6/BiasAdd", kSp + "kpt_offset_0/conv2d_7/BiasAdd"}},
    {"movenet-thunder",
     {kSp + "center_0/conv2d_4/BiasAdd", kSp + "kpt_heatmap_0/conv2d_5/BiasAdd",
      kSp + "kpt_regress_0/conv2d_6/BiasAdd", kSp + "kpt_offset_0/conv2d_7/BiasAdd"}},
    {"centernet", {"tower_0/Sigmoid", "tower_0/mul"}},
    // BlazePose's landmarks and pose flag, as detect::SinglePoseNetwork cuts it (RGB / 255).
    {"blazepose-lite",
     {kSp + "model/convld_3d/BiasAdd", kSp + "model/activation_poseflag/Sigmoid"},
     false,
     1.0f / 255},
    {"blazepose-full",
     {kSp + "model/convld_3d/BiasAdd", kSp + "model/activation_poseflag/Sigmoid"},
     false,
     1.0f / 255},
    {"blazepose-heavy",
     {kSp + "model/convld_3d/BiasAdd", kSp + "model/activation_poseflag/Sigmoid"},
     false,
     1.0f / 255},
    {"nanodet",
     {"Identity", "Identity_1", "Identity_2", "Identity_3", "Identity_4", "Identity_5"},
     true,
     1.0f / 255},
};

struct Config {
  std::string model, input;
  Backend backend = Backend::opencv;
  int threads = 1;
  int batch = 1;  // images per forward
  std::unique_ptr<GraphRunner> runner;
  std::vector<std::int64_t> shape;
  std::vector<float> values;
  double first_ms = 0;
  std::vector<double> times, cpu_times;  // per forward
};

// This thread's CPU time in ms.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// BlazePose's landmark models, which detect.topdown feeds in batches of crops and which take a
// batch at their placeholder (MoveNet single-pose takes one only after its batch-of-one
// reshuffles: detect::SinglePoseNetwork).
bool takes_batches(const std::string& model) { return model.starts_with("blazepose"); }

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

std::vector<std::string> list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) items.push_back(item);
  return items;
}

// The frame resized to width × height, RGB floats × scale, NHWC or NCHW.
std::vector<float> input_values(const cv::Mat& rgb, int width, int height, const Network& net) {
  cv::Mat resized;
  cv::resize(rgb, resized, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
  std::vector<float> out(static_cast<std::size_t>(width) * height * 3);
  const std::size_t plane = static_cast<std::size_t>(width) * height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) {
        const std::size_t pixel = static_cast<std::size_t>(y) * width + x;
        out[net.nchw ? c * plane + pixel : pixel * 3 + c] =
            static_cast<float>(resized.at<cv::Vec3b>(y, x)[c]) * net.scale;
      }
  return out;
}

// Input sizes (width × height) of one network: MultiPose takes any multiple of 32, the others
// their fixed size.
std::vector<std::pair<int, int>> sizes(const std::string& model, const std::string& multipose) {
  if (model == "movenet-lightning") return {{192, 192}};
  if (model == "movenet-thunder" || model.starts_with("blazepose")) return {{256, 256}};
  if (model == "centernet") return {{512, 512}};
  if (model == "nanodet") return {{416, 416}};
  std::vector<std::pair<int, int>> out;
  for (const auto& s : list(multipose)) out.emplace_back(std::stoi(s), std::stoi(s) * 3 / 4);
  return out;
}

void run_once(Config& c, std::vector<GraphTensor>& outputs) {
  if (c.backend == Backend::opencv) cv::setNumThreads(c.threads);  // process-wide
  c.runner->run({c.shape, c.values}, outputs);
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-networks [options]",
                 "forward time of the 2D networks per runtime and thread count");
  args.option("image", "PNG", "frame the inputs are resized from",
              "../shared/docs/models/movenet-multipose/vtest-f300.png")
      .option("models", "LIST", "models (folders of the model cache)",
              "movenet-multipose,movenet-lightning,movenet-thunder,centernet,nanodet,"
              "blazepose-lite,blazepose-full,blazepose-heavy")
      .option("multipose-sizes", "LIST", "MoveNet MultiPose input long sides (4:3)", "256,384,512")
      .option("backends", "LIST", "runtimes: opencv, xnnpack", "opencv,xnnpack")
      .option("threads", "LIST", "thread counts", "1,2")
      .option("rounds", "N", "rounds over all configurations", "6")
      .option("per-round", "N", "timed forwards per configuration and round", "5")
      .option("batches", "LIST",
              "crops per forward of BlazePose's landmark models (the others run one image)", "1");
  int exit_code = 0;
  if (!args.parse(argc - 1, argv + 1, exit_code)) return exit_code;
  try {
    cv::Mat rgb = cv::imread(args.get("image"));
    if (rgb.empty()) throw std::runtime_error("cannot read " + args.get("image"));
    cv::cvtColor(rgb, rgb, cv::COLOR_BGR2RGB);
    std::vector<Config> configs;
    for (const auto& model : list(args.get("models"))) {
      const auto net = std::find_if(kNetworks.begin(), kNetworks.end(),
                                    [&](const Network& n) { return n.name == model; });
      if (net == kNetworks.end()) throw std::runtime_error("unknown model " + model);
      const auto json = model_cache_dir() / model / (model + ".json");
      for (const auto& [w, h] : sizes(model, args.get("multipose-sizes"))) {
        for (const auto& backend : list(args.get("backends"))) {
          for (const auto& threads : list(args.get("threads")))
            for (const auto& batch :
                 takes_batches(model) ? list(args.get("batches")) : std::vector<std::string>{"1"}) {
              Config c;
              c.batch = std::stoi(batch);
              c.model = model;
              c.input = std::to_string(w) + "x" + std::to_string(h);
              c.backend = parse_backend(backend);
              c.threads = std::stoi(threads);
              RunnerOptions options;
              options.backend = c.backend;
              options.threads = c.threads;
              try {
                c.runner = make_graph_runner(json, net->outputs, options);
              } catch (const std::exception& e) {
                std::cerr << model << " " << backend << ": not run: " << e.what() << "\n";
                continue;
              }
              c.shape = net->nchw ? std::vector<std::int64_t>{1, 3, h, w}
                                  : std::vector<std::int64_t>{c.batch, h, w, 3};
              const std::vector<float> image = input_values(rgb, w, h, *net);
              for (int i = 0; i < c.batch; ++i)
                c.values.insert(c.values.end(), image.begin(), image.end());
              configs.push_back(std::move(c));
            }
        }
      }
    }
    double load[3] = {0, 0, 0};
    if (getloadavg(load, 3) > 0)
      std::printf("load average at start: %.2f %.2f %.2f\n", load[0], load[1], load[2]);
    std::vector<GraphTensor> outputs;
    for (Config& c : configs) {  // the first run builds the runtime (XNNPACK packs weights then)
      const auto start = Clock::now();
      run_once(c, outputs);
      c.first_ms = ms_since(start);
      run_once(c, outputs);  // warm-up
    }
    const long rounds = args.integer("rounds"), per_round = args.integer("per-round");
    for (long r = 0; r < rounds; ++r) {
      for (Config& c : configs) {
        for (long i = 0; i < per_round; ++i) {
          const auto start = Clock::now();
          const double cpu = thread_cpu_ms();
          run_once(c, outputs);
          c.cpu_times.push_back(thread_cpu_ms() - cpu);
          c.times.push_back(ms_since(start));
        }
      }
    }
    if (getloadavg(load, 3) > 0)
      std::printf("load average at end: %.2f %.2f %.2f\n", load[0], load[1], load[2]);
    std::printf("\n%ld rounds x %ld forwards per configuration, interleaved\n\n", rounds,
                per_round);
    std::printf(
        "| model | input (WxH) | runtime | threads | batch | median ms | p90 ms | min ms | first "
        "run ms | median ms per image | CPU ms per image (median) | cv::dnn / this (same "
        "threads and batch) |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const Config& c : configs) {
      const double median = percentile(c.times, 0.5);
      double ratio = 0;
      for (const Config& o : configs)
        if (o.model == c.model && o.input == c.input && o.threads == c.threads &&
            o.batch == c.batch && o.backend == Backend::opencv)
          ratio = percentile(o.times, 0.5) / median;
      std::printf("| %s | %s | %s | %d | %d | %.1f | %.1f | %.1f | %.0f | %.1f | %.1f | %s |\n",
                  c.model.c_str(), c.input.c_str(), std::string(backend_name(c.backend)).c_str(),
                  c.threads, c.batch, median, percentile(c.times, 0.9), percentile(c.times, 0.0),
                  c.first_ms, median / c.batch, percentile(c.cpu_times, 0.5) / c.batch,
                  ratio > 0 ? (std::to_string(ratio).substr(0, 4) + "x").c_str() : "-");
    }
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-networks: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
