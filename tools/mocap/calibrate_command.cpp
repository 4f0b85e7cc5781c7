// `mocap calibrate layout`: measures where a keypoint layout puts its joints relative to the
// canonical body's joint centres (eval/layout_calibration.hpp) and writes the coefficients of the
// correction (recon/layout_offsets.hpp) as calibration/layouts/<layout>.yaml.
// `mocap calibrate intrinsics`: camera intrinsics from chessboard or ChArUco images or a video
// (camera/chessboard_calibration.hpp, camera/charuco_calibration.hpp), written as an OpenCV YAML
// camera file.
// `mocap calibrate ground`: the floor from one image of a board lying on it
// (camera/ground_from_board.hpp), added to the camera file.
// `mocap calibrate rig`: several cameras posed in one world from a board they all film
// (camera/rig_calibration.hpp), written as a rig file.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string_view>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>

#include "calibration/people_calibration.hpp"
#include "camera/board.hpp"
#include "camera/camera_file.hpp"
#include "camera/charuco_calibration.hpp"
#include "camera/chessboard_calibration.hpp"
#include "camera/ground_from_board.hpp"
#include "camera/rig.hpp"
#include "camera/rig_calibration.hpp"
#include "camera/rig_file.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "detector_presets.hpp"
#include "eval/layout_calibration.hpp"
#include "eval_report.hpp"
#include "io/openpose_json.hpp"
#include "motion/canonical_body.hpp"
#include "people_views.hpp"
#include "progress_bar.hpp"

