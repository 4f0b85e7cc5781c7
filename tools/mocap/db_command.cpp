// `mocap db build | info | query`: the 2D-projection pose database.

#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "core/keypoint_layout.hpp"
#include "output_files.hpp"
#include "posedb/builder.hpp"
#include "posedb/cluster_search.hpp"
#include "posedb/database.hpp"
#include "posedb/exact_search.hpp"
#include "posedb/flann_search.hpp"
#include "progress_bar.hpp"

namespace mocap::cli {
namespace {

using nlohmann::json;

std::string joined_command(const char* name, int argc, char** argv) {
  std::string s = std::string("mocap db ") + name;
  for (int i = 0; i < argc; ++i) s += std::string(" ") + argv[i];
  return s;
}

// The motion files of the inputs for `split`: a folder with a splits.txt ("train 01_01.bvh"
// lines) gives only the files it assigns to `split`; a folder without one (bandai/) and a file
// named directly give all their files, said on stderr. At least one folder must have a
// splits.txt.
std::vector<std::string> files_of_split(const std::vector<std::string>& inputs,
                                        const std::string& split) {
  std::vector<std::string> kept;
  bool any_list = false;
  for (const auto& in : inputs) {
    const std::vector<std::string> files = posedb::collect_motion_files({in});
    std::ifstream list(std::filesystem::path(in) / "splits.txt");
    if (!std::filesystem::is_directory(in) || !list) {
      std::cerr << in << ": no splits.txt, all " << files.size() << " motion file(s) taken\n";
      kept.insert(kept.end(), files.begin(), files.end());
      continue;
    }
    any_list = true;
    std::map<std::string, std::string> split_of;
    std::string which, file;
    while (list >> which >> file) split_of[file] = which;
    std::size_t taken = 0;
    for (const auto& f : files) {
      const auto it = split_of.find(std::filesystem::path(f).filename().string());
      if (it != split_of.end() && it->second == split) kept.push_back(f), ++taken;
    }
    std::cerr << in << ": " << taken << " of " << files.size() << " motion file(s) in split '"
              << split << "'\n";
  }
  if (!any_list) throw InputError("--split", "no splits.txt found in the input folders");
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  if (kept.empty()) throw InputError("--split", "no file belongs to split '" + split + "'");
  return kept;
}

int build(int argc, char** argv) {
  Args args("mocap db build PATH... --out FILE [options]",
            "Builds the pose database from mocap files (BVH, or ASF/AMC) and folders of them: "
            "every frame is\n"
            "resampled, mapped to the 15-joint body and projected through virtual cameras at "
            "several yaws\n"
            "and heights; the normalised projections are clustered for fast search.");
  args.positional("PATH", "BVH/AMC files or folders (searched recursively)", true)
      .option("out", "FILE", "database file to write (through a temporary file)")
      .option("fps", "N", "frame rate of the database", "24", Range::between(1.0, 1000.0))
      .option("yaw-steps", "N", "camera yaw steps around the person (30 = every 12 degrees)", "30",
              Range::count(1, 3600))
      .option("heights", "LIST", "camera heights in metres, comma-separated", "1.5,2.5,4,6",
              Range::positive_list())
      .option("distance", "M", "horizontal camera distance in metres", "4", Range::positive())
      .option("scaling", "MODE", "2D normalisation: bbox_height (paper) or bone_length",
              "bbox_height")
      .option("body", "NAME",
              "canonical: every family rescaled to one body (CMU-train median bones, bone "
              "directions kept;\nsee docs/body15.md), source: each skeleton's own proportions",
              "canonical")
      .option("clusters", "N", "k-means clusters (0 = about sqrt(projections))", "0",
              Range::count(0, 100'000'000))
      .option("seed", "N", "random seed for k-means", "1",
              Range::count(0, std::numeric_limits<long>::max()))
      .option("threads", "N", "worker threads", "2", Range::count(1, 64))
      .option("split", "NAME",
              "only the files a folder's splits.txt assigns to NAME (e.g. train); a folder "
              "without\nsplits.txt (bandai/) is taken whole. Never give cmu_daz/ for a training "
              "database:\nit holds the held-out subjects' trials");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("out")) throw InputError("--out", "required: the database file to write");

