// mocap-bench-offsets: frame offsets of a calibrated rig's views (camera/frame_offsets.hpp)
// against the truth (issue 20's report "Offsets"):
//  * Pose2Sim's demo (4 synchronised views of the balancing trial, its calibration): each of
//    cam02, cam03 and cam04 shifted by -10..10 frames and by fractions of a frame against cam01
//    (frames cut from the start of one view or the other; fractions by interpolating the view's
//    keypoints between its frames);
//  * the virtual scenes of CMU *held-out* clips (eval/offset_scene.hpp): one person seen by a
//    ring of 4 cameras, detector-like 2D (σ 2 % of the box height, 10 % of the joints dropped,
//    5 % outliers), view 2 starting -10..10 frames and fractions after view 1.
// Both are only evaluated here: no parameter of the method was chosen on them.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <algorithm>
#include <cmath>

#include "camera/frame_offsets.hpp"
#include "camera/rig_file.hpp"
#include "cli_args.hpp"
#include "eval/multiview_protocol.hpp"
#include "eval/offset_scene.hpp"
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

// The view as if its frame i showed its own instant i + fraction: each person's joints moved
// that far toward the nearest person of the next frame (confidence: the lower of the two).
camera::BodySequence interpolated(const camera::BodySequence& view, double fraction) {
  if (fraction == 0.0 || view.size() < 2) return view;
  camera::BodySequence out(view.size() - 1);
  const auto f = static_cast<float>(fraction);
  for (std::size_t i = 0; i + 1 < view.size(); ++i) {
    for (const camera::BodyKeypoints& a : view[i]) {
      const camera::BodyKeypoints* nearest = nullptr;
      float best = 1e30f;
      for (const camera::BodyKeypoints& b : view[i + 1]) {
        float d = 0.0f;
        for (int k = 0; k < kBodyJoints; ++k) d += std::hypot(a[k].x - b[k].x, a[k].y - b[k].y);
        if (d < best) best = d, nearest = &b;
      }
      if (!nearest) continue;
      camera::BodyKeypoints& p = out[i].emplace_back();
      for (int k = 0; k < kBodyJoints; ++k) {
        const Keypoint2D& b = (*nearest)[k];
        p[k] = {a[k].x + f * (b.x - a[k].x), a[k].y + f * (b.y - a[k].y),
                std::min(a[k].confidence, b.confidence)};
      }
    }
  }
  return out;
}

// `view` shifted by `shift` frames, whole and fraction, against the reference (view 0).
std::vector<camera::BodySequence> shifted_by(std::vector<camera::BodySequence> views,
                                             std::size_t view, double shift) {
  const double whole = std::floor(shift);
  views[view] = interpolated(views[view], shift - whole);
  return shifted(views, view, static_cast<int>(whole));
}

// The shifts tried: every whole frame in [-max, max] and some fractions.
std::vector<double> shifts(int max) {
  std::vector<double> out;
  for (int s = -max; s <= max; ++s) out.push_back(s);
  for (double f : {-7.5, -2.25, -0.5, 0.25, 0.5, 0.75, 3.5, 6.25}) out.push_back(f);
  return out;
}

struct Tally {
  double sum = 0.0, whole = 0.0, fraction = 0.0;
  int count = 0, wholes = 0, found = 0;
  std::vector<double> errors;
  void add(double truth, const camera::ViewOffset& o) {
    const double e = std::abs(o.frames - truth);
    if (o.found) {
      ++found;
      errors.push_back(e);
      (truth == std::floor(truth) ? whole : fraction) += e;
      wholes += truth == std::floor(truth) ? 1 : 0;
    }
    ++count;
  }
  std::string summary() const {
    std::vector<double> e = errors;
    std::sort(e.begin(), e.end());
    const int fractions = found - wholes;
    char row[200];
    std::snprintf(row, sizeof row,
                  "median error %.2f, mean whole %.2f, mean fraction %.2f | %d of %d",
                  e.empty() ? NAN : e[e.size() / 2], wholes ? whole / wholes : NAN,
                  fractions ? fraction / fractions : NAN, found, count);
    return row;
  }
};

