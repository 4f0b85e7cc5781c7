// mocap-bench-view-check [SHARED_DATA]: what multiview::check_views (multiview/view_check.hpp)
// says of views as given, of views given in another order (two exchanged, or any permutation) and
// of one view's keypoints scaled (as if made at another image size), on
//  * Pose2Sim's demo (4 portrait cameras 1088x1920, balancing and static trials, its OpenPose
//    BODY_25B JSON): every pair exchanged, the orders 4 3 2 1, 2 1 4 3 and 2 3 1 4, every camera
//    scaled by 1/2, 2/3 and 3/4;
//  * HumanEva-I's Train chunks of 60 frames or more (3 cameras 640x480, ground-truth 2D through
//    the folder's fitted pinhole cameras), as given and with 3 px of Gaussian noise: false alarms
//    counted, and every pair exchanged and every camera scaled by 1/2.
// Markdown tables: per case the medians as given, what was said, the time. Only evaluated here:
// no threshold of check_views was chosen on these data (ViewCheckOptions, set beforehand).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "camera/rig_file.hpp"
#include "io/humaneva.hpp"
#include "io/openpose_json.hpp"
#include "multiview/view_check.hpp"
#include "multiview/view_order.hpp"

namespace fs = std::filesystem;
using namespace mocap;

namespace {

struct Views {
  std::vector<camera::Camera> cameras;
  std::vector<camera::BodySequence> views;
};

camera::BodySequence scaled(camera::BodySequence view, float factor) {
  for (auto& people : view)
    for (auto& person : people)
      for (Keypoint2D& k : person) {
        k.x *= factor;
        k.y *= factor;
      }
  return view;
}

// "4 3 2 1": the cameras whose views are given as views 1, 2, ...
std::string order_text(const std::vector<std::size_t>& camera_of_view) {
  std::string text;
  for (const std::size_t c : camera_of_view) {
    text += text.empty() ? "" : " ";  // not "" + to_string(): GCC 12's -Wrestrict false positive
    text += std::to_string(c + 1);
  }
  return text;
}

// What check_views said, in a few words: "order 1 3 2 4", "scaled 4 x2.00 (544x960)", "flagged 1
// unexplained", "another rig", "-".
std::string verdict(const multiview::ViewCheck& check) {
  std::string text;
  const auto add = [&](const std::string& part) { text += (text.empty() ? "" : "; ") + part; };
  if (check.reordered) add("order " + order_text(check.reordered->camera_of_view));
  for (const auto& s : check.scaled) {
    char line[96];
    std::snprintf(line, sizeof line, "scaled %zu x%.3f (%dx%d)", s.view + 1, s.factor,
                  s.image_width, s.image_height);
    add(line);
  }
  for (const std::size_t v : check.unexplained)
    add("flagged " + std::to_string(v + 1) + " unexplained");
  if (check.foreign_rig) add("another rig");
  return text.empty() ? "-" : text;
}

std::string medians(const multiview::ViewCheck& check) {
  std::string text;
  for (const auto& e : check.errors.views) {
    char value[32];
    std::snprintf(value, sizeof value, "%s%.1f%s", text.empty() ? "" : " ", e.median_px,
                  e.flagged ? "*" : "");
    text += value;
  }
  return text;
}

// The least of the cameras' median errors (explanations applied) as a fraction of the person's
// height in its image, in %: "another rig" is said when it exceeds foreign_rig_fraction.
double least_error_of_height(const multiview::ViewCheck& check) {
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < check.explained_errors.views.size(); ++v)
    if (check.explained_errors.views[v].points > 0)
      least = std::min(least,
                       100 * check.explained_errors.views[v].median_px / check.person_height_px[v]);
  return least;
}

struct Outcome {
  multiview::ViewCheck check;
  double ms = 0;
};

