// `mocap-bench-fit`: the skeleton fitting (components/fit) measured on the virtual protocol with
// known cameras. Held-out CMU clips are rendered through virtual cameras, reconstructed by the
// retrieval (path + Savitzky-Golay + ray + view, the offline "full" configuration) on a train
// database, then fitted in full-sequence mode (one solve, and in overlapping windows as recon.fit's
// full mode does) and in fixed-lag live mode, per clip length (--max-frames 120,0). Prints MPJPE,
// PA-MPJPE and acceleration error before and after fitting, root translation error, foot skating
// during (truth) contact, ground penetration, and the fitting's person-frames per CPU second
// (one thread) with its iterations.

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <tuple>

#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "eval/virtual_protocol.hpp"
#include "fit/fit_evaluation.hpp"
#include "fit/foot_contact.hpp"
#include "fit/skeleton_fit.hpp"
#include "fit/view_fit.hpp"
#include "posedb/builder.hpp"
#include "posedb/database.hpp"
#include "recon/matcher.hpp"
#include "recon/temporal_selector.hpp"

namespace {

using namespace mocap;

struct Row {
  eval::Scores pose;
  fit::PlacementScores placement;
  double seconds = 0, frames = 0;  // fitting CPU time (not retrieval)
  double solves = 0, iterations = 0, frame_iterations = 0;
  void add(const Row& o) {
    pose.add(o.pose);
    placement.add(o.placement);
    seconds += o.seconds;
    frames += o.frames;
    solves += o.solves;
    iterations += o.iterations;
    frame_iterations += o.frame_iterations;
  }
  void add(const fit::FitStats& s) {
    solves += s.solves;
    iterations += s.iterations;
    frame_iterations += s.frame_iterations;
  }
};

// CPU seconds of this process (the machine is shared: wall time would count other work).
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void print_row(const std::string& name, const std::string& length, const std::string& condition,
               const Row& r) {
  const auto& p = r.placement;
  std::cout << "| " << name << " | " << length << " | " << condition << " | " << std::fixed
            << std::setprecision(1) << r.pose.mpjpe() << " | " << r.pose.pa_mpjpe() << " | "
            << r.pose.accel() << " | " << p.root_error_mm() << " | " << std::setprecision(2)
            << p.skate_cm() << " | " << p.penetration_cm() << " | " << std::setprecision(1)
            << p.penetrating_percent() << " | ";
  if (r.seconds > 0)
    std::cout << std::setprecision(0) << r.frames / r.seconds;
  else
    std::cout << "-";
  std::cout << " | ";
  if (r.solves > 0)
    std::cout << std::setprecision(1) << r.iterations / r.solves << " | "
              << r.frame_iterations / r.frames;
  else
    std::cout << "- | -";
  std::cout << " |\n";
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    if (end > start) out.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

// A named weight of FitWeights that `--sweep NAME=V1,V2` may vary; nullptr when unknown.
double* sweep_weight(fit::FitWeights& w, const std::string& name) {
  if (name == "prior") return &w.prior_rad;
  if (name == "live-prior") return &w.live_prior_rad;
  if (name == "reprojection") return &w.reprojection;
  if (name == "bone-accel") return &w.bone_accel_m;
  if (name == "root-accel") return &w.root_accel_m;
  if (name == "translation-prior") return &w.translation_prior_m;
  if (name == "bone-prior") return &w.bone_prior_m;
  if (name == "symmetry") return &w.symmetry_m;
  if (name == "body-scale") return &w.body_scale;
  if (name == "knee-limit") return &w.knee_limit;
  if (name == "slide") return &w.slide_m;
  if (name == "ground") return &w.ground_m;
  if (name == "contact-ground") return &w.contact_ground_m;
  return nullptr;
}

struct Variant {
  std::string label;  // empty for the base options
  fit::FitOptions options;
};

// The base options, then one variant per `--sweep` value (every other weight at the base), then
// the `--variant` combinations (`NAME=V,NAME=V`, all changed together).
std::vector<Variant> make_variants(const fit::FitOptions& base,
                                   const std::vector<std::string>& sweeps,
                                   const std::vector<std::string>& combos) {
  std::vector<Variant> out{{"", base}};
  auto assign = [](fit::FitOptions& o, const std::string& name, const std::string& value) {
    double* w = sweep_weight(o.weights, name);
    if (w == nullptr) throw InputError("--sweep/--variant", "unknown weight '" + name + "'");
    try {
      *w = std::stod(value);
    } catch (const std::exception&) {
      throw InputError("--sweep/--variant", "not a number: '" + value + "'");
    }
  };
  for (const auto& s : sweeps) {
    const auto eq = s.find('=');
    if (eq == std::string::npos) throw InputError("--sweep", "expected NAME=V1,V2: '" + s + "'");
    const std::string name = s.substr(0, eq);
    for (const auto& v : split_commas(s.substr(eq + 1))) {
      Variant x{name + "=" + v, base};
      assign(x.options, name, v);
      out.push_back(std::move(x));
    }
  }
  for (const auto& c : combos) {
    Variant x{c, base};
    for (const auto& item : split_commas(c)) {
      const auto eq = item.find('=');
      if (eq == std::string::npos)
        throw InputError("--variant", "expected NAME=V,NAME=V: '" + c + "'");
      assign(x.options, item.substr(0, eq), item.substr(eq + 1));
    }
    out.push_back(std::move(x));
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-fit [options]",
                 "Skeleton fitting on the virtual protocol (held-out CMU clips, known cameras): "
                 "errors before and\nafter fitting and fitted person-frames per second on one "
                 "core.");
  args.option("db", "FILE", "pose database built from the train split", "build/db/cmu31_train.mdb")
      .option("mocap", "DIR", "cmu31 folder with splits.txt", "../shared/data/mocap/cmu31")
      .option("clips", "N", "evaluated clips used, the first N (0 = all)", "4")
      .option("eval-split", "NAME", "split of splits.txt whose clips are evaluated", "heldout")
      .option("eval-clips", "A,B", "only these clips of the split (names, e.g. 08_01,08_02)")
      .option("eval-files", "A.bvh,B.bvh", "evaluate these mocap files instead of a split")
      .option("max-frames", "N[,M]",
              "frames per clip at most (0 = all); a list gives the rows per clip length "
              "(120,0: the first 120 frames and the whole clips, each retrieved on its own)",
              "240")
      .option("windows", "N:M[,N:M]",
              "windowed full mode: frames solved together : frames of a window solved again in "
              "the next; a list gives a row each (same retrieval)",
              "64:16")
      .option("iterations", "N", "full modes: solver iterations per solve (window)", "30")
      .option("lag", "N", "live mode: frames of delay", "3")
      .option("live-iterations", "N", "live mode: solver iterations per frame", "8")
      .option("clearance", "M", "ankle height over the ground plane", "0.07")
      .flag("all-cameras", "all 20 protocol cameras (default: the quick set, 2 yaws x 4 families)")
      .flag("all-conditions",
            "the protocol's five conditions (noise 0, 1, 2, 5 %, 2 % with 10 % drop-out); "
            "default: 0 and 2 %")
      .flag("no-ground", "no ground-plane term")
      .flag("no-contact", "no foot-contact (no sliding) term")
      .flag("fixed-bones", "full mode: bone lengths fixed at the retrieved poses' medians")
      .option("prior", "RAD", "sigma of the prior to the retrieved bone directions", "0.15")
      .option("reprojection", "F", "reprojection sigma, fraction of the 2D height", "0.02")
      .option("bone-accel", "M", "sigma of bone-vector acceleration, m/frame²", "0.015")
      .option("root-accel", "M", "sigma of root acceleration, m/frame²", "0.01")
      .option("velocity", "M", "live lag 0: sigma of bone and root velocity, m/frame", "0.03")
      .option("translation-prior", "M", "sigma of the root from its closed-form start", "1.0")
      .option("bone-prior", "M", "full mode: sigma of a bone length from its initial value", "0.01")
      .option(
          "sweep", "NAME=V1,V2",
          "also fit with each value of one weight (the others as given; retrieval shared); "
          "names: prior live-prior reprojection bone-accel root-accel translation-prior bone-prior "
          "symmetry body-scale knee-limit slide ground contact-ground",
          std::nullopt, true)
      .option("variant", "NAME=V,NAME=V", "also fit with these weights changed together",
              std::nullopt, true);
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  try {
    const posedb::Database db = posedb::Database::open(args.get("db"));
    const double fps = db.build_info().fps;
    std::vector<std::string> files;
    if (args.has("eval-files")) {
      files = split_commas(args.get("eval-files"));
    } else {
      files = posedb::split_files(args.get("mocap"), args.get("eval-split"));
      if (args.has("eval-clips")) {
        const auto wanted = split_commas(args.get("eval-clips"));
        std::vector<std::string> kept;
        for (const auto& w : wanted) {
          const auto it = std::find_if(files.begin(), files.end(), [&](const std::string& f) {
            return std::filesystem::path(f).stem().string() == w;
          });
          if (it == files.end())
            throw InputError(args.get("mocap"),
                             "no clip " + w + " in split '" + args.get("eval-split") + "'");
          kept.push_back(*it);
        }
        files = kept;
      }
    }
    if (files.empty())
      throw InputError(args.get("mocap"),
                       "no clips to evaluate (split '" + args.get("eval-split") + "' is empty)");
    auto truth = eval::load_truth(files, fps);
    if (const long n = args.integer("clips"); n > 0 && static_cast<std::size_t>(n) < truth.size())
      truth.resize(n);
    std::vector<std::size_t> lengths;
    for (const auto& text : split_commas(args.get("max-frames"))) {
      char* end = nullptr;
      const long n = std::strtol(text.c_str(), &end, 10);
      if (end == text.c_str() || *end != '\0' || n < 0)
        throw InputError("--max-frames", "expected frame counts (0 = all), got '" + text + "'");
      lengths.push_back(static_cast<std::size_t>(n));
    }
    if (lengths.empty()) throw InputError("--max-frames", "no frame count given");
    const auto cameras = eval::default_cameras(!args.has("all-cameras"));
    const auto conditions = eval::default_conditions(!args.has("all-conditions"));
    const eval::Image image;
    const camera::Camera lens =
        camera::Camera::from_fov(image.width, image.height, image.horizontal_fov_deg);

    recon::Matcher matcher(db, {});
    const recon::FrameBones bones(db);
    const fit::ContactDetector detector(db);
    recon::SequenceOptions retrieval;
    retrieval.fps = fps;
    retrieval.selection = recon::Selection::path;
    retrieval.smoothing = recon::Smoothing::savitzky_golay;
    retrieval.camera = lens;
    retrieval.refine_view = true;

    fit::FitOptions options;
    options.camera = lens;  // each frame's moving camera places it in the clip's world
    options.ankle_clearance_m = args.number("clearance");
    if (!args.has("no-ground")) options.ground = GroundPlane{{0.0, 1.0, 0.0}, 0.0};
    options.lag = static_cast<int>(args.integer("lag"));
    options.live_iterations = static_cast<int>(args.integer("live-iterations"));
    options.max_iterations = static_cast<int>(args.integer("iterations"));
    std::vector<fit::WindowOptions> windows;
    for (const auto& text : split_commas(args.get("windows"))) {
      fit::WindowOptions w;
      char colon = 0;
      std::istringstream in(text);
      if (!(in >> w.frames >> colon >> w.overlap) || colon != ':' || !in.eof() || w.frames < 2 ||
          w.overlap < 1 || w.overlap >= w.frames)
        throw InputError("--windows",
                         "expected FRAMES:OVERLAP (overlap 1 .. frames - 1), got '" + text + "'");
      windows.push_back(w);
    }
    if (windows.empty()) throw InputError("--windows", "no window given");
    auto window_name = [](const fit::WindowOptions& w) {
      return "+ fit, full windowed " + std::to_string(w.frames) + ":" + std::to_string(w.overlap);
    };
    options.solve_bones = !args.has("fixed-bones");
    options.weights.prior_rad = args.number("prior");
    options.weights.reprojection = args.number("reprojection");
    options.weights.bone_accel_m = args.number("bone-accel");
    options.weights.root_accel_m = args.number("root-accel");
    options.weights.bone_prior_m = args.number("bone-prior");
    options.weights.translation_prior_m = args.number("translation-prior");
    options.weights.bone_velocity_m = options.weights.root_velocity_m = args.number("velocity");
    const bool use_contact = !args.has("no-contact");
    const auto variants = make_variants(options, args.all("sweep"), args.all("variant"));

    // truth, retrieval, one solve, the windows, live.
    std::vector<std::string> methods = {"truth", "retrieval only",
                                        "+ fit, full sequence (one solve)"};
    for (const auto& w : windows) methods.push_back(window_name(w));
    methods.push_back("+ fit, live");
    const std::string& live_method = methods.back();
    // Rows by (method [variant], clip length, condition).
    std::map<std::tuple<std::string, std::string, std::string>, Row> rows;
    std::vector<std::string> length_labels;
    std::cout << "## Skeleton fitting, virtual protocol\n\nclip floors (lowest ankle, m):";
    for (const auto& t : truth)
      std::cout << " " << t.clip << " " << std::setprecision(3) << fit::ankle_floor(t.world);
    std::cout << "\n\n";
    for (const std::size_t length : lengths) {
      const std::string len = length == 0 ? "whole" : "<=" + std::to_string(length);
      length_labels.push_back(len);
      std::vector<eval::TruthSequence> clips = truth;
      std::size_t frames = 0;
      for (auto& t : clips) {
        if (length > 0 && t.world.size() > length) t.world.resize(length);
        frames += t.world.size();
      }
      std::cerr << clips.size() << " clips (" << len << " frames), " << frames << " frames, "
                << cameras.size() << " cameras, " << conditions.size() << " conditions\n";
      for (std::size_t n = 0; n < conditions.size(); ++n) {
        const std::string cond = conditions[n].label();
        for (std::size_t k = 0; k < cameras.size(); ++k) {
          for (std::size_t s = 0; s < clips.size(); ++s) {
            const auto rendered = eval::render(clips[s], cameras[k], image, conditions[n],
                                               1000003ull * s + 1009ull * k + n);
            const auto& world = clips[s].world;
            const auto poses =
                recon::reconstruct_sequence(matcher, bones, rendered.input, retrieval);
            const auto cams = fit::moving_cameras(lens, world, rendered.truth_camera);
            const auto inputs = fit::make_inputs(
                rendered.input, poses,
                use_contact ? detector.contacts(poses) : std::vector<std::array<bool, 2>>{}, cams);
            const auto contacts = fit::truth_contacts(world, fps);
            const double floor = fit::ankle_floor(world);
            auto score = [&](const std::vector<fit::FittedFrame>& f, double start) {
              Row r;
              r.seconds = cpu_seconds() - start;
              r.frames = static_cast<double>(inputs.size());
              r.pose = eval::score(fit::as_poses(f), rendered.truth_camera);
              r.placement = fit::score_placement(f, rendered.truth_camera, cams, contacts, floor);
              return r;
            };
            // The truth itself (skating and penetration of the reference).
            std::vector<fit::FittedFrame> t(world.size());
            for (std::size_t i = 0; i < t.size(); ++i)
              t[i] = {true, true, rendered.truth_camera[i]};
            Row truth_row = score(t, cpu_seconds());
            truth_row.seconds = 0;
            rows[{methods[0], len, cond}].add(truth_row);
            Row retrieved;
            retrieved.pose = eval::score(poses, rendered.truth_camera);
            retrieved.placement = fit::score_placement(
                fit::placed_retrieval(inputs, lens), rendered.truth_camera, cams, contacts, floor);
            rows[{methods[1], len, cond}].add(retrieved);
            for (const auto& v : variants) {
              const std::string suffix = v.label.empty() ? "" : " [" + v.label + "]";
              double start = cpu_seconds();
              const auto one_solve = fit::fit_sequence(inputs, v.options);
              Row row = score(one_solve.frames, start);
              row.add(one_solve.stats);
              rows[{methods[2] + suffix, len, cond}].add(row);
              std::vector<fit::FittedFrame> out;
              for (const auto& w : windows) {
                start = cpu_seconds();
                fit::WindowedFitter windowed(v.options, w);
                out.clear();
                for (const auto& in : inputs)
                  for (auto& f : windowed.push(in)) out.push_back(f);
                for (auto& f : windowed.finish()) out.push_back(f);
                row = score(out, start);
                row.add(windowed.stats());
                rows[{window_name(w) + suffix, len, cond}].add(row);
              }
              start = cpu_seconds();
              fit::LiveFitter live(v.options);
              out.clear();
              for (const auto& in : inputs)
                if (auto f = live.push(in)) out.push_back(*f);
              for (auto& f : live.finish()) out.push_back(f);
              row = score(out, start);
              row.add(live.stats());
              rows[{live_method + suffix, len, cond}].add(row);
            }
            std::cerr << "." << std::flush;
          }
        }
      }
      std::cerr << "\n";
    }
    std::cout << truth.size() << " clips ("
              << (args.has("eval-files") ? "files" : args.get("eval-split"))
              << "; frames each: " << args.get("max-frames") << ", 0 = whole) at " << fps
              << " fps, " << cameras.size() << " cameras; full: " << options.max_iterations
              << " iterations per solve; live: lag " << options.lag << ", "
              << options.live_iterations << " iterations; ground plane "
              << (options.ground ? "given" : "none") << ", ankle clearance "
              << options.ankle_clearance_m << " m\n\n"
              << "| method | clip frames | condition | MPJPE mm | PA-MPJPE mm | accel mm/f² | root "
                 "err mm | skate cm/f | below floor cm | ankle-frames >1 cm below % | fit "
                 "person-frames per CPU s | iterations per solve | frames × iterations per frame "
                 "|\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const auto& len : length_labels) {
      for (const auto& m : methods) {
        Row all;
        for (const auto& c : conditions) {
          print_row(m, len, c.label(), rows[{m, len, c.label()}]);
          all.add(rows[{m, len, c.label()}]);
        }
        print_row(m, len, "all", all);
      }
    }
    if (variants.size() > 1) {
      std::cout
          << "\nWeight variants (rows \"all\": every condition; the base is the options "
             "given):\n\n| variant | clip frames | full MPJPE mm | full PA-MPJPE mm | full "
             "root err mm | full skate cm/f | windowed (first) MPJPE mm | live MPJPE mm | live "
             "PA-MPJPE mm | live root err mm | live accel mm/f² "
             "|\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
      for (const auto& len : length_labels) {
        for (const auto& v : variants) {
          const std::string suffix = v.label.empty() ? "" : " [" + v.label + "]";
          Row full, windowed, live;
          for (const auto& c : conditions) {
            full.add(rows[{methods[2] + suffix, len, c.label()}]);
            windowed.add(rows[{methods[3] + suffix, len, c.label()}]);
            live.add(rows[{live_method + suffix, len, c.label()}]);
          }
          std::cout << "| " << (v.label.empty() ? "base" : v.label) << " | " << len << " | "
                    << std::fixed << std::setprecision(1) << full.pose.mpjpe() << " | "
                    << full.pose.pa_mpjpe() << " | " << full.placement.root_error_mm() << " | "
                    << std::setprecision(2) << full.placement.skate_cm() << " | "
                    << std::setprecision(1) << windowed.pose.mpjpe() << " | " << live.pose.mpjpe()
                    << " | " << live.pose.pa_mpjpe() << " | " << live.placement.root_error_mm()
                    << " | " << live.pose.accel() << " |\n";
        }
      }
    }
    std::cout << "\nRetrieval: path + Savitzky-Golay (3, 11) + ray + view refinement on "
              << args.get("db") << ". Skating: horizontal ankle motion (world) between "
              << "consecutive frames where the truth ankle is in contact. Below floor: the ankle "
                 "under the clip's lowest true ankle height.\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-fit: " << e.what() << "\n";
    return 1;
  }
}