  posedb::BuildOptions options;
  options.fps = args.number("fps");
  options.views.yaw_steps = static_cast<int>(args.integer("yaw-steps"));
  for (const double height : args.numbers("heights"))
    options.views.heights_m.push_back(static_cast<float>(height));
  options.views.distance_m = static_cast<float>(args.number("distance"));
  if (!posedb::parse_scaling(args.get("scaling"), options.scaling)) {
    throw InputError("--scaling",
                     "expected bbox_height or bone_length, got '" + args.get("scaling") + "'");
  }
  if (!posedb::parse_body_choice(args.get("body"), options.body))
    throw InputError("--body", "expected canonical or source, got '" + args.get("body") + "'");
  options.clusters = static_cast<int>(args.integer("clusters"));
  options.seed = static_cast<std::uint64_t>(args.integer("seed"));
  options.threads = static_cast<int>(args.integer("threads"));
  options.command = joined_command("build", argc, argv);

  const std::vector<std::string> files = args.has("split")
                                             ? files_of_split(args.positionals(), args.get("split"))
                                             : posedb::collect_motion_files(args.positionals());
  if (files.empty()) throw InputError("", "no .bvh or .amc files in the given paths");
  std::vector<NamedPath> inputs;
  for (const std::string& file : files) inputs.push_back({"", file});
  for (const std::string& path : args.positionals()) inputs.push_back({"PATH", path});
  refuse_output_over_inputs({"--out", args.get("out")}, inputs);
  std::cerr << "building from " << files.size() << " motion file(s)\n";

