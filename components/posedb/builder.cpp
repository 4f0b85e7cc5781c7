#include "posedb/builder.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <set>
#include <thread>

#include "core/input_error.hpp"
#include "motion/asf_amc.hpp"
#include "motion/body_mapping.hpp"
#include "motion/bvh.hpp"
#include "motion/canonical_body.hpp"
#include "motion/pose_sequence.hpp"
#include "posedb/kmeans.hpp"
#include "posedb/projection.hpp"

namespace mocap::posedb {
namespace fs = std::filesystem;
namespace {

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

// An AMC file is listed as "skeleton.asf|motion.amc" so one string names both files.
std::string asf_for(const fs::path& amc) {
  const std::string stem = amc.stem().string();
  const fs::path subject = amc.parent_path() / (stem.substr(0, stem.find('_')) + ".asf");
  if (fs::exists(subject)) return subject.string();
  std::vector<fs::path> found;
  for (const auto& e :
       fs::directory_iterator(amc.parent_path().empty() ? fs::path(".") : amc.parent_path())) {
    if (e.is_regular_file() && lower_extension(e.path()) == ".asf") found.push_back(e.path());
  }
  if (found.size() == 1) return found.front().string();
  throw InputError(amc.string(),
                   found.empty()
                       ? "no .asf skeleton beside this .amc file"
                       : "several .asf files beside this .amc file; expected " + subject.string());
}

void add_file(const fs::path& p, std::set<std::string>& out) {
  const std::string ext = lower_extension(p);
  if (ext == ".bvh") out.insert(p.string());
  if (ext == ".amc") out.insert(asf_for(p) + "|" + p.string());
}

// One clip after reading: the part of the database it contributes, before projection.
struct ClipFrames {
  ClipInfo info;
  std::vector<FrameRecord> frames;                         // clip index filled in later
  std::vector<std::array<glm::vec3, kBodyJoints>> joints;  // root-relative, facing +Z, metres
  std::vector<float> rotations;                            // frame * joints * 4
};

motion::Clip read_clip(const std::string& file) {
  if (const auto bar = file.find('|'); bar != std::string::npos) {
    return motion::read_asf_amc(file.substr(0, bar), file.substr(bar + 1));
  }
  return motion::read_bvh(file);
}

// The body's facing (yaw about +Y, 0 = +Z) from its hip and shoulder lines.
bool facing(const std::array<glm::vec3, kBodyJoints>& b, float& heading) {
  glm::vec3 across = (b[index(Joint::left_hip)] - b[index(Joint::right_hip)]) +
                     (b[index(Joint::left_shoulder)] - b[index(Joint::right_shoulder)]);
  across.y = 0.0f;
  if (glm::length(across) < 1e-4f) return false;
  const glm::vec3 forward = glm::cross(across, glm::vec3(0, 1, 0));
  heading = std::atan2(forward.x, forward.z);
  return true;
}

// Runs of frames that hold capture data: after the reference frame, without all-zero frames.
std::vector<std::pair<int, int>> capture_runs(const motion::Clip& clip, bool skip_first,
                                              BuildReport& report, std::mutex& m) {
  std::vector<std::pair<int, int>> runs;
  int start = -1;
  std::size_t blank = 0;
  for (int f = skip_first ? 1 : 0; f <= clip.frame_count; ++f) {
    const bool usable = f < clip.frame_count && !motion::is_blank_frame(clip, f);
    if (f < clip.frame_count && !usable) ++blank;
    if (usable && start < 0) start = f;
    if (!usable && start >= 0) {
      runs.emplace_back(start, f - start);
      start = -1;
    }
  }
  std::lock_guard lock(m);
  report.blank_frames_dropped += blank;
  report.reference_frames_dropped += (skip_first && clip.frame_count > 0) ? 1 : 0;
  return runs;
}

// Turns one frame's world body about the vertical to face +Z around its root and appends it,
// with the root and the heading removed. `heading` carries the last measured facing over frames
// where it cannot be measured (hips and shoulders seen end-on).
void add_body_frame(std::array<glm::vec3, kBodyJoints> body, float& heading, ClipFrames& out) {
  facing(body, heading);
  const glm::vec3 root = body[index(Joint::root)];
  const glm::quat turn = glm::angleAxis(-heading, glm::vec3(0, 1, 0));
  for (auto& p : body) p = turn * (p - root);
  out.joints.push_back(body);
  out.frames.push_back(
      {0, static_cast<std::uint32_t>(out.frames.size()), heading, {root.x, root.y, root.z}});
}

// What the canonical body adds to a clip's mapping text.
std::string canonical_note() {
  return "; rescaled to the canonical body (" + motion::describe(motion::canonical_proportions()) +
         "; bone directions kept, shoulders re-hung from the neck, hips symmetric about the root)";
}

void add_run(const motion::PoseSequence& poses, const motion::BodyMapping& mapping,
             BodyChoice choice, ClipFrames& out) {
  motion::GlobalPose global;
  float heading = 0.0f;
  const int joints = poses.joint_count();
  for (int f = 0; f < poses.frame_count; ++f) {
    motion::forward_kinematics(poses, f, global);
    std::array<glm::vec3, kBodyJoints> body;
    motion::body_positions(mapping, global, body);
    if (choice == BodyChoice::canonical)
      body = motion::retarget(body, motion::canonical_proportions());
    add_body_frame(body, heading, out);
    for (int j = 0; j < joints; ++j) {
      const glm::quat q = poses.rotation[poses.at(f, j)];
      out.rotations.insert(out.rotations.end(), {q.w, q.x, q.y, q.z});
    }
  }
}

std::vector<ClipFrames> read_clips(const std::string& file, const BuildOptions& options,
                                   BuildReport& report, std::mutex& m) {
  const motion::Clip clip = read_clip(file);
  const motion::BodyMapping mapping = motion::map_to_body(clip.skeleton, clip.source);
  const bool is_amc = file.find('|') != std::string::npos;
  const auto runs = capture_runs(clip, mapping.first_frame_is_reference && !is_amc, report, m);
  const motion::PoseSequence all = motion::to_poses(clip);
  std::vector<ClipFrames> out;
  for (const auto& [first, count] : runs) {
    ClipFrames c;
    const fs::path path(is_amc ? file.substr(file.find('|') + 1) : file);
    c.info.name = path.filename().string();
    if (!out.empty())
      c.info.name.append("#").append(std::to_string(out.size() + 1));  // a later run of the file
    c.info.source = path.string();
    c.info.family = std::string(motion::family_name(mapping.family));
    c.info.mapping = mapping.notes;
    if (options.body == BodyChoice::canonical) c.info.mapping += canonical_note();
    c.info.source_fps = clip.fps();
    c.info.source_first_frame = static_cast<std::uint32_t>(first);
    c.info.metres_per_unit = mapping.metres_per_unit;
    c.info.skeleton = clip.skeleton;
    add_run(motion::resample(motion::slice(all, first, count), options.fps), mapping, options.body,
            c);
    c.info.frame_count = static_cast<std::uint32_t>(c.frames.size());
    out.push_back(std::move(c));
  }
  return out;
}

// Reads every file on `threads` threads; keeps the input order in the result.
std::vector<ClipFrames> read_all(const std::vector<std::string>& files, const BuildOptions& options,
                                 const BuildProgress& progress, BuildReport& report) {
  std::vector<std::vector<ClipFrames>> per_file(files.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex m;
  auto work = [&] {
    for (std::size_t i; (i = next++) < files.size();) {
      try {
        per_file[i] = read_clips(files[i], options, report, m);
      } catch (const std::exception& e) {
        std::lock_guard lock(m);
        report.skipped.push_back(e.what());
      }
      const std::size_t d = ++done;
      std::lock_guard lock(m);
      if (progress) progress("read", static_cast<double>(d) / static_cast<double>(files.size()));
    }
  };
  std::vector<std::jthread> pool;
  for (int t = 1; t < std::max(1, options.threads); ++t) pool.emplace_back(work);
  work();
  pool.clear();
  std::vector<ClipFrames> clips;
  for (auto& f : per_file) {
    for (auto& c : f) clips.push_back(std::move(c));
  }
  report.files_read = files.size() - report.skipped.size();
  std::sort(report.skipped.begin(), report.skipped.end());
  return clips;
}

// Why a position-only sequence cannot be used, or empty when it can.
std::string unusable(const BodySequence& sequence) {
  if (sequence.frames.empty()) return "no frames";
  if (!(sequence.fps > 0.0 && sequence.fps <= 1000.0)) return "frame rate not in (0, 1000]";
  for (std::size_t f = 0; f < sequence.frames.size(); ++f) {
    for (const glm::vec3& p : sequence.frames[f]) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return "non-finite joint position in frame " + std::to_string(f);
    }
  }
  return {};
}

// A position-only sequence as a clip without skeleton or rotations.
ClipFrames clip_from_bodies(const BodySequence& sequence, const BuildOptions& options) {
  ClipFrames c;
  c.info.name = sequence.name;
  c.info.source = sequence.source;
  c.info.family = sequence.family;
  c.info.mapping = sequence.mapping;
  if (options.body == BodyChoice::canonical) c.info.mapping += canonical_note();
  c.info.source_fps = sequence.fps;
  float heading = 0.0f;
  for (const auto& body :
       motion::resample_points(std::span<const std::array<glm::vec3, kBodyJoints>>(sequence.frames),
                               sequence.fps, options.fps)) {
    add_body_frame(options.body == BodyChoice::canonical
                       ? motion::retarget(body, motion::canonical_proportions())
                       : body,
                   heading, c);
  }
  c.info.frame_count = static_cast<std::uint32_t>(c.frames.size());
  return c;
}

std::vector<ClipFrames> clips_from_bodies(const std::vector<BodySequence>& sequences,
                                          const BuildOptions& options,
                                          const BuildProgress& progress, BuildReport& report) {
  std::vector<ClipFrames> clips;
  for (std::size_t i = 0; i < sequences.size(); ++i) {
    if (const std::string why = unusable(sequences[i]); !why.empty()) {
      report.skipped.push_back(sequences[i].name + ": " + why);
    } else {
      clips.push_back(clip_from_bodies(sequences[i], options));
    }
    if (progress)
      progress("read", static_cast<double>(i + 1) / static_cast<double>(sequences.size()));
  }
  report.files_read = clips.size();
  std::sort(report.skipped.begin(), report.skipped.end());
  return clips;
}

void gather(std::vector<ClipFrames>& clips, DatabaseContents& db,
            std::vector<std::array<glm::vec3, kBodyJoints>>& joints) {
  for (auto& c : clips) {
    c.info.first_frame = static_cast<std::uint32_t>(db.frames.size());
    c.info.rotation_offset = db.rotations.size() / 4;
    for (auto& f : c.frames) {
      f.clip = static_cast<std::uint32_t>(db.clips.size());
      db.frames.push_back(f);
    }
    for (const auto& body : c.joints) {
      joints.push_back(body);
      for (const auto& p : body) db.joints.insert(db.joints.end(), {p.x, p.y, p.z});
    }
    db.rotations.insert(db.rotations.end(), c.rotations.begin(), c.rotations.end());
    db.clips.push_back(std::move(c.info));
  }
}

// Projects every frame through every view; rows in (frame, view) order.
void project_all(const std::vector<std::array<glm::vec3, kBodyJoints>>& joints,
                 const BuildOptions& options, DatabaseContents& db, const BuildProgress& progress,
                 BuildReport& report) {
  std::vector<camera::Camera> cameras;
  for (const View& v : db.views) cameras.push_back(view_camera(v, options.views.root_height_m));
  db.projections.reserve(joints.size() * cameras.size() * kPoseDims);
  db.projection_records.reserve(joints.size() * cameras.size());
  std::array<glm::vec2, kBodyJoints> image;
  PoseVector row;
  for (std::size_t f = 0; f < joints.size(); ++f) {
    for (std::size_t v = 0; v < cameras.size(); ++v) {
      project_body(joints[f], cameras[v], image);
      if (!normalize_pose(image, options.scaling, row)) {
        ++report.projections_dropped;
        continue;
      }
      db.projections.insert(db.projections.end(), row.begin(), row.end());
      db.projection_records.push_back(
          {static_cast<std::uint32_t>(f), static_cast<std::uint32_t>(v)});
    }
    if (progress && f % 512 == 0)
      progress("project", static_cast<double>(f) / static_cast<double>(joints.size()));
  }
  if (progress) progress("project", 1.0);
}

// Clusters the rows (the paper's clusters with representatives) and stores them grouped by cluster.
void cluster(const BuildOptions& options, DatabaseContents& db, const BuildProgress& progress) {
  const std::size_t rows = db.projection_records.size();
  const int k = options.clusters > 0
                    ? options.clusters
                    : std::max(16, static_cast<int>(std::sqrt(static_cast<double>(rows))));
  KMeansOptions km;
  km.clusters = static_cast<int>(
      std::min<std::size_t>(static_cast<std::size_t>(k), std::max<std::size_t>(rows, 1)));
  km.iterations = options.kmeans_iterations;
  km.sample_size = options.kmeans_sample;
  km.seed = options.seed;
  km.threads = options.threads;
  km.progress = [&](double f) {
    if (progress) progress("cluster", f);
  };
  const MatrixView data{db.projections.data(), rows, kPoseDims};
  const KMeansResult result = kmeans(data, km);
  const ClusterOrder order = group_by_cluster(result.assignment, result.clusters());
  std::vector<float> sorted(db.projections.size());
  std::vector<ProjectionRecord> records(rows);
  for (std::size_t i = 0; i < rows; ++i) {
    const std::size_t from = order.permutation[i];
    std::copy_n(db.projections.begin() + static_cast<std::ptrdiff_t>(from * kPoseDims), kPoseDims,
                sorted.begin() + static_cast<std::ptrdiff_t>(i * kPoseDims));
    records[i] = db.projection_records[from];
  }
  db.projections = std::move(sorted);
  db.projection_records = std::move(records);
  db.centroids = result.centroids;
  db.cluster_begin = order.cluster_begin;
}

std::string now_iso() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

void check_fps(const BuildOptions& options) {
  if (!(options.fps > 0.0 && options.fps <= 1000.0))
    throw InputError("--fps", "must be between 0 and 1000");
}

// The steps after reading, shared by every kind of input: gather the clips, project every frame
// through every view, cluster, record the options. `inputs` names what was read, for the error.
DatabaseContents assemble(std::vector<ClipFrames>& clips, const BuildOptions& options,
                          const BuildProgress& progress, BuildReport& report,
                          const std::string& inputs,
                          std::chrono::steady_clock::time_point started) {
  DatabaseContents db;
  db.views = make_views(options.views);
  std::vector<std::array<glm::vec3, kBodyJoints>> joints;
  gather(clips, db, joints);
  if (db.frames.empty()) {
    throw InputError("",
                     "no usable motion in " + inputs +
                         (report.skipped.empty() ? std::string()
                                                 : "; first problem: " + report.skipped.front()));
  }
  project_all(joints, options, db, progress, report);
  cluster(options, db, progress);
  db.build.fps = options.fps;
  db.build.scaling = options.scaling;
  db.build.body = options.body;
  db.build.views = options.views;
  db.build.clusters = static_cast<int>(db.cluster_begin.size()) - 1;
  db.build.seed = options.seed;
  db.build.created = now_iso();
  db.build.command = options.command;
  db.build.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return db;
}

}  // namespace

std::vector<std::string> collect_motion_files(const std::vector<std::string>& paths) {
  std::set<std::string> files;
  for (const auto& p : paths) {
    const fs::path path(p);
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      for (const auto& e :
           fs::recursive_directory_iterator(path, fs::directory_options::skip_permission_denied)) {
        if (e.is_regular_file()) add_file(e.path(), files);
      }
    } else if (fs::is_regular_file(path, ec)) {
      const std::string ext = lower_extension(path);
      if (ext != ".bvh" && ext != ".amc")
        throw InputError(p, "not a motion file (expected .bvh, or .amc with its .asf)");
      add_file(path, files);
    } else {
      throw InputError(p, "no such file or folder");
    }
  }
  return {files.begin(), files.end()};
}

