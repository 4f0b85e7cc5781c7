// `mocap rig info RIG [VIEW...]`, `mocap rig convert IN OUT` and `mocap rig offsets RIG VIEW...`:
// what a rig file (docs/cameras.md: the Pose2Sim/anipose TOML layout or OpenCV YAML) holds, the
// same rig in the other format, and the frame offsets between views filmed without a common clock.

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "camera/frame_offsets.hpp"
#include "camera/rig_file.hpp"
#include "camera/rig_report.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "io/openpose_json.hpp"
#include "multiview/view_check.hpp"
#include "view_offsets.hpp"

namespace mocap::cli {
namespace {

io::OpenPoseOptions json_options(const std::string& layout) {
  if (layout != "auto" && layout != "BODY_25" && layout != "BODY_25B")
    throw InputError("--layout", "expected auto, BODY_25 or BODY_25B, got '" + layout + "'");
  io::OpenPoseOptions options;
  options.body25 = layout == "auto"       ? io::Body25Choice::detect
                   : layout == "BODY_25B" ? io::Body25Choice::body25b
                                          : io::Body25Choice::body25;
  return options;
}

// The frames `rig info` checks the views on (those with a person in every view): a bounded time,
// and enough for a median over thousands of joints per camera.
constexpr std::size_t kCheckedFrames = 300;

// Per camera, how far its keypoints lie from the joints triangulated from the other cameras. A
// view that cannot be read is named and left out (its camera then has no error).
void print_view_errors(const camera::Rig& rig, const std::string& file,
                       const std::vector<std::string>& folders, const std::string& layout) {
  if (folders.size() != rig.cameras.size())
    throw InputError(file, std::to_string(rig.cameras.size()) + " cameras, " +
                               std::to_string(folders.size()) +
                               " views given: give one view per camera, in the rig's order");
  const io::OpenPoseOptions options = json_options(layout);
  std::vector<camera::Camera> cameras;
  std::vector<camera::BodySequence> views;
  std::vector<std::size_t> index;  // the rig's camera of each view read
  for (std::size_t v = 0; v < folders.size(); ++v) {
    try {
      const io::OpenPoseSequence json = io::read_openpose_folder(folders[v], options);
      for (const io::FrameProblem& p : json.problems)
        std::cerr << "mocap rig info: " << folders[v] << ": " << p.message << "\n";
      const bool people = std::any_of(json.frames.begin(), json.frames.end(),
                                      [](const People2D& f) { return !f.people.empty(); });
      if (!people) throw InputError(folders[v], "no person in any of its frames");
      views.push_back(camera::body_sequence(json.frames));
      cameras.push_back(rig.cameras[v]);
      index.push_back(v);
    } catch (const std::exception& e) {
      std::cerr << "mocap rig info: " << e.what() << "; view " << v + 1 << " ("
                << rig.cameras[v].name << ") skipped\n";
    }
  }
  multiview::ViewCheckOptions check_options;
  check_options.max_frames = kCheckedFrames;
  const multiview::ViewCheck check = multiview::check_views(cameras, views, check_options);
  const multiview::ViewErrorReport& report = check.errors;
  std::cout << "\nreprojection error per camera: its keypoints against the joints triangulated "
               "from the other\ncameras, over "
            << report.frames_used << " of " << report.frames
            << " frames (those with a person in every view, at most " << kCheckedFrames
            << "; per view its tallest)\n\n"
            << "| camera | points | median px | mean px | |\n|---|---|---|---|---|\n";
  std::vector<std::string> labels;
  for (std::size_t v = 0; v < rig.cameras.size(); ++v) {
    const auto it = std::find(index.begin(), index.end(), v);
    char row[256];
    if (it == index.end()) {
      std::snprintf(row, sizeof row, "| %s | - | - | - | view not read |\n",
                    rig.cameras[v].name.c_str());
    } else {
      const multiview::ViewError& e = report.views[static_cast<std::size_t>(it - index.begin())];
      std::snprintf(row, sizeof row, "| %s | %zu | %.1f | %.1f | %s |\n",
                    rig.cameras[v].name.c_str(), e.points, e.median_px, e.mean_px,
                    e.flagged ? "far worse than the rest" : "");
      labels.push_back("view " + std::to_string(v + 1) + " (" + rig.cameras[v].name + ")");
    }
    std::cout << row;
  }
  if (views.size() < 3)
    std::cout << "fewer than 3 views read: a camera's keypoints need two others to check them\n";
  for (const std::string& line : multiview::describe(check, cameras, labels))
    std::cout << line << "\n";
}

int info(int argc, char** argv) {
  Args args("mocap rig info RIG [VIEW1 VIEW2 ...] [--layout L]",
            "Prints a rig's cameras (name, image size, focal lengths, principal point, "
            "distortion), where they\nare in the world and where they look, the baselines and "
            "the angles between their optical axes\nfor every pair, and the floor (with each "
            "camera's height and tilt above it). RIG: a .toml\n(Pose2Sim, anipose, Caliscope, "
            "FreeMoCap) or OpenCV .yml rig file, or the single-camera file\nof `mocap calibrate "
            "intrinsics`. Given keypoints (VIEW: an OpenPose JSON folder per camera, in\nthe "
            "rig's order; at least 3), also the reprojection error per camera: its keypoints "
            "against\nthe joints triangulated from the other cameras (median, mean, points), a "
            "camera far worse\nthan the rest flagged, and what explains it when something "
            "does: the views given in another order\n(any permutation among cameras of one size: "
            "the order to give them in), or a view's keypoints\nmade at another image size "
            "(the factor and the size); and when every camera is far off, that\nthe rig may not "
            "be these views' rig (docs/cameras.md).");
  args.positional("RIG", "the rig file")
      .positional("VIEW", "OpenPose JSON folders, one per camera of the rig, in its order", true,
                  false)
      .option("layout", "L",
              "25-keypoint files are BODY_25 or BODY_25B (Pose2Sim's); auto: told by the "
              "keypoints, as source.openpose_json does",
              "auto");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const std::string file = args.positionals().at(0);
  const camera::Rig rig = camera::read_rig(file);
  std::cout << file << ": " << camera::rig_report(rig);
  const std::vector<std::string> folders(args.positionals().begin() + 1, args.positionals().end());
  if (!folders.empty()) print_view_errors(rig, file, folders, args.get("layout"));
  return 0;
}

int convert(int argc, char** argv) {
  Args args("mocap rig convert IN OUT",
            "Reads a rig file and writes the same rig in the format OUT's extension names: .toml "
            "(the\nPose2Sim/anipose layout, our floor in [metadata.floor]) or .yml/.yaml (OpenCV "
            "YAML, a `cameras`\nlist). IN may be either, or the single-camera file of `mocap "
            "calibrate intrinsics`.");
  args.positional("IN", "the rig file to read").positional("OUT", "the rig file to write");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const std::string in = args.positionals().at(0), out = args.positionals().at(1);
  camera::rig_format_for_writing(out);  // a bad extension fails before anything is read
  const camera::Rig rig = camera::read_rig(in);
  camera::write_rig(out, rig);
  if (camera::read_rig(out) != rig) {
    // Not expected: the formats keep every number (shortest round-trip text, %.16e).
    std::cerr << "mocap rig convert: warning: " << out << " does not read back exactly as " << in
              << "\n";
  }
  std::cout << "wrote " << out << ": " << rig.cameras.size() << " camera(s)"
            << (rig.floor ? ", the floor" : "") << "\n";
  return 0;
}

int offsets(int argc, char** argv) {
  Args args("mocap rig offsets RIG VIEW1 VIEW2 ... [--reference N] [--max-offset F] [--layout L]",
            "Estimates how many frames each view is shifted against the reference view, from "
            "where its\npeople lie on the reference's epipolar lines (docs/cameras.md, \"Frame "
            "offsets\"). VIEW: an\nOpenPose JSON folder per camera, in the rig's camera order. "
            "Prints per view the offset\n(its frame i shows the reference's frame i + offset) or "
            "why none was found; exits 1 when\na view has none.");
  args.positional("RIG", "the rig file")
      .positional("VIEW", "OpenPose JSON folders, one per camera of the rig, in its order", true)
      .option("reference", "N", "the view the others are measured against (1 = the first)", "1",
              Range::count(1, 64))
      .option("max-offset", "F", "largest offset tried, in frames", "30", Range::count(1, 1000))
      .option("layout", "L",
              "25-keypoint files are BODY_25 or BODY_25B (Pose2Sim's); auto: told by the "
              "keypoints, as source.openpose_json does",
              "auto");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const std::string file = args.positionals().at(0);
  const camera::Rig rig = camera::read_rig(file);
  const std::vector<std::string> folders(args.positionals().begin() + 1, args.positionals().end());
  if (folders.size() != rig.cameras.size())
    throw InputError(file, std::to_string(rig.cameras.size()) + " cameras, " +
                               std::to_string(folders.size()) +
                               " views given: give one view per camera, in the rig's order");
  const auto reference = static_cast<std::size_t>(args.integer("reference") - 1);
  if (reference >= folders.size())
    throw InputError("--reference", "view " + std::to_string(reference + 1) + " of " +
                                        std::to_string(folders.size()));
  const io::OpenPoseOptions options_json = json_options(args.get("layout"));
  camera::OffsetOptions options;
  options.max_offset_frames = static_cast<int>(args.integer("max-offset"));
  const ViewOffsets estimated =
      estimate_view_offsets(rig, folders, options_json, reference, options, "mocap rig offsets");
  const std::vector<camera::ViewOffset>& found = estimated.offsets;
  std::cout
      << "| view | camera | frames | offset (frames) | contrast | epipolar cost (body heights) |\n"
         "|---|---|---|---|---|---|\n";
  int missing = 0;
  for (std::size_t v = 0; v < found.size(); ++v) {
    char offset[32] = "reference";
    if (v != reference) std::snprintf(offset, sizeof offset, "%+.2f", found[v].frames);
    char row[256];
    std::snprintf(row, sizeof row, "| %zu | %s | %zu | %s%s | %.2f | %.4f |\n", v + 1,
                  rig.cameras[v].name.c_str(), estimated.frames[v], offset,
                  found[v].found ? "" : " (none)", found[v].contrast, found[v].cost);
    std::cout << row;
    if (!found[v].found) ++missing;
  }
  for (std::size_t v = 0; v < found.size(); ++v)
    if (!found[v].found) std::cout << rig.cameras[v].name << ": " << found[v].problem << "\n";
  return missing == 0 ? 0 : 1;
}

}  // namespace

int rig_command(int argc, char** argv) {
  static constexpr Subcommand kSubcommands[] = {
      {"info", "a rig's cameras, positions, baselines, angles and floor", info},
      {"convert", "a rig file in the other format (TOML <-> OpenCV YAML)", convert},
      {"offsets", "frame offsets between views filmed without a common clock", offsets},
  };
  return run_subcommand("rig", kSubcommands, argc, argv);
}

}  // namespace mocap::cli
