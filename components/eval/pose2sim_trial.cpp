#include "eval/pose2sim_trial.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "core/keypoint_layout.hpp"
#include "io/openpose_json.hpp"
#include "io/trc.hpp"
#include "motion/pose_sequence.hpp"

namespace mocap::eval {
namespace fs = std::filesystem;
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

fs::path reference_trc(const fs::path& pose3d) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(pose3d, ec))
    if (entry.path().filename().string().ends_with("_filt_butterworth.trc")) return entry.path();
  throw InputError(pose3d.string(), "no *_filt_butterworth.trc file (Pose2Sim's filtered 3D)");
}

recon::BodyXyc body_of(const Person2D& person, LayoutId layout) {
  std::vector<float> xyc;
  for (const Keypoint2D& k : person.joints) xyc.insert(xyc.end(), {k.x, k.y, k.confidence});
  recon::BodyXyc body{};
  mocap::to_body15(mocap::layout(layout), xyc, body);
  return body;
}

// Median pixel distance of the present joints to the projected reference; NaN if none.
double median(std::vector<double> d);

double distance_to(const recon::BodyXyc& body, const std::array<glm::dvec2, kBodyJoints>& ref) {
  std::vector<double> d;
  for (int j = 0; j < kBodyJoints; ++j)
    if (body[3 * j + 2] > 0 && std::isfinite(body[3 * j]) && std::isfinite(ref[j].x))
      d.push_back(glm::distance(glm::dvec2(body[3 * j], body[3 * j + 1]), ref[j]));
  return median(d);
}

// BODY_25B keypoint index of each TRC marker that is one.
std::vector<std::pair<std::size_t, int>> marker_keypoints(const io::TrcFile& trc) {
  std::vector<std::pair<std::size_t, int>> out;
  for (std::size_t m = 0; m < trc.markers.size(); ++m)
    if (const int k = pose2sim_marker_keypoint(trc.markers[m]); k >= 0) out.emplace_back(m, k);
  return out;
}

double median(std::vector<double> d) {
  if (d.empty()) return kNan;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

}  // namespace

std::vector<fs::path> pose2sim_json_folders(const fs::path& trial, std::size_t cameras,
                                            const fs::path& calibration) {
  const fs::path pose = trial / "pose";
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(pose, ec))
    if (entry.is_directory() && entry.path().filename().string().ends_with("_json"))
      out.push_back(entry.path());
  if (ec) throw InputError(pose.string(), "cannot be listed: " + ec.message());
  std::sort(out.begin(), out.end());
  if (out.size() != cameras)
    throw InputError(pose.string(), std::to_string(out.size()) + " camXX_json folders for " +
                                        std::to_string(cameras) + " cameras in " +
                                        calibration.string());
  return out;
}

int pose2sim_marker_keypoint(std::string_view marker) {
  if (marker == "Neck") marker = "UpperNeck";
  if (marker == "Head") marker = "HeadTop";
  const KeypointLayout& layout = mocap::layout(LayoutId::body25b);
  for (std::size_t k = 0; k < layout.keypoints.size(); ++k)
    if (layout.keypoints[k] == marker) return static_cast<int>(k);
  return -1;
}

glm::dvec3 trc_to_world(const glm::vec3& trc) { return {trc.z, trc.x, trc.y}; }