namespace mocap::cli {
namespace {

namespace fs = std::filesystem;
namespace he = io::humaneva;

struct Trial {
  std::string name;
  std::vector<eval::CalibrationFrame> frames;
};

// Every <trial>/pose-3d/*_LSTM.trc under the Pose2Sim folder, in name order.
std::vector<Trial> pose2sim_trials(const fs::path& folder, LayoutId layout) {
  if (!fs::is_directory(folder)) throw InputError(folder.string(), "not a folder");
  std::vector<fs::path> files;
  for (const auto& trial : fs::directory_iterator(folder)) {
    const fs::path dir = trial.path() / "pose-3d";
    if (!fs::is_directory(dir)) continue;
    for (const auto& f : fs::directory_iterator(dir))
      if (f.path().filename().string().ends_with("_LSTM.trc")) files.push_back(f.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty())
    throw InputError(folder.string(), "no <trial>/pose-3d/*_LSTM.trc files (Pose2Sim demo)");
  std::vector<Trial> out;
  for (const fs::path& f : files)
    out.push_back({f.filename().string(), eval::pose2sim_frames(io::read_trc(f), layout)});
  return out;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

// The fit as a Markdown table (also written, commented, into the file).
std::string fit_table(const eval::LayoutFit& fit) {
  std::ostringstream t;
  t << "| joint | basis | along | lateral | forward (3D only) | along mm | lateral mm | forward mm "
       "| offset up/left/fwd mm | frames | before mm | after (2D part) mm | after (3D) mm "
       "|\n|---|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|\n";
  for (int j = 0; j < kBodyJoints; ++j) {
    const auto& o = fit.offsets.joints[j];
    const auto& f = fit.joints[j];
    t << "| " << kJointNames[j] << " | " << recon::basis_name(o.basis) << " | " << fixed(o.along, 4)
      << " | " << fixed(o.lateral, 4) << " | " << fixed(o.forward, 4) << " | "
      << fixed(f.along_mm, 1) << " | " << fixed(f.lateral_mm, 1) << " | " << fixed(f.forward_mm, 1)
      << " | " << fixed(f.mean_offset_mm.x, 0) << " / " << fixed(f.mean_offset_mm.y, 0) << " / "
      << fixed(f.mean_offset_mm.z, 0) << " | " << f.frames << " | " << fixed(f.before_mm, 1)
      << " | " << fixed(f.after_mm, 1) << " | " << fixed(f.after_3d_mm, 1) << " |\n";
  }
  return t.str();
}

std::string check_table(const std::string& title,
                        const std::array<eval::JointFit, kBodyJoints>& rows) {
  std::ostringstream t;
  t << title << "\n\n| joint | samples | before mm | after mm |\n|---|---:|---:|---:|\n";
  double before = 0, after = 0, n = 0;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (rows[j].frames == 0) continue;
    t << "| " << kJointNames[j] << " | " << rows[j].frames << " | " << fixed(rows[j].before_mm, 1)
      << " | " << fixed(rows[j].after_mm, 1) << " |\n";
    before += rows[j].before_mm;
    after += rows[j].after_mm;
    ++n;
  }
  if (n > 0)
    t << "| mean of joints | | " << fixed(before / n, 1) << " | " << fixed(after / n, 1) << " |\n";
  return t.str();
}

// Mean proportions of the reference bodies (mm), to compare with the database's body.
std::string proportions(std::span<const eval::CalibrationFrame> frames) {
  const auto mean_distance = [&](auto&& a, auto&& b) {
    double sum = 0;
    int n = 0;
    for (const auto& f : frames) {
      const double d = glm::length(a(f.reference) - b(f.reference));
      if (std::isfinite(d)) sum += d, ++n;
    }
    return n ? 1000.0 * sum / n : 0.0;
  };
  const auto joint = [](Joint j) { return [j](const eval::Joints3& r) { return r[index(j)]; }; };
  const auto mid = [](Joint a, Joint b) {
    return [a, b](const eval::Joints3& r) { return 0.5f * (r[index(a)] + r[index(b)]); };
  };
  const auto shoulders = mid(Joint::right_shoulder, Joint::left_shoulder);
  const auto hips = mid(Joint::right_hip, Joint::left_hip);
  std::ostringstream t;
  t << "| hip-mid -> shoulder-mid | shoulders apart | hips apart | thigh | shin | upper arm | "
       "forearm |\n|---:|---:|---:|---:|---:|---:|---:|\n| "
    << fixed(mean_distance(shoulders, hips), 0) << " | "
    << fixed(mean_distance(joint(Joint::right_shoulder), joint(Joint::left_shoulder)), 0) << " | "
    << fixed(mean_distance(joint(Joint::right_hip), joint(Joint::left_hip)), 0) << " | "
    << fixed(mean_distance(joint(Joint::right_hip), joint(Joint::right_knee)), 0) << " | "
    << fixed(mean_distance(joint(Joint::right_knee), joint(Joint::right_ankle)), 0) << " | "
    << fixed(mean_distance(joint(Joint::right_shoulder), joint(Joint::right_elbow)), 0) << " | "
    << fixed(mean_distance(joint(Joint::right_elbow), joint(Joint::right_wrist)), 0) << " |\n";
  return t.str();
}

constexpr const char* kModel =
    "offset = along * T + lateral * (left - right) for the shoulders/hips bases, along * (joint - "
    "parent) for bone, T = mid-shoulders - mid-hips, all from the layout's own keypoints; fitted "
    "by least squares in 3D, applied in 2D (docs/keypoint-layouts.md)";

int layout_command(int argc, char** argv) {
  Args args("mocap calibrate layout (--pose2sim DIR | --humaneva DIR) --layout NAME [--out FILE]",
            "Fits where a keypoint layout puts its joints relative to the canonical joint "
            "centres and writes\nthe coefficients (calibration/layouts/<layout>.yaml). Pose2Sim: "
            "BODY_25B keypoints triangulated,\nreference from the LSTM anatomical markers "
            "(COCO-17, BODY_25, COCO-18 from the BODY_25B keypoints\nthey share). HumanEva: "
            "HumanEva-15 from its Train 3D. Prints the fit and checks as Markdown.");
  args.option("pose2sim", "DIR", "the Pose2Sim demo folder (trials with pose-3d/*_LSTM.trc)")
      .option("humaneva", "DIR", "HumanEva-I in the VideoPose3D format")
      .option("layout", "NAME", "BODY_25B, COCO-17, BODY_25, COCO-18 (Pose2Sim) or HumanEva-15",
              "BODY_25B")
      .option("leave", "JOINTS",
              "comma-separated Body15 joints left uncorrected (basis none), e.g. root for "
              "HumanEva-15\n(docs/keypoint-layouts.md: its hips are not joint centres, so "
              "its root offset hurts)")
      .option("out", "FILE", "where to write the offsets (nothing written when absent)");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const KeypointLayout* lay = find_layout(args.get("layout"));
  if (!lay) throw InputError("--layout", "unknown layout '" + args.get("layout") + "'");
  if (args.has("pose2sim") == args.has("humaneva"))
    throw InputError("mocap calibrate layout", "give exactly one of --pose2sim and --humaneva");

  std::vector<Trial> trials;
  std::string source;
  if (args.has("pose2sim")) {
    trials = pose2sim_trials(args.get("pose2sim"), lay->id);
    source = "Pose2Sim demo " + args.get("pose2sim") + " (";
    for (const auto& t : trials)
      source += t.name + ": " + std::to_string(t.frames.size()) + " frames; ";
    source +=
        "keypoints = the triangulated, filtered BODY_25B markers; reference = the LSTM "
        "anatomical markers)";
  } else {
    if (lay->id != LayoutId::humaneva15)
      throw InputError("--layout", "HumanEva data gives HumanEva-15 only");
    he::LoadOptions options;
    options.load_2d = false;
    const he::Dataset data = he::load_dataset(args.get("humaneva"), options);
    trials.push_back({"Train", eval::humaneva_frames(data, he::Split::train)});
    trials.push_back({"Validate", eval::humaneva_frames(data, he::Split::validate)});
    source = "HumanEva-I " + args.get("humaneva") + " Train split 3D (" +
             std::to_string(trials[0].frames.size()) +
             " frames); reference: shoulders and hips are joint centres in both, neck/head/root "
             "from their midpoints";
  }
  // HumanEva: fit on Train only, check on Validate. Pose2Sim: fit on all trials.
  std::vector<eval::CalibrationFrame> fit_frames;
  for (const auto& t : trials) {
    if (lay->id == LayoutId::humaneva15 && t.name != "Train") continue;
    fit_frames.insert(fit_frames.end(), t.frames.begin(), t.frames.end());
  }
  auto bases = eval::default_bases(lay->id);
  std::string left_alone;
  if (args.has("leave")) {
    std::stringstream list(args.get("leave"));
    for (std::string name; std::getline(list, name, ',');) {
      const auto* found = std::find(kJointNames.begin(), kJointNames.end(), name);
      if (found == kJointNames.end())
        throw InputError("--leave", "'" + name + "' is not a Body15 joint name");
      bases[static_cast<std::size_t>(found - kJointNames.begin())] = recon::OffsetBasis::none;
      left_alone += (left_alone.empty() ? "" : ", ") + name;
    }
    source += "; left uncorrected (--leave): " + left_alone;
  }
  const eval::LayoutFit fit = eval::fit_layout_offsets(lay->id, fit_frames, bases);
  std::ostringstream report;
  report << "## " << lay->name << ": fitted offsets (3D, " << fit_frames.size()
         << " frames; offset = reference - keypoint in the body frame before correction)\n\n"
         << fit_table(fit);
  if (!fit.notes.empty()) report << "\n" << fit.notes;
  report << "\nProportions of the reference joints (mean, mm; right side):\n\n"
         << proportions(fit_frames);
  std::cout << report.str();

  if (lay->id == LayoutId::humaneva15) {
    std::cout << "\n"
              << check_table("## HumanEva-15: held-out check on Validate 3D (fitted on Train)",
                             eval::evaluate_offsets_3d(fit.offsets, trials[1].frames));
  } else {
    // Cross-trial: fit on one trial, check on the other.
    for (std::size_t a = 0; a < trials.size() && trials.size() > 1; ++a) {
      std::vector<eval::CalibrationFrame> rest;
      for (std::size_t b = 0; b < trials.size(); ++b)
        if (b != a) rest.insert(rest.end(), trials[b].frames.begin(), trials[b].frames.end());
      const auto other = eval::fit_layout_offsets(lay->id, rest, eval::default_bases(lay->id));
      std::cout << "\n"
                << check_table("## " + std::string(lay->name) + ": 3D check on " + trials[a].name +
                                   ", fitted on the other trial(s)",
                               eval::evaluate_offsets_3d(other.offsets, trials[a].frames));
    }
    const fs::path toml = fs::path(args.get("pose2sim")) / "calibration" / "Calib_qualisys.toml";
    const auto cameras = camera::read_rig(toml).cameras;
    std::cout << "\n"
              << check_table("## " + std::string(lay->name) +
                                 ": 2D check, keypoints and reference projected through the " +
                                 std::to_string(cameras.size()) +
                                 " Pose2Sim cameras, correction applied in 2D (mm at the joint's "
                                 "depth)",
                             eval::evaluate_offsets_2d(fit.offsets, fit_frames, cameras));
  }

  if (args.has("out")) {
    std::string header = "Where " + std::string(lay->name) +
                         " puts its joints relative to the canonical joint centres.\n"
                         "Produced by: " +
                         command_line("mocap calibrate layout", argc, argv) + "\nData: " + source +
                         "\nModel: " + kModel + "\n\n" + report.str();
    const fs::path out = args.get("out");
    if (out.has_parent_path()) fs::create_directories(out.parent_path());
    std::ofstream(out) << recon::format_layout_offsets(fit.offsets, header);
    recon::load_layout_offsets(out);  // what was written reads back
    std::cout << "\nwrote " << out.string() << "\n";
  }
  return 0;
}

bool is_image_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* known :
       {".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".ppm", ".pgm", ".pbm", ".webp"})
    if (ext == known) return true;
  return false;
}

// "9x6" -> {9, 6}; `option` and `what` name the option and its meaning in the error.
std::pair<int, int> grid_size(const std::string& text, const std::string& option,
                              const std::string& what) {
  const auto x = text.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument(text);
    std::size_t used = 0;
    const int columns = std::stoi(text.substr(0, x), &used);
    if (used != x) throw std::invalid_argument(text);
    const int rows = std::stoi(text.substr(x + 1), &used);
    if (used != text.size() - x - 1) throw std::invalid_argument(text);
    if (columns < 2 || rows < 2 || columns > 100 || rows > 100) throw std::invalid_argument(text);
    return {columns, rows};
  } catch (const std::logic_error&) {
    throw InputError(option, "'" + text + "' is not COLUMNSxROWS " + what + " (2..100 each)");
  }
}

// The board options shared by `calibrate intrinsics` and `calibrate ground`.
void board_options(Args& args) {
  args.option("board", "KIND",
              "chessboard or charuco; CxR alone (e.g. 9x6) is a chessboard with that many inner "
              "corners",
              "chessboard")
      .option("corners", "CxR", "chessboard: inner corners, columns x rows", "9x6")
      .option("squares", "CxR", "ChArUco: squares along x and y (as the board was created)", "5x7")
      .option("square", "MM", "side of one square in millimetres", "25")
      .option("marker", "MM", "ChArUco: side of one marker in millimetres (required)")
      .option("dictionary", "NAME",
              "ChArUco: ArUco dictionary, e.g. DICT_4X4_50, DICT_5X5_100, DICT_6X6_250",
              "DICT_4X4_50");
}

camera::BoardSpec board_from(const Args& args) {
  camera::BoardSpec board;
  const std::string kind = args.get("board");
  std::string corners = args.get("corners");
  if (kind == "charuco") {
    board.kind = camera::BoardKind::charuco;
    std::tie(board.columns, board.rows) = grid_size(args.get("squares"), "--squares", "squares");
    if (!args.has("marker"))
      throw InputError("--marker", "a ChArUco board needs its marker size in millimetres");
    board.marker_mm = args.number("marker");
    board.dictionary = args.get("dictionary");
  } else {
    if (kind != "chessboard") {
      if (kind.find('x') == std::string::npos)
        throw InputError("--board", "'" + kind + "' is not chessboard, charuco or CxR, e.g. 9x6");
      corners = kind;
    }
    std::tie(board.columns, board.rows) =
        grid_size(corners, kind == "chessboard" ? "--corners" : "--board", "inner corners");
  }
  board.square_mm = args.number("square");
  if (!(board.square_mm > 0)) throw InputError("--square", "must be positive");
  try {
    camera::check_board(board);
  } catch (const std::invalid_argument& e) {
    throw InputError("--board", e.what());
  }
  return board;
}

int intrinsics_command(int argc, char** argv) {
  Args args(
      "mocap calibrate intrinsics IMAGES_OR_VIDEO... [--board chessboard|charuco ...] "
      "--square MM --out FILE",
      "Calibrates a camera's intrinsics from chessboard or ChArUco images (files, or "
      "folders of them)\nor one video (every --step-th frame) with OpenCV, prints the "
      "views used and skipped and the RMS\nreprojection error, and writes an OpenCV YAML "
      "camera file (camera_matrix,\ndistortion_coefficients, image_width, image_height). "
      "A ChArUco board may be partly hidden\nor cut by the image border.");
  args.positional("inputs", "board images, folders of images, or one video file", true);
  board_options(args);
  args.option("step", "N", "try every Nth frame of a video", "15")
      .option("out", "FILE", "where to write the camera file (nothing written when absent)");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const camera::BoardSpec board = board_from(args);
  const long step = args.integer("step");
  if (step < 1) throw InputError("--step", "must be at least 1");

  std::vector<std::string> images;
  std::string video;
  for (const std::string& input : args.positionals()) {
    std::error_code ec;
    if (fs::is_directory(input, ec)) {
      std::vector<std::string> found;
      for (const auto& entry : fs::directory_iterator(input, ec))
        if (entry.is_regular_file() && is_image_file(entry.path()))
          found.push_back(entry.path().string());
      if (found.empty()) throw InputError(input, "no image files in this folder");
      std::sort(found.begin(), found.end());
      images.insert(images.end(), found.begin(), found.end());
    } else if (!fs::exists(input, ec)) {
      throw InputError(input, "no such file");
    } else if (is_image_file(input)) {
      images.push_back(input);
    } else if (args.positionals().size() == 1) {
      video = input;
    } else {
      throw InputError(input, "not an image file (a video must be the only input)");
    }
  }
  camera::BoardCalibration result;
  if (board.kind == camera::BoardKind::chessboard) {
    camera::ChessboardOptions options;
    options.inner_columns = board.columns;
    options.inner_rows = board.rows;
    options.square_mm = board.square_mm;
    options.video_step = static_cast<int>(step);
    result = video.empty() ? camera::calibrate_chessboard_images(images, options)
                           : camera::calibrate_chessboard_video(video, options);
  } else {
    camera::CharucoOptions options;
    options.board = board;
    options.video_step = static_cast<int>(step);
    result = video.empty() ? camera::calibrate_charuco_images(images, options)
                           : camera::calibrate_charuco_video(video, options);
  }
  std::cout << "board " << camera::describe(board) << "\n";
  std::cout << "used " << result.used.size() << " views:\n";
  for (const auto& name : result.used) std::cout << "  " << name << "\n";
  std::cout << "skipped " << result.skipped.size() << " views:\n";
  for (const auto& s : result.skipped) std::cout << "  " << s.name << ": " << s.reason << "\n";
  const camera::Camera& c = result.camera;
  std::cout << "image " << c.width << "x" << c.height << "\n"
            << "fx " << fixed(c.fx, 2) << "  fy " << fixed(c.fy, 2) << "  cx " << fixed(c.cx, 2)
            << "  cy " << fixed(c.cy, 2) << "\ndistortion";
  for (double d : c.distortion) std::cout << " " << fixed(d, 5);
  std::cout << "\nRMS reprojection error " << fixed(result.rms_px, 3) << " px\n";
  if (args.has("out")) {
    const fs::path out = args.get("out");
    if (out.has_parent_path()) fs::create_directories(out.parent_path());
    camera::write_camera_file(out.string(), c, result.rms_px);
    camera::read_camera_file(out.string());  // what was written reads back
    std::cout << "wrote " << out.string() << "\n";
  }
  return 0;
}

int ground_command(int argc, char** argv) {
  Args args(
      "mocap calibrate ground --camera CAM.yml IMAGE [--board chessboard|charuco ...] "
      "--square MM [--out FILE]",
      "Finds the floor from one image of a calibration board lying flat on it: the "
      "board's pose\n(solvePnP with the camera file's intrinsics and lens distortion) "
      "gives its plane in the camera\nframe. Prints the camera's height above the floor "
      "and its tilt (degrees of the optical axis\nbelow the horizon) and writes the plane "
      "into the camera file (ground_normal, ground_offset).\nWithout a board, `mocap "
      "reconstruct` estimates the ground from the feet of the people in view\nover time.");
  args.positional("image", "an image of the board on the floor, taken by the calibrated camera");
  args.option("camera", "FILE",
              "the camera file (OpenCV YAML from `mocap calibrate intrinsics`, or a rig file of "
              "one camera)");
  board_options(args);
  args.option("thickness", "MM", "thickness of the board: the floor lies this far below it", "0")
      .option("out", "FILE",
              "write the camera file with the plane here instead of updating --camera");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("camera")) throw InputError("--camera", "the camera file is required");
  const camera::BoardSpec board = board_from(args);
  const double thickness = args.number("thickness");
  if (!(thickness >= 0)) throw InputError("--thickness", "must be zero or positive");
  const std::string camera_file = args.get("camera");
  const camera::Camera cam = camera::read_camera_file(camera_file);
  const std::string image = args.positionals().front();
  const camera::FloorFromBoard floor =
      camera::ground_from_board_image(image, cam, board, thickness);
  const auto& n = floor.plane.normal;
  std::cout << "board " << camera::describe(board) << ", thickness " << fixed(thickness, 1)
            << " mm\n"
            << "corners " << floor.corners << ", pose reprojection error " << fixed(floor.rms_px, 3)
            << " px\n"
            << "board origin in the camera frame " << fixed(floor.translation_m[0], 4) << " "
            << fixed(floor.translation_m[1], 4) << " " << fixed(floor.translation_m[2], 4) << " m\n"
            << "floor normal (up, camera frame) " << fixed(n[0], 5) << " " << fixed(n[1], 5) << " "
            << fixed(n[2], 5) << "\n"
            << "camera height above the floor "
            << fixed(camera::height_above_m(camera::Camera{}, floor.plane), 4) << " m\n"
            << "camera tilt "
            << fixed(camera::tilt_below_horizon_deg(camera::Camera{}, floor.plane), 2)
            << " degrees below the horizon\n";
  std::string target = camera_file;
  if (args.has("out")) {
    const fs::path out = args.get("out");
    if (out.has_parent_path()) fs::create_directories(out.parent_path());
    std::error_code ec;
    if (!fs::equivalent(camera_file, out, ec))
      fs::copy_file(camera_file, out, fs::copy_options::overwrite_existing);
    target = out.string();
  }
  camera::write_ground_plane(target, floor.plane);
  camera::read_ground_plane(target);  // what was written reads back
  std::cout << "wrote " << target << "\n";
  return 0;
}

// > 1: a factor of the median error.
Range outlier_range() {
  Range r = Range::between(1.0, 1000.0);
  r.above_min = true;
  return r;
}

// `mocap calibrate rig --from-people`: the extrinsics from the people the views show
// (calibration/people_calibration.hpp); videos and image folders through the detector first
// (people_views.hpp).
int rig_people_command(int argc, char** argv) {
  Args args(
      "mocap calibrate rig --from-people (--intrinsics RIG | --hfov DEG [--size WxH]) VIEW1 VIEW2 "
      "... --out RIG.toml [--height M] [--detector NAME] [--keypoints DIR]",
      "Calibrates the cameras' poses from the people they film: one view per camera, in the "
      "rig's\norder and in step (frame i of every view taken at the same instant): an OpenPose "
      "JSON folder,\na video or an image folder. Videos and image folders go through the "
      "detector first (--detector,\nas mocap reconstruct names them; frames per view on a "
      "progress bar) and their detections are\nkept as OpenPose JSON, one folder per camera "
      "under --keypoints (default: RIG's name +\n_keypoints beside --out), which a second run "
      "takes as its views without detecting again.\nTakes the person in each view and frame, "
      "the relative pose of the best-connected pair of\ncameras (essential matrix, RANSAC) and "
      "the others by PnP, then one bundle adjustment over the\ncamera poses and the joints of "
      "every frame used, the bones' lengths held constant over the\nframes (keypoints off by "
      "more than --outlier x the median dropped and the solve repeated).\nMetres from the "
      "person's standing height (--height; default: the canonical body's); the world\nfrom the "
      "feet: floor z = 0, z up, origin under the people's mean position, x along the first\n"
      "camera's heading. Prints each camera's RMS reprojection error and writes the rig\n"
      "(docs/cameras.md). The people must move through the space (one person standing still "
      "is\nrefused), and the cameras must stand apart (the same video twice is refused).");
  args.positional("views",
                  "per camera, in the rig's order: an OpenPose JSON folder, a video or an image "
                  "folder",
                  true);
  args.flag("from-people", "calibrate from the people in view (this command)")
      .option("intrinsics", "RIG",
              "each camera's matrix, distortion and size from this rig file, camera k for view k "
              "(its poses are ignored)")
      .option("hfov", "DEG",
              "without --intrinsics: every camera a pinhole of this horizontal field of view, "
              "without distortion",
              std::nullopt, Range::between(1.0, 179.0))
      .option("size", "WxH",
              "with --hfov: the images' size in pixels (default for videos and image folders: "
              "their own; needed for JSON views)",
              std::nullopt, Range::image_size())
      .option("cameras", "NAMES",
              "comma-separated camera names, one per view (default: those of --intrinsics, "
              "else cam_01, cam_02, ...)")
      .option("layout", "NAME", "the JSON's 25-keypoint layout: auto, BODY_25 or BODY_25B", "auto")
      .option("height", "M",
              "the person's standing height, floor to top of head, metres (default: the "
              "canonical body's, " +
                  fixed(motion::canonical_stature_m(), 2) + " m; docs/cameras.md)",
              std::nullopt, Range::between(0.5, 2.5))
      .option("outlier", "X", "drop keypoints whose error exceeds X times the median (> 1)", "3",
              outlier_range())
      .option("min-shared", "N", "frames with a person each camera must share with another", "20",
              Range::count(1))
      .option("detector", "NAME",
              "videos and image folders: how people are found, one of " + detector_names(),
              std::string(kFileDetector))
      .option("keypoints", "DIR",
              "videos and image folders: where their detections are kept, DIR/<camera>/ as "
              "OpenPose JSON (default: beside --out, its name + _keypoints)")
      .flag("force", "detect again over detections kept in --keypoints by an earlier run")
      .option("frames", "N", "use the first N frames of every view (default: all)", std::nullopt,
              Range::count(1))
      .option("fps", "F", "the frame rate of image folders (default 30)", std::nullopt,
              Range::between(0.001, 10000.0))
      .flag("quiet", "no progress while detecting")
      .option("out", "FILE", "where to write the rig (.toml or .yml; nothing written when absent)");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const std::vector<std::string>& paths = args.positionals();
  if (paths.size() < 2) throw InputError("mocap calibrate rig", "give at least 2 views");
  if (args.has("out")) camera::rig_format_for_writing(args.get("out"));  // a bad name fails now
  if (args.has("intrinsics") == args.has("hfov"))
    throw InputError("mocap calibrate rig --from-people", "give one of --intrinsics and --hfov");
  PeopleViewsOptions view_options;
  view_options.detector = args.get("detector");
  detector_preset(view_options.detector);  // an unknown name fails now, listing the names
  view_options.force = args.has("force");
  view_options.quiet = args.has("quiet");
  if (args.has("frames")) view_options.max_frames = args.integer("frames");
  if (args.has("fps")) view_options.folder_fps = args.number("fps");
  std::vector<PeopleView> views = open_people_views(paths, view_options);

  std::vector<camera::Camera> cameras;
  if (args.has("intrinsics")) {
    const std::string file = args.get("intrinsics");
    const camera::Rig rig = camera::read_rig(file);
    if (rig.cameras.size() < views.size())
      throw InputError(file, "has " + std::to_string(rig.cameras.size()) + " cameras for " +
                                 std::to_string(views.size()) + " views (camera k for view k)");
    cameras.assign(rig.cameras.begin(), rig.cameras.begin() + static_cast<long>(views.size()));
  } else {
    for (std::size_t i = 0; i < views.size(); ++i) {
      ImageSize size{views[i].width, views[i].height};
      if (args.has("size")) {
        size = args.image_size("size");
      } else if (views[i].kind == InputKind::openpose_json) {
        throw InputError("--hfov", views[i].path +
                                       " is an OpenPose JSON folder: give the images' size "
                                       "(--size WxH)");
      }
      cameras.push_back(camera::Camera::from_fov(
          size.width, size.height, args.number("hfov"),
          std::string("cam_") + (i < 9 ? "0" : "") + std::to_string(i + 1)));
    }
  }
  if (args.has("cameras")) {
    std::stringstream list(args.get("cameras"));
    std::vector<std::string> names;
    for (std::string name; std::getline(list, name, ',');) names.push_back(name);
    if (names.size() != views.size())
      throw InputError("--cameras", std::to_string(names.size()) + " names for " +
                                        std::to_string(views.size()) + " views");
    for (std::size_t i = 0; i < views.size(); ++i) cameras[i].name = names[i];
  }
  check_people_views(views, cameras);

  const std::string layout = args.get("layout");
  if (layout != "auto" && layout != "BODY_25" && layout != "BODY_25B")
    throw InputError("--layout", "expected auto, BODY_25 or BODY_25B, got '" + layout + "'");
  const bool detecting = std::any_of(
      views.begin(), views.end(), [](const PeopleView& v) { return v.kind == InputKind::video; });
  if (detecting) {
    if (args.has("keypoints")) {
      view_options.keypoints = args.get("keypoints");
    } else if (args.has("out")) {
      const fs::path out = args.get("out");
      view_options.keypoints = out.parent_path() / (out.stem().string() + "_keypoints");
    } else {
      throw InputError("mocap calibrate rig --from-people",
                       "videos and image folders need --keypoints DIR or --out (their detections "
                       "are kept beside it)");
    }
    detect_people(views, cameras, view_options);
  }

  io::OpenPoseOptions json_options;
  json_options.body25 = layout == "auto"       ? io::Body25Choice::detect
                        : layout == "BODY_25B" ? io::Body25Choice::body25b
                                               : io::Body25Choice::body25;
  std::vector<camera::BodySequence> sequences;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const PeopleView& v = views[i];
    const io::OpenPoseSequence json = io::read_openpose_folder(v.json, json_options);
    for (const io::FrameProblem& p : json.problems)
      std::cerr << "mocap calibrate rig: " << v.json.string() << ": " << p.message << "\n";
    check_keypoints_fit(v, json, cameras[i]);
    if (const std::string note = small_keypoints_note(v, json, cameras[i]); !note.empty())
      std::cerr << "mocap calibrate rig: note: " << note << "\n";
    sequences.push_back(camera::body_sequence(json.frames));
    if (view_options.max_frames && sequences.back().size() > std::size_t(*view_options.max_frames))
      sequences.back().resize(static_cast<std::size_t>(*view_options.max_frames));
  }