  posedb::BuildReport report;
  ProgressBar bar;
  posedb::DatabaseContents db = posedb::build_database(
      files, options, [&](std::string_view stage, double f) { bar.update(stage, f); }, report);
  bar.update("write", 0.0);
  posedb::write_database(db, args.get("out"));
  bar.finish();
  for (const auto& s : report.skipped) std::cerr << "skipped: " << s << "\n";
  if (std::any_of(db.clips.begin(), db.clips.end(),
                  [](const posedb::ClipInfo& c) { return c.family == "cmu_daz"; })) {
    std::cerr << "warning: cmu_daz clips are in this database; they are trials of the held-out "
                 "CMU subjects, so do not evaluate with it\n";
  }
  std::cout << "wrote " << args.get("out") << ": " << db.clips.size() << " clips, "
            << db.frames.size() << " frames, " << db.views.size() << " views, "
            << db.projection_records.size() << " projections, " << db.cluster_begin.size() - 1
            << " clusters in " << std::fixed << std::setprecision(1) << db.build.build_seconds
            << " s";
  if (!report.skipped.empty()) std::cout << " (" << report.skipped.size() << " file(s) skipped)";
  std::cout << "\n";
  return report.skipped.empty() ? 0 : 3;
}

json info_json(const posedb::Database& db) {
  std::map<std::string, std::pair<int, std::uint64_t>> families;
  json clips = json::array();
  for (const auto& c : db.clips()) {
    auto& [count, frames] = families[c.family];
    ++count;
    frames += c.frame_count;
    clips.push_back({{"name", c.name},
                     {"family", c.family},
                     {"frames", c.frame_count},
                     {"source_fps", c.source_fps}});
  }
  json fam = json::object();
  for (const auto& [name, cf] : families) fam[name] = {{"clips", cf.first}, {"frames", cf.second}};
  const auto cb = db.cluster_begin();
  std::uint32_t largest = 0;
  for (size_t c = 1; c < cb.size(); ++c) largest = std::max(largest, cb[c] - cb[c - 1]);
  return {{"file", db.path()},
          {"bytes", db.file_size()},
          {"clips", db.clips().size()},
          {"frames", db.frames().size()},
          {"views", db.views().size()},
          {"projections", db.projections().rows},
          {"dims", db.projections().dim},
          {"clusters", db.centroids().rows},
          {"largest_cluster", largest},
          {"index", "k-means clusters with representatives (rows stored grouped by cluster)"},
          {"body", std::string(posedb::body_choice_name(db.build_info().body))},
          {"families", fam},
          {"build", json::parse(db.options_json())},
          {"clip_list", clips}};
}

int info(int argc, char** argv) {
  Args args("mocap db info FILE [--json] [--clips]",
            "Prints what a pose database holds and how it was built.");
  args.positional("FILE", "pose database")
      .flag("json", "print JSON")
      .flag("clips", "list every clip");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const posedb::Database db = posedb::Database::open(args.positionals()[0]);
  json j = info_json(db);
  if (args.has("json")) {
    std::cout << json_text(j, 2) << "\n";
    return 0;
  }
  const auto& b = db.build_info();
  std::cout << "file         " << db.path() << " (" << std::fixed << std::setprecision(1)
            << static_cast<double>(db.file_size()) / 1e6 << " MB)\n"
            << "clips        " << db.clips().size() << "\n"
            << "frames       " << db.frames().size() << " at " << b.fps << " fps\n"
            << "views        " << db.views().size() << " (" << b.views.yaw_steps << " yaws x "
            << b.views.heights_m.size() << " camera heights";
  for (float h : b.views.heights_m) std::cout << " " << h;
  std::cout << " m, " << b.views.distance_m << " m away)\n"
            << "body         " << posedb::body_choice_name(b.body)
            << (b.body == posedb::BodyChoice::canonical
                    ? " (every clip rescaled to the canonical body)"
                    : " (each clip on its source skeleton's proportions)")
            << "\n"
            << "projections  " << db.projections().rows << " x " << db.projections().dim
            << " floats, " << posedb::scaling_name(b.scaling) << " normalisation\n"
            << "clusters     " << db.centroids().rows << " (largest " << j["largest_cluster"]
            << ")\n"
            << "index        " << j["index"].get<std::string>() << "\n"
            << "families     " << j["families"].size() << "\n";
  for (const auto& [name, f] : j["families"].items()) {
    std::cout << "  " << std::left << std::setw(10) << name << std::right << " " << std::setw(5)
              << f["clips"].get<int>() << " clips " << std::setw(8)
              << f["frames"].get<std::uint64_t>() << " frames\n";
  }
  std::cout << "built        " << b.created << " in " << b.build_seconds << " s, seed " << b.seed
            << "\n"
            << "command      " << b.command << "\n";
  if (args.has("clips")) {
    for (const auto& c : db.clips())
      std::cout << "  " << c.name << "  " << c.family << "  " << c.frame_count << " frames\n";
  }
  return 0;
}

// A query pose: {"layout": "COCO-17", "keypoints": [[x, y, c], ...]} (or a flat list), or
// {"joints": {"head": [x, y], ...}} with the 15 body joint names; absent joints are missing.
std::array<glm::vec2, kBodyJoints> parse_query_pose(const std::string& text,
                                                    const std::string& where) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(where, std::string("not valid JSON: ") + e.what());
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::array<glm::vec2, kBodyJoints> points;
  points.fill({nan, nan});
  try {
    if (j.contains("joints")) {
      for (const auto& [name, xy] : j.at("joints").items()) {
        const auto joint = joint_from_name(name);
        if (!joint) throw InputError(where, "unknown joint '" + name + "'");
        points[index(*joint)] = {xy.at(0).get<float>(), xy.at(1).get<float>()};
      }
      return points;
    }
    const KeypointLayout* layout = find_layout(j.at("layout").get<std::string>());
    if (!layout)
      throw InputError(where, "unknown layout '" + j.at("layout").get<std::string>() + "'");
    std::vector<float> flat;
    for (const auto& v : j.at("keypoints")) {
      if (v.is_array()) {
        for (const auto& x : v) flat.push_back(x.get<float>());
      } else {
        flat.push_back(v.get<float>());
      }
    }
    if (flat.size() != layout->keypoints.size() * 3) {
      throw InputError(where, std::string(layout->name) + " needs " +
                                  std::to_string(layout->keypoints.size()) +
                                  " keypoints of (x, y, confidence), got " +
                                  std::to_string(flat.size()) + " numbers");
    }
    std::array<float, kBodyJoints * 3> body;
    to_body15(*layout, flat, body);
    for (int b = 0; b < kBodyJoints; ++b) points[b] = {body[3 * b], body[3 * b + 1]};
  } catch (const json::exception& e) {
    throw InputError(where, std::string("unexpected JSON shape: ") + e.what());
  }
  return points;
}