Pose2SimTrial load_pose2sim_trial(const fs::path& trial, const fs::path& calibration,
                                  std::size_t max_frames) {
  Pose2SimTrial out;
  out.folder = trial.string();
  const auto cameras = camera::read_rig(calibration).cameras;
  const auto folders = pose2sim_json_folders(trial, cameras.size(), calibration);
  const fs::path trc_path = reference_trc(trial / "pose-3d");
  out.reference_file = trc_path.string();
  const io::TrcFile trc = io::read_trc(trc_path);
  out.fps = trc.rate;
  // Body15 from the markers as the BODY_25B layout makes it (core/keypoint_layout.cpp).
  constexpr std::array<std::string_view, kBodyJoints> kMarkerOf = {
      "Head", "Neck",  "RShoulder", "RElbow", "RWrist", "LShoulder", "LElbow", "LWrist",
      "RHip", "RKnee", "RAnkle",    "LHip",   "LKnee",  "LAnkle",    ""};
  std::array<std::size_t, kBodyJoints> column{};
  for (int j = 0; j + 1 < kBodyJoints; ++j) {
    const auto m = trc.marker(kMarkerOf[j]);
    if (!m) throw InputError(out.reference_file, "no marker '" + std::string(kMarkerOf[j]) + "'");
    column[j] = *m;
  }
  for (const auto& frame : trc.frames) {
    Body world;
    for (int j = 0; j + 1 < kBodyJoints; ++j) world[j] = glm::vec3(trc_to_world(frame[column[j]]));
    world[index(Joint::root)] =
        0.5f * (world[index(Joint::right_hip)] + world[index(Joint::left_hip)]);
    out.truth_world.push_back(world);
  }
  if (max_frames > 0 && out.truth_world.size() > max_frames) out.truth_world.resize(max_frames);

  const auto markers = marker_keypoints(trc);
  io::OpenPoseOptions options;
  options.body25 = io::Body25Choice::body25b;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    Pose2SimView view;
    view.camera = cameras[c];
    view.json_folder = folders[c].string();
    const io::OpenPoseSequence json = io::read_openpose_folder(folders[c], options);
    if (json.first_frame != 0 || json.frames.size() < out.truth_world.size())
      throw InputError(view.json_folder, "frames " + std::to_string(json.first_frame) + ".. do " +
                                             "not cover the " +
                                             std::to_string(out.truth_world.size()) +
                                             " frames of " + out.reference_file);
    for (std::size_t t = 0; t < out.truth_world.size(); ++t) {
      std::array<glm::dvec2, kBodyJoints> ref;
      Body cam;
      for (int j = 0; j < kBodyJoints; ++j) {
        const glm::dvec3 w(out.truth_world[t][j]);
        ref[j] = view.camera.project_pinhole(w);
        cam[j] = glm::vec3(view.camera.to_camera(w));
      }
      view.truth_camera.push_back(cam);
      const auto& people = json.frames[t].people;
      view.people.push_back(static_cast<int>(people.size()));
      recon::BodyXyc best{};
      double best_d = kNan;
      const Person2D* chosen = nullptr;
      for (const Person2D& person : people) {
        const recon::BodyXyc body = body_of(person, json.layout);
        const double d = distance_to(body, ref);
        if (std::isfinite(d) && !(d >= best_d)) best = body, best_d = d, chosen = &person;
      }
      view.input.push_back(best);
      view.reprojection_px.push_back(best_d);
      std::vector<double> marker_d;
      if (chosen)
        for (const auto& [m, k] : markers) {
          if (k >= static_cast<int>(chosen->joints.size())) continue;
          const Keypoint2D& kp = chosen->joints[k];
          const glm::vec3& p = trc.frames[t][m];
          if (!(kp.confidence > 0) || !std::isfinite(p.x)) continue;
          marker_d.push_back(
              glm::distance(view.camera.project_pinhole(trc_to_world(p)), glm::dvec2(kp.x, kp.y)));
        }
      view.marker_reprojection_px.push_back(median(marker_d));
    }
    out.views.push_back(std::move(view));
  }
  return out;
}

std::vector<recon::BodyXyc> resample_keypoints(const std::vector<recon::BodyXyc>& frames,
                                               double from_fps, double to_fps) {
  std::vector<recon::BodyXyc> out;
  for (const motion::ResampleStep& s :
       motion::resample_steps(static_cast<int>(frames.size()), from_fps, to_fps)) {
    const recon::BodyXyc& a = frames[s.before];
    const recon::BodyXyc& b = frames[s.after];
    recon::BodyXyc& o = out.emplace_back();
    for (int j = 0; j < kBodyJoints; ++j) {
      const bool has_a = a[3 * j + 2] > 0, has_b = b[3 * j + 2] > 0;
      const float w = s.weight;
      if (has_a && has_b) {
        for (int k = 0; k < 3; ++k) o[3 * j + k] = (1 - w) * a[3 * j + k] + w * b[3 * j + k];
      } else if (has_a && w <= 1e-6f) {
        for (int k = 0; k < 3; ++k) o[3 * j + k] = a[3 * j + k];
      } else if (has_b && w >= 1 - 1e-6f) {
        for (int k = 0; k < 3; ++k) o[3 * j + k] = b[3 * j + k];
      } else {
        o[3 * j] = o[3 * j + 1] = std::numeric_limits<float>::quiet_NaN();
        o[3 * j + 2] = 0.0f;
      }
    }
  }
  return out;
}

std::vector<Body> resample_bodies(const std::vector<Body>& frames, double from_fps, double to_fps) {
  return motion::resample_points(std::span<const Body>(frames), from_fps, to_fps);
}

}  // namespace mocap::eval