  calibration::PeopleCalibrationOptions options;
  if (args.has("height")) options.height_m = args.number("height");
  options.outlier_factor = args.number("outlier");
  options.min_shared_frames = static_cast<int>(args.integer("min-shared"));
  const calibration::PeopleCalibration result =
      calibration::calibrate_rig_from_people(cameras, sequences, paths, options);

  std::cout << result.frames_used << " frames in the bundle adjustment; person height "
            << fixed(result.height_m, 3) << " m; motion " << fixed(result.motion, 3)
            << " body heights\n";
  for (const std::string& note : result.notes) std::cout << "note: " << note << "\n";
  std::cout << "\n| camera | frames | keypoints used | dropped | RMS px | position m |\n"
               "|---|---:|---:|---:|---:|---|\n";
  for (std::size_t k = 0; k < result.rig.cameras.size(); ++k) {
    const camera::Camera& c = result.rig.cameras[k];
    const auto& r = result.cameras[k];
    const glm::dvec3 p = c.centre();
    std::cout << "| " << c.name << " | " << r.frames << " | " << r.observations << " | "
              << r.dropped << " | " << fixed(r.rms_px, 2) << " | " << fixed(p.x, 3) << " "
              << fixed(p.y, 3) << " " << fixed(p.z, 3) << " |\n";
  }
  std::cout << "\nRMS reprojection error " << fixed(result.rms_px, 2) << " px\n";
  if (args.has("out")) {
    const fs::path out = args.get("out");
    if (out.has_parent_path()) fs::create_directories(out.parent_path());
    camera::write_rig(out, result.rig);
    camera::read_rig(out);  // what was written reads back
    std::cout << "wrote " << out.string() << "\n";
  }
  return 0;
}