Outcome run(const Views& v) {
  const auto start = std::chrono::steady_clock::now();
  Outcome out{multiview::check_views(v.cameras, v.views), 0};
  out.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

// What a case expects: nothing explained (nor another rig), the views in the order `given`, or
// view a scaled by `factor` (within 5 %).
struct Expected {
  enum { nothing, order, scale, foreign } kind = nothing;
  std::size_t a = 0;
  double factor = 1;
  std::vector<std::size_t> given = {};

  bool met(const multiview::ViewCheck& c) const {
    switch (kind) {
      case nothing:
        return !c.explained() && !c.foreign_rig;
      case foreign:
        return c.foreign_rig;
      case order:
        return c.scaled.empty() && c.reordered && c.reordered->camera_of_view == given;
      case scale:
        return !c.reordered && c.scaled.size() == 1 && c.scaled[0].view == a &&
               std::abs(c.scaled[0].factor / factor - 1) < 0.05;
    }
    return false;
  }
};

struct Tally {
  int cases = 0, right = 0;
};

void row(const std::string& data, const std::string& alteration, const Expected& expected,
         const Outcome& o, Tally& tally) {
  const bool right = expected.met(o.check);
  ++tally.cases;
  tally.right += right;
  std::printf("| %s | %s | %s | %s | %.1f | %s | %.0f |\n", data.c_str(), alteration.c_str(),
              medians(o.check).c_str(), verdict(o.check).c_str(), least_error_of_height(o.check),
              right ? "yes" : "**no**", o.ms);
}

// `given` with its views in the order `order` (order[v]: the camera whose view is given as v).
void reordered(const std::string& data, const Views& given, const std::vector<std::size_t>& order,
               Tally& tally) {
  Views v = given;
  for (std::size_t i = 0; i < order.size(); ++i) v.views[i] = given.views[order[i]];
  row(data, "order " + order_text(order), {Expected::order, 0, 1, order}, run(v), tally);
}

// `given` against another rig: each camera turned about the world's vertical (z) through the
// origin by a further quarter turn (cam 1 by 90 degrees, cam 2 by 180, ...), as if another
// session's calibration were given.
void another_rig(const std::string& data, const Views& given, Tally& tally) {
  Views v = given;
  for (std::size_t c = 0; c < v.cameras.size(); ++c) {
    const double angle = 1.5707963 * static_cast<double>(c + 1);
    const glm::dmat3 turn(std::cos(angle), std::sin(angle), 0, -std::sin(angle), std::cos(angle), 0,
                          0, 0, 1);
    v.cameras[c].rotation = v.cameras[c].rotation * glm::transpose(turn);
  }
  row(data, "cameras turned (another rig)", {Expected::foreign}, run(v), tally);
}

// Every alteration of `given`: as given, each pair exchanged, the `orders`, another rig, each
// camera scaled by `factors`.
void alterations(const std::string& data, const Views& given,
                 const std::vector<std::vector<std::size_t>>& orders,
                 const std::vector<float>& factors, Tally& tally) {
  row(data, "as given", {}, run(given), tally);
  for (std::size_t a = 0; a < given.views.size(); ++a)
    for (std::size_t b = a + 1; b < given.views.size(); ++b) {
      std::vector<std::size_t> order(given.views.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::swap(order[a], order[b]);
      reordered(data, given, order, tally);
    }
  for (const std::vector<std::size_t>& order : orders) reordered(data, given, order, tally);
  another_rig(data, given, tally);
  for (std::size_t c = 0; c < given.views.size(); ++c)
    for (const float f : factors) {
      Views v = given;
      v.views[c] = scaled(v.views[c], f);
      char alteration[64];
      std::snprintf(alteration, sizeof alteration, "%zu made at x%.3f", c + 1, f);
      row(data, alteration, {Expected::scale, c, 1 / f}, run(v), tally);
    }
}

Views pose2sim(const fs::path& shared, const std::string& trial) {
  const fs::path demo = shared / "eval/pose2sim_demo";
  Views v;
  v.cameras = camera::read_rig(demo / "calibration/Calib_qualisys.toml").cameras;
  io::OpenPoseOptions options;
  options.body25 = io::Body25Choice::detect;
  for (int c = 1; c <= 4; ++c)
    v.views.push_back(camera::body_sequence(
        io::read_openpose_folder(demo / trial / "pose" / ("cam0" + std::to_string(c) + "_json"),
                                 options)
            .frames));
  return v;
}

// A HumanEva chunk's ground-truth 2D as body joints (HumanEva-15 -> Body15 is a choice of one
// joint per Body15 joint, so to_body15 maps the pixels given as (x, y, 0)), with `noise_px` of
// Gaussian noise.
Views humaneva(const io::humaneva::Chunk& chunk, const camera::Rig& rig, double noise_px,
               std::mt19937& random) {
  std::normal_distribution<float> noise(0.0f, static_cast<float>(noise_px));
  Views v;
  v.cameras = rig.cameras;
  for (int c = 0; c < io::humaneva::kCameras; ++c) {
    camera::BodySequence view;
    for (const io::humaneva::Pose2& pose : chunk.positions_2d[static_cast<std::size_t>(c)]) {
      io::humaneva::Pose3 flat;
      for (int j = 0; j < io::humaneva::kJoints; ++j)
        flat[static_cast<std::size_t>(j)] = {pose[static_cast<std::size_t>(j)], 0.0f};
      const auto body = io::humaneva::to_body15(flat);
      camera::BodyKeypoints person;
      for (int j = 0; j < kBodyJoints; ++j) {
        const glm::vec3& p = body[static_cast<std::size_t>(j)];
        person[static_cast<std::size_t>(j)] = {p.x + (noise_px > 0 ? noise(random) : 0.0f),
                                               p.y + (noise_px > 0 ? noise(random) : 0.0f), 1.0f};
      }
      view.push_back({person});
    }
    v.views.push_back(std::move(view));
  }
  return v;
}

// The time of the exhaustive order search at its limit, 8 cameras: the balancing trial's 4
// cameras twice (the twins with the same views: ties, only the time counts), the first four's
// views in the order 4 3 2 1.
void eight_cameras(const Views& demo) {
  Views v = demo;
  for (std::size_t c = 0; c < 4; ++c) {
    v.cameras.push_back(demo.cameras[c]);
    v.cameras.back().name += "_twin";
    v.views.push_back(demo.views[c]);
  }
  for (std::size_t c = 0; c < 4; ++c) v.views[c] = demo.views[3 - c];
  const auto start = std::chrono::steady_clock::now();
  const multiview::ViewOrder order = multiview::best_view_order(v.cameras, v.views, 0.3);
  const auto searched = std::chrono::steady_clock::now();
  const multiview::ViewCheck check = multiview::check_views(v.cameras, v.views);
  const auto checked = std::chrono::steady_clock::now();
  std::printf(
      "8 cameras (balancing trial twice, first four in the order 4 3 2 1): best_view_order %.0f "
      "ms (order %s), check_views %.0f ms (said: %s)\n",
      std::chrono::duration<double, std::milli>(searched - start).count(),
      order_text(order.camera_of_view).c_str(),
      std::chrono::duration<double, std::milli>(checked - searched).count(),
      verdict(check).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path shared = argc > 1 ? fs::path(argv[1]) : fs::path("../shared/data");
  std::printf(
      "| data | alteration | medians px as given (* flagged) | said | least error explained, "
      "%% of height | right | ms |\n|---|---|---|---|---:|---|---:|\n");
  Tally pose2sim_tally, humaneva_tally;
  for (const char* trial : {"S00_P00_T01_BalancingTrial", "S00_P00_T00_StaticTrial"})
    if (fs::exists(shared / "eval/pose2sim_demo" / trial))
      alterations(
          std::string("pose2sim ") +
              (std::string(trial).find("T01") != std::string::npos ? "balancing" : "static"),
          pose2sim(shared, trial), {{3, 2, 1, 0}, {1, 0, 3, 2}, {1, 2, 0, 3}},
          {0.5f, 2.0f / 3.0f, 0.75f}, pose2sim_tally);
  std::printf("\nPose2Sim's demo: %d of %d cases right\n\n", pose2sim_tally.right,
              pose2sim_tally.cases);
  if (fs::exists(shared / "eval/pose2sim_demo/S00_P00_T01_BalancingTrial"))
    eight_cameras(pose2sim(shared, "S00_P00_T01_BalancingTrial"));

  const fs::path he = shared / "eval/humaneva_i_videopose3d";
  if (!fs::exists(he / io::humaneva::kCamerasFile)) return 0;
  const io::humaneva::Dataset dataset = io::humaneva::load_dataset(he);
  const auto rigs = io::humaneva::load_cameras(he / io::humaneva::kCamerasFile);
  std::mt19937 random(11);
  int chunks = 0, false_alarms = 0, flagged = 0;
  double closest = 0;  // the highest least error of height (%) among them
  for (const io::humaneva::Chunk* chunk : dataset.select(io::humaneva::Split::train)) {
    if (chunk->frames() < 60) continue;
    for (const double noise : {0.0, 3.0}) {
      const Views v = humaneva(*chunk, rigs.at(chunk->subject), noise, random);
      const std::string data =
          "HumanEva Train/" + chunk->subject + " " + chunk->key + (noise > 0 ? " +3 px" : "");
      const Outcome given = run(v);
      ++chunks;
      false_alarms += given.check.explained() || given.check.foreign_rig;
      flagged += !given.check.unexplained.empty();
      closest = std::max(closest, least_error_of_height(given.check));
      // As given: shown when something is said; every chunk 0 with noise: all its alterations.
      if (chunk->key.ends_with("chunk0") && noise > 0)
        alterations(data, v, {{1, 2, 0}, {2, 0, 1}}, {0.5f}, humaneva_tally);
      else if (given.check.explained() || given.check.foreign_rig ||
               !given.check.unexplained.empty())
        row(data, "as given", {}, given, humaneva_tally);
    }
  }
  std::printf("\nHumanEva rows above: %d of %d right\n", humaneva_tally.right,
              humaneva_tally.cases);
  std::printf(
      "HumanEva Train, chunks of 60 frames or more, as given (0 and 3 px noise): %d "
      "checks, %d explained or said another rig (false alarms), %d with a flagged camera left "
      "unexplained; the least camera error at most %.1f %% of the person's height\n",
      chunks, false_alarms, flagged, closest);
  return 0;
}