int demo_table(const fs::path& demo, int max) {
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
  std::cout << "## Pose2Sim's demo, balancing trial: view shifted against cam01\n\n"
               "| view | true shift | estimated | error | contrast | found |\n"
               "|---|---|---|---|---|---|\n";
  for (std::size_t v = 1; v < views.size(); ++v) {
    Tally tally;
    for (const double shift : shifts(max)) {
      const auto offset =
          camera::estimate_offsets(rig.cameras, shifted_by(views, v, shift), 0, options)[v];
      char row[200];
      std::snprintf(row, sizeof row, "| cam0%zu | %+.2f | %+.2f | %.2f | %.2f | %s |\n", v + 1,
                    shift, offset.frames, std::abs(offset.frames - shift), offset.contrast,
                    offset.found ? "yes" : offset.problem.c_str());
      std::cout << row;
      tally.add(shift, offset);
    }
    std::cout << "| cam0" << v + 1 << " | all | | " << tally.summary() << " |\n";
  }
  return 0;
}

int virtual_table(const std::string& cmu, int clips, int max) {
  const int steps = 4;  // quarter frames
  const auto truth = eval::load_heldout_clips(cmu, 30.0 * steps);
  eval::SceneDegradation degradation;
  degradation.noise = 0.02f;
  degradation.dropout = 0.10f;
  degradation.outliers = 0.05f;
  degradation.occlusion = false;
  const auto ring = eval::ring_rig(4, 5.0, 1.6, 0.5, {0.0, 1.0, 0.0}, {});
  std::cout << "\n## Virtual scenes, CMU held-out clips, 4 cameras, σ 2 %, 10 % dropped, 5 % "
               "outliers, 150 frames: view 2 shifted against view 1\n\n"
               "| clip | shifts | result |\n|---|---|---|\n";
  Tally all;
  for (int c = 0; c < clips && c < static_cast<int>(truth.size()); ++c) {
    eval::ScenePerson person;
    person.motion = &truth[static_cast<std::size_t>(c)];
    Tally tally;
    for (const double shift : shifts(max)) {
      const int whole = static_cast<int>(std::floor(shift));
      const int quarter = static_cast<int>(std::lround((shift - whole) * steps));
      const int base = max + 1;
      const auto s =
          eval::shifted_views(person, ring, {base, base + whole, base, base}, {0, quarter, 0, 0},
                              steps, 150, degradation, static_cast<std::uint64_t>(11 + c));
      const auto offset = camera::estimate_offsets(s.cameras, s.views, 0)[1];
      tally.add(shift, offset);
      all.add(shift, offset);
    }
    std::cout << "| " << person.motion->clip << " | " << tally.count << " | " << tally.summary()
              << " |\n";
  }
  std::cout << "| all | " << all.count << " | " << all.summary() << " |\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args(
      "mocap-bench-offsets [options]",
      "Frame offsets estimated on Pose2Sim's demo views and on virtual views of CMU held-out\n"
      "clips, shifted by whole frames and fractions, against the truth.");
  args.option("demo", "DIR", "Pose2Sim's demo", "../shared/data/eval/pose2sim_demo")
      .option("max", "N", "largest shift (frames)", "10")
      .option("cmu", "DIR", "CMU clips with splits.txt (held-out ones are used)",
              "../shared/data/mocap/cmu31")
      .option("clips", "N", "held-out clips in the virtual table", "16");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  const fs::path demo = args.get("demo");
  if (!fs::exists(demo / "calibration" / "Calib_qualisys.toml")) {
    std::cerr << "mocap-bench-offsets: " << demo << " not found\n";
    return 1;
  }
  const int max = static_cast<int>(args.integer("max"));
  demo_table(demo, max);
  return virtual_table(args.get("cmu"), static_cast<int>(args.integer("clips")), max);
}