// Frame numbers, comma-separated, each a whole number >= 0.
Range frame_list_range() {
  Range r = Range::count(0);
  r.list = true;
  return r;
}

int rig_board_command(int argc, char** argv) {
  for (int i = 0; i < argc; ++i)
    if (std::string_view(argv[i]) == "--from-people") return rig_people_command(argc, argv);
  Args args(
      "mocap calibrate rig VIEW1 VIEW2 ... [--board charuco ...] --square MM --out RIG.toml\n"
      "       mocap calibrate rig --from-people ... (see mocap calibrate rig --from-people --help)",
      "Calibrates several cameras together from a chessboard or ChArUco board that they all "
      "film: one\nview per camera (a video, or a folder of images in name order), in step "
      "(frame i of every view\ntaken at the same instant). Finds the board in every --step-th "
      "frame, calibrates each camera's\nintrinsics from its own frames (or takes them from "
      "--intrinsics), chains the cameras' poses over\nthe frames they share, refines all "
      "camera and board poses (and intrinsics from the cameras'\nown frames) in one bundle "
      "adjustment (dropping\ncorners off by more than "
      "--outlier x the median and solving again), and sets the world from\nthe board lying "
      "on the floor in --floor-frame: origin at the board's origin, x along the board,\nz up, "
      "metres from --square; or from --floor-frames: the floor plane through the corners of\n"
      "all of them, origin and x from the first. Prints each camera's RMS reprojection error and\n"
      "writes the rig (.toml: Pose2Sim/anipose layout; .yml: OpenCV YAML; docs/cameras.md).");
  args.positional("views", "a video or a folder of images per camera, in the rig's order", true);
  board_options(args);
  args.option("cameras", "NAMES",
              "comma-separated camera names, one per view (default: those of --intrinsics, "
              "else cam_01, cam_02, ...)")
      .option("intrinsics", "RIG",
              "take each camera's matrix, distortion and size from this rig file (by name); its "
              "poses are ignored")
      .flag("refine-intrinsics",
            "also refine the --intrinsics' fx, fy, cx, cy and k1 k2 in the bundle (k3 and, "
            "without --tangential, p1 p2 stay); always done with intrinsics from the cameras' "
            "own frames")
      .flag("tangential",
            "fit (own frames) or refine (--refine-intrinsics) the tangential distortion p1 p2; "
            "held by default: on a distant board it trades against the principal point and so "
            "the camera's angle (docs/cameras.md)")
      .flag("aspect",
            "fit fx and fy apart in intrinsics from the cameras' own frames (default: square "
            "pixels, fx = fy)")
      .option("floor-frame", "N",
              "the frame in which the board lies flat on the floor (default: the first frame in "
              "which a camera sees the board)",
              std::nullopt, Range::count(0))
      .option("floor-frames", "N,N,...",
              "several frames of the board lying flat on the floor, slid and turned between "
              "them (instead of --floor-frame): the floor plane is fitted to all their corners "
              "(a board seen at a grazing angle tilts the world less), origin and x from the "
              "first; a frame whose board lies over 10 mm off that plane gets a note",
              std::nullopt, frame_list_range())
      .option("thickness", "MM", "thickness of the board: the floor lies this far below it", "0",
              Range::at_least(0))
      .option("step", "N", "search every Nth frame of each view", "1", Range::count(1))
      .option("outlier", "X", "drop corners whose error exceeds X times the median (> 1)", "3",
              outlier_range())
      .flag("drop-unconnected",
            "leave out cameras that never see the board (or never together with the others) "
            "instead of refusing")
      .option("out", "FILE", "where to write the rig (.toml or .yml; nothing written when absent)");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const std::vector<std::string>& views = args.positionals();
  if (views.size() < 2) throw InputError("mocap calibrate rig", "give at least 2 views");
  camera::RigBoardOptions options;
  options.board = board_from(args);
  options.step = static_cast<int>(args.integer("step"));
  // Intrinsics from the cameras' own frames are always refined: held, each is off by what its
  // few distant views allow (mocap-bench-rig-board: up to 27 mm and 1.3 degrees).
  options.refine_intrinsics = args.has("refine-intrinsics") || !args.has("intrinsics");
  options.tangential_distortion = args.has("tangential");
  options.square_pixels = !args.has("aspect");
  options.outlier_factor = args.number("outlier");
  options.board_thickness_mm = args.number("thickness");
  options.drop_unconnected = args.has("drop-unconnected");
  if (args.has("floor-frame")) options.floor_frame = static_cast<int>(args.integer("floor-frame"));
  if (args.has("floor-frames")) {
    if (args.has("floor-frame"))
      throw InputError("--floor-frames", "give --floor-frame or --floor-frames, not both");
    for (double frame : args.numbers("floor-frames"))
      options.floor_frames.push_back(static_cast<int>(frame));
  }
  if (args.has("out")) camera::rig_format_for_writing(args.get("out"));  // a bad name fails now

  std::vector<std::string> names;
  if (args.has("intrinsics")) {
    options.intrinsics_source = args.get("intrinsics");
    options.intrinsics = camera::read_rig(options.intrinsics_source);
  }
  if (args.has("cameras")) {
    std::stringstream list(args.get("cameras"));
    for (std::string name; std::getline(list, name, ',');) names.push_back(name);
    if (names.size() != views.size())
      throw InputError("--cameras", std::to_string(names.size()) + " names for " +
                                        std::to_string(views.size()) + " views");
  } else if (options.intrinsics) {
    const auto& cameras = options.intrinsics->cameras;
    for (std::size_t i = 0; i < views.size(); ++i) {
      if (i >= cameras.size())
        throw InputError(options.intrinsics_source,
                         "has " + std::to_string(cameras.size()) + " cameras, no camera for view " +
                             std::to_string(i + 1) + " (" + views[i] +
                             "): add it, or name the views' cameras with --cameras");
      names.push_back(cameras[i].name);
    }
  } else {
    for (std::size_t i = 0; i < views.size(); ++i)
      names.push_back(std::string("cam_") + (i < 9 ? "0" : "") + std::to_string(i + 1));
  }

  ProgressBar bar;
  options.progress = [&bar](const std::string& stage, double fraction) {
    bar.update(stage, fraction);
  };
  const camera::RigCalibration result = camera::calibrate_rig_from_board(views, names, options);
  bar.finish();

  std::cout << "board " << camera::describe(options.board) << "\n"
            << result.frames_used << " frames with the board; the floor from frame"
            << (result.floor_frames.size() > 1 ? "s" : "");
  for (const camera::FloorFrameReport& f : result.floor_frames) {
    std::cout << " " << f.frame;
    if (result.floor_frames.size() > 1)
      std::cout << " (" << fixed(f.max_off_mm, 1) << " mm off the plane, tilted "
                << fixed(f.tilt_deg, 2) << " deg)";
  }
  std::cout << "\n";
  for (const std::string& note : result.notes) std::cout << "note: " << note << "\n";
  std::cout << "\n| camera | frames with board | corners used | dropped | RMS px | fx | fy | cx | "
               "cy | position m |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (std::size_t k = 0; k < result.rig.cameras.size(); ++k) {
    const camera::Camera& c = result.rig.cameras[k];
    const auto& r = result.cameras[k];
    const glm::dvec3 p = c.centre();
    std::cout << "| " << c.name << " | " << r.frames_with_board << " | " << r.observations << " | "
              << r.dropped << " | " << fixed(r.rms_px, 3) << " | " << fixed(c.fx, 1) << " | "
              << fixed(c.fy, 1) << " | " << fixed(c.cx, 1) << " | " << fixed(c.cy, 1) << " | "
              << fixed(p.x, 3) << " " << fixed(p.y, 3) << " " << fixed(p.z, 3) << " |\n";
  }
  std::cout << "\nRMS reprojection error " << fixed(result.rms_px, 3) << " px\n";
  if (args.has("out")) {
    const fs::path out = args.get("out");
    if (out.has_parent_path()) fs::create_directories(out.parent_path());
    camera::write_rig(out, result.rig);
    camera::read_rig(out);  // what was written reads back
    std::cout << "wrote " << out.string() << "\n";
  }
  return 0;
}

}  // namespace

int calibrate_command(int argc, char** argv) {
  static constexpr Subcommand kSubcommands[] = {
      {"layout", "fit where a keypoint layout puts its joints (calibration/layouts/)",
       layout_command},
      {"intrinsics",
       "camera intrinsics from chessboard or ChArUco images or a video (OpenCV camera file)",
       intrinsics_command},
      {"ground", "the floor from an image of a board lying on it (added to the camera file)",
       ground_command},
      {"rig",
       "several cameras in one world from a board they all film, or from the people in view "
       "(--from-people; a rig file)",
       rig_board_command},
  };
  return run_subcommand("calibrate", kSubcommands, argc, argv);
}

}  // namespace mocap::cli