DatabaseContents build_database(const std::vector<std::string>& files, const BuildOptions& options,
                                const BuildProgress& progress, BuildReport& report) {
  check_fps(options);
  const auto started = std::chrono::steady_clock::now();
  std::vector<ClipFrames> clips = read_all(files, options, progress, report);
  return assemble(clips, options, progress, report, std::to_string(files.size()) + " file(s)",
                  started);
}

DatabaseContents build_database_from_bodies(const std::vector<BodySequence>& sequences,
                                            const BuildOptions& options,
                                            const BuildProgress& progress, BuildReport& report) {
  check_fps(options);
  const auto started = std::chrono::steady_clock::now();
  std::vector<ClipFrames> clips = clips_from_bodies(sequences, options, progress, report);
  return assemble(clips, options, progress, report,
                  std::to_string(sequences.size()) + " sequence(s)", started);
}

std::vector<std::string> split_files(const std::string& folder, const std::string& split) {
  std::ifstream list(std::filesystem::path(folder) / "splits.txt");
  if (!list)
    throw InputError(folder,
                     "no splits.txt here: give the cmu31 folder of the shared data (--mocap)");
  std::vector<std::string> files;
  std::string which, file;
  while (list >> which >> file) {
    if (which == split) files.push_back((std::filesystem::path(folder) / file).string());
  }
  return files;
}

}  // namespace mocap::posedb
