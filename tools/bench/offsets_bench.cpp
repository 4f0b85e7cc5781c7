// mocap-bench-offsets: frame offsets of a calibrated rig's views (camera/frame_offsets.hpp) on
// Pose2Sim's demo (4 synchronised views of the balancing trial, its calibration): each of cam02,
// cam03 and cam04 shifted by -10..10 frames against cam01 (frames cut from the start of one view
// or the other), the offset estimated against the truth. The demo is only evaluated here: no
// parameter of the method was chosen on it.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "camera/frame_offsets.hpp"
#include "camera/rig_file.hpp"
#include "cli_args.hpp"
#include "io/openpose_json.hpp"

namespace fs = std::filesystem;
using namespace mocap;

namespace {

// `view` as if it started `shift` frames after the reference (shift < 0: the reference started
// later, so the reference loses its first frames instead).
std::vector<camera::BodySequence> shifted(const std::vector<camera::BodySequence>& views,
                                          std::size_t view, int shift) {
  std::vector<camera::BodySequence> out = views;
  auto& cut = shift >= 0 ? out[view] : out[0];
  cut.erase(cut.begin(), cut.begin() + std::abs(shift));
  if (shift < 0) {  // the reference lost frames: every other view keeps its frames, but only
    for (std::size_t v = 1; v < out.size(); ++v)  // `view` is compared; the others stay aligned
      if (v != view) out[v].erase(out[v].begin(), out[v].begin() + std::abs(shift));
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-offsets [options]",
                 "Frame offsets estimated on Pose2Sim's demo views shifted against cam01.");
  args.option("demo", "DIR", "Pose2Sim's demo", "../shared/data/eval/pose2sim_demo")
      .option("max", "N", "largest shift (frames)", "10");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  const fs::path demo = args.get("demo");
  if (!fs::exists(demo / "calibration" / "Calib_qualisys.toml")) {
    std::cerr << "mocap-bench-offsets: " << demo << " not found\n";
    return 1;
  }
  const camera::Rig rig = camera::read_rig(demo / "calibration" / "Calib_qualisys.toml");
  io::OpenPoseOptions json;
  json.body25 = io::Body25Choice::body25b;
  std::vector<camera::BodySequence> views;
  for (const char* c : {"cam01", "cam02", "cam03", "cam04"}) {
    const auto folder = demo / "S00_P00_T01_BalancingTrial" / "pose" / (std::string(c) + "_json");
    views.push_back(camera::body_sequence(io::read_openpose_folder(folder, json).frames));
  }
  camera::OffsetOptions options;
  options.max_offset_frames = 15;
  const int max = static_cast<int>(args.integer("max"));
  std::cout << "| view | true shift | estimated | error | contrast | found "
               "|\n|---|---|---|---|---|---|\n";
  for (std::size_t v = 1; v < views.size(); ++v) {
    double sum = 0;
    int count = 0, found = 0;
    for (int shift = -max; shift <= max; ++shift) {
      const auto offset =
          camera::estimate_offsets(rig.cameras, shifted(views, v, shift), 0, options)[v];
      char row[200];
      std::snprintf(row, sizeof row, "| cam0%zu | %+d | %+.2f | %.2f | %.2f | %s |\n", v + 1, shift,
                    offset.frames, std::abs(offset.frames - shift), offset.contrast,
                    offset.found ? "yes" : offset.problem.c_str());
      std::cout << row;
      sum += std::abs(offset.frames - shift);
      ++count;
      found += offset.found ? 1 : 0;
    }
    std::printf("| cam0%zu | all | | mean %.2f | | %d of %d |\n", v + 1, sum / count, found, count);
  }
  return 0;
}