int query(int argc, char** argv) {
  Args args("mocap db query FILE (--pose JSON | --pose-file FILE | --self N) [options]",
            "Finds the k nearest database projections of a 2D pose.\n"
            "A pose is {\"layout\": \"COCO-17\", \"keypoints\": [[x, y, confidence], ...]} in any "
            "layout\n"
            "(COCO-17, BODY_25, BODY_25B, COCO-18, HumanEva-15), or {\"joints\": {\"head\": [x, "
            "y], ...}}\n"
            "with the 15 body joint names; image coordinates, y down. Missing joints are left out "
            "of the distance.");
  args.positional("FILE", "pose database")
      .option("pose", "JSON", "the pose, inline")
      .option("pose-file", "FILE", "the pose, from a file")
      .option("self", "N", "query with the database's own projection number N", std::nullopt,
              Range::count(0, std::numeric_limits<long>::max()))
      .option("k", "N", "neighbours to return", "10", Range::count(1, 10000))
      .option("method", "NAME",
              "clusters (the database's own index), exact, or flann (kd-forest built now)",
              "clusters")
      .option("probe", "N", "clusters to scan (method clusters)", "16", Range::count(1, 1'000'000))
      .option("checks", "N", "leaves to examine (method flann)", "128",
              Range::count(1, 100'000'000))
      .flag("json", "print JSON lines");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const posedb::Database db = posedb::Database::open(args.positionals()[0]);

  posedb::PoseVector query{};
  if (args.has("self")) {
    const long n = args.integer("self");
    if (n < 0 || static_cast<std::size_t>(n) >= db.projections().rows) {
      throw InputError("--self", "projection number out of range (0 to " +
                                     std::to_string(db.projections().rows - 1) + ")");
    }
    std::copy_n(db.projections().row(static_cast<std::size_t>(n)), posedb::kPoseDims,
                query.begin());
  } else {
    std::string text = args.get("pose"), where = "--pose";
    if (args.has("pose-file")) {
      where = args.get("pose-file");
      std::ifstream in(where);
      if (!in) throw InputError(where, "cannot open");
      text.assign(std::istreambuf_iterator<char>(in), {});
    } else if (!args.has("pose")) {
      throw InputError("", "give the pose with --pose, --pose-file or --self");
    }
    const auto points = parse_query_pose(text, where);
    if (!posedb::normalize_pose(points, db.build_info().scaling, query)) {
      throw InputError(
          where,
          "cannot normalise this pose: the root (mid-hips) and at least 3 joints are needed");
    }
  }
  posedb::PoseVector weights;
  for (int d = 0; d < posedb::kPoseDims; ++d) weights[d] = std::isfinite(query[d]) ? 1.0f : 0.0f;

  std::unique_ptr<posedb::SearchIndex> index;
  if (args.get("method") == "exact") {
    index = std::make_unique<posedb::ExactSearch>(db.projections());
  } else if (args.get("method") == "clusters") {
    index = std::make_unique<posedb::ClusterSearch>(db.projections(), db.centroids(),
                                                    db.cluster_begin(),
                                                    static_cast<int>(args.integer("probe")));
  } else if (args.get("method") == "flann") {
    posedb::FlannOptions flann;
    flann.checks = static_cast<int>(args.integer("checks"));
    index = std::make_unique<posedb::FlannSearch>(db.projections(), flann);
  } else {
    throw InputError("--method",
                     "expected clusters, exact or flann, got '" + args.get("method") + "'");
  }
  const bool partial =
      std::any_of(weights.begin(), weights.end(), [](float w) { return w == 0.0f; });
  if (partial && !index->supports_weights()) {
    throw InputError(
        "--method",
        index->name() + " cannot leave missing joints out of the distance: use clusters or exact");
  }
  std::vector<posedb::Neighbor> found;
  index->search(query.data(), index->supports_weights() ? weights.data() : nullptr,
                static_cast<int>(args.integer("k")), found);
  for (size_t r = 0; r < found.size(); ++r) {
    const auto& rec = db.projection_records()[found[r].index];
    const auto& frame = db.frames()[rec.frame];
    const auto& clip = db.clips()[frame.clip];
    const auto& view = db.views()[rec.view];
    if (args.has("json")) {
      std::cout << json_text(json{{"rank", r},
                                  {"projection", found[r].index},
                                  {"distance", found[r].distance},
                                  {"clip", clip.name},
                                  {"clip_frame", frame.clip_frame},
                                  {"frame", rec.frame},
                                  {"yaw_deg", view.yaw_deg},
                                  {"camera_height_m", view.height_m}},
                             -1)
                << "\n";
    } else {
      std::cout << std::setw(3) << r << "  distance " << std::setw(10) << std::setprecision(6)
                << found[r].distance << "  projection " << std::setw(8) << found[r].index << "  "
                << clip.name << " frame " << frame.clip_frame << "  yaw " << view.yaw_deg
                << "  camera " << view.height_m << " m\n";
    }
  }
  return 0;
}

}  // namespace

int db_command(int argc, char** argv) {
  static constexpr Subcommand kSubcommands[] = {
      {"build", "build a pose database from mocap files", build},
      {"info", "print what a database holds", info},
      {"query", "find the nearest projections of a 2D pose", query},
  };
  return run_subcommand("db", kSubcommands, argc, argv);
}

}  // namespace mocap::cli
