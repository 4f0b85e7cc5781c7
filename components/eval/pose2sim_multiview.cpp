#include "eval/pose2sim_multiview.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <glm/geometric.hpp>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "core/keypoint_layout.hpp"
#include "eval/pose2sim_trial.hpp"
#include "fit/track_fit.hpp"
#include "io/openpose_json.hpp"
#include "io/trc.hpp"
#include "multiview/reconstructor.hpp"
#include "multiview/rig_reconstruction.hpp"

namespace mocap::eval {
namespace {

constexpr float kLikelihoodThreshold = 0.3f;  // Pose2Sim's, for the "all views" errors

glm::dmat3 intrinsic_matrix(const camera::Camera& c) {
  const std::array<double, 9> rows = c.matrix();
  glm::dmat3 k(1.0);  // GLM is column-major, Camera::matrix() row-major
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) k[col][r] = rows[static_cast<std::size_t>(3 * r + col)];
  return k;
}

std::filesystem::path raw_trc(const std::filesystem::path& trial) {
  const std::filesystem::path folder = trial / "pose-3d";
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".trc" && name.find("_filt") == std::string::npos)
      return entry.path();
  }
  throw InputError(folder.string(), "no raw triangulation TRC (*.trc without _filt) here");
}

// The body joint that is keypoint k itself (not a midpoint), or -1: the markers a fitted body
// (15 joints) can be compared on.
int body_joint_of(const multiview::KeypointSet& set, int k) {
  for (int j = 0; j < kBodyJoints; ++j)
    if (set.body[j].first == k && set.body[j].second < 0) return j;
  return -1;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::vector<float> finite_only(const std::vector<float>& v) {
  std::vector<float> out;
  for (float x : v)
    if (std::isfinite(x)) out.push_back(x);
  return out;
}

}  // namespace

void Pose2SimDemo::observations(std::size_t i, multiview::FrameObservations& out) const {
  out.reset(static_cast<int>(views.size()), 25);
  std::vector<std::array<float, 2>> pixels;
  for (std::size_t c = 0; c < views.size(); ++c) {
    if (i >= json[c].frames.size()) continue;
    for (const Person2D& person : json[c].frames[i].people) {
      const std::span<float> xyc = out.add_person(static_cast<int>(c));
      pixels.clear();
      for (const Keypoint2D& k : person.joints) pixels.push_back({k.x, k.y});
      cameras[c].undistort_pixels(pixels);
      for (std::size_t k = 0; k < person.joints.size() && k < 25; ++k) {
        xyc[3 * k] = pixels[k][0];
        xyc[3 * k + 1] = pixels[k][1];
        xyc[3 * k + 2] = person.joints[k].confidence;
      }
    }
  }
}

bool Pose2SimDemo::confident(std::size_t i, std::size_t c, int d, int k) const {
  if (d < 0) return false;
  return json[c]
             .frames[i]
             .people[static_cast<std::size_t>(d)]
             .joints[static_cast<std::size_t>(k)]
             .confidence >= kLikelihoodThreshold;
}

float Pose2SimDemo::error_px(std::size_t i, std::size_t c, int d, int k,
                             const glm::dvec3& world) const {
  if (!confident(i, c, d, k)) return std::nanf("");
  const Keypoint2D& kp = json[c].frames[i].people[static_cast<std::size_t>(d)].joints[k];
  const glm::dvec2 p = cameras[c].project(world);
  return std::isfinite(p.x) ? static_cast<float>(glm::distance(p, glm::dvec2(kp.x, kp.y)))
                            : std::nanf("");
}

float Pose2SimDemo::error_all_px(std::size_t i, std::span<const int> detections, int k,
                                 const glm::dvec3& world) const {
  double sum = 0.0;
  int n = 0;
  for (std::size_t c = 0; c < detections.size(); ++c) {
    const float e = error_px(i, c, detections[c], k, world);
    if (std::isfinite(e)) sum += e, ++n;
  }
  return n > 0 ? static_cast<float>(sum / n) : std::nanf("");
}

Pose2SimDemo load_pose2sim_demo(const std::filesystem::path& trial,
                                const std::filesystem::path& calibration, std::size_t max_frames) {
  Pose2SimDemo d;
  d.trial = trial.string();
  d.calibration = calibration.string();
  const camera::Rig rig = camera::read_rig(calibration);
  d.cameras = rig.cameras;
  d.floor = multiview::rig_floor(rig);
  for (const auto& c : d.cameras)
    d.views.push_back(
        multiview::ViewGeometry::from_krt(intrinsic_matrix(c), c.rotation, c.translation));
  const auto folders = pose2sim_json_folders(trial, d.cameras.size(), calibration);
  io::OpenPoseOptions options;
  options.body25 = io::Body25Choice::body25b;
  for (const auto& f : folders) d.json.push_back(io::read_openpose_folder(f, options));
  d.trc = io::read_trc(raw_trc(trial));
  d.frames = d.trc.frames.size();
  if (max_frames > 0) d.frames = std::min(d.frames, max_frames);
  return d;
}

Pose2SimRun run_pose2sim_demo(const Pose2SimDemo& demo, std::string name,
                              const multiview::ReconstructionOptions& o, bool fit,
                              const Pose2SimFrameObserver& observe) {
  multiview::ReconstructionOptions options = o;
  options.tracker.fps = static_cast<float>(demo.trc.rate);
  const multiview::KeypointSet set = multiview::KeypointSet::of(layout(LayoutId::body25b));
  multiview::MultiViewReconstructor reconstructor(demo.views, set, options);
  Pose2SimRun out;
  out.name = std::move(name);
  out.fitted = fit;
  out.markers.resize(demo.trc.markers.size());
  for (auto& m : out.markers) m.left_out.assign(demo.views.size(), 0);
  out.limb_lengths.resize(pose2sim_limbs().size());
  const auto rhip = demo.trc.marker("RHip"), lhip = demo.trc.marker("LHip");
  if (!rhip || !lhip) throw InputError(demo.trc.path, "no RHip and LHip markers");
  std::vector<multiview::FrameObservations> observations(demo.frames);
  std::vector<multiview::FrameResult> results;
  for (std::size_t i = 0; i < demo.frames; ++i) {
    demo.observations(i, observations[i]);
    results.push_back(reconstructor.process(observations[i], static_cast<std::int64_t>(i)));
  }
  std::vector<multiview::FrameResult> triangulated;  // the fit's input, to measure its moves
  if (fit) {
    triangulated = results;
    fit::MultiViewFitOptions f;
    f.cameras = demo.cameras;
    f.fit = fit::multiview_fit_defaults();
    f.fit.ground = demo.floor;
    fit::fit_tracks(observations, results, f, false, set);
  }
  // A point of the reconstruction for keypoint k of person p: the keypoint, or with the fit the
  // body joint it is (nullptr: none).
  const auto point = [&](const multiview::FrameResult& r, std::size_t p,
                         int k) -> const multiview::TriangulatedPoint* {
    if (k < 0) return nullptr;
    if (!fit) return &r.keypoints_of(p)[static_cast<std::size_t>(k)];
    const int j = body_joint_of(set, k);
    return j < 0 ? nullptr : &r.body_of(p)[static_cast<std::size_t>(j)];
  };
  for (std::size_t i = 0; i < demo.frames; ++i) {
    const multiview::FrameResult& r = results[i];
    out.outside_people += r.outside_people;
    const glm::vec3 hips(
        0.5 * (trc_to_world(demo.trc.frames[i][*rhip]) + trc_to_world(demo.trc.frames[i][*lhip])));
    int participant = -1;
    float nearest = 0.5f;
    for (std::size_t p = 0; p < r.people.size(); ++p) {
      const float d = glm::distance(multiview::body_centre(r.body_of(p)), hips);
      if (d < nearest) {
        nearest = d;
        participant = static_cast<int>(p);
      }
    }
    out.other_people += static_cast<int>(r.people.size()) - (participant >= 0);
    if (observe) observe(i, r, participant);
    if (participant < 0) continue;
    ++out.frames_with_participant;
    const auto p = static_cast<std::size_t>(participant);
    const auto detections = r.detections_of(p);
    for (std::size_t l = 0; l < pose2sim_limbs().size(); ++l) {
      const auto* a = point(r, p, pose2sim_marker_keypoint(pose2sim_limbs()[l].first));
      const auto* b = point(r, p, pose2sim_marker_keypoint(pose2sim_limbs()[l].second));
      if (a && b && a->valid() && b->valid())
        out.limb_lengths[l].push_back(glm::distance(a->position, b->position));
    }
    const auto* right_hip = point(r, p, pose2sim_marker_keypoint("RHip"));
    const auto* left_hip = point(r, p, pose2sim_marker_keypoint("LHip"));
    if (right_hip && left_hip && right_hip->valid() && left_hip->valid())
      out.hip_width_m.push_back(glm::distance(right_hip->position, left_hip->position));
    for (std::size_t m = 0; m < demo.trc.markers.size(); ++m) {
      const int k = pose2sim_marker_keypoint(demo.trc.markers[m]);
      const multiview::TriangulatedPoint* ours = point(r, p, k);
      if (!ours || !ours->valid()) continue;
      Pose2SimMarkerStats& s = out.markers[m];
      if (fit) {
        const multiview::TriangulatedPoint& before =
            triangulated[i].keypoints_of(p)[static_cast<std::size_t>(k)];
        if (before.valid())
          s.from_triangulated_m.push_back(glm::distance(ours->position, before.position));
      } else {
        for (std::size_t c = 0; c < detections.size(); ++c)
          if (demo.confident(i, c, detections[c], k) && !(ours->views & (std::uint64_t{1} << c))) {
            ++s.left_out[c];
            s.left_out_error_px.push_back(
                demo.error_px(i, c, detections[c], k, glm::dvec3(ours->position)));
          }
      }
      const glm::dvec3 theirs = trc_to_world(demo.trc.frames[i][m]);
      s.trc_error_all_px.push_back(demo.error_all_px(i, detections, k, theirs));
      s.distance_m.push_back(glm::distance(ours->position, glm::vec3(theirs)));
      s.views.push_back(static_cast<float>(ours->view_count()));
      // A fitted joint is not triangulated from chosen views: no "views used" error.
      s.error_used_px.push_back(fit ? std::nanf("") : ours->error_px);
      s.error_all_px.push_back(demo.error_all_px(i, detections, k, glm::dvec3(ours->position)));
    }
  }
  return out;
}

namespace {

// "a/b/c": counts or names joined by slashes.
template <class T>
std::string joined(const std::vector<T>& items) {
  std::ostringstream s;
  for (std::size_t i = 0; i < items.size(); ++i) s << (i ? "/" : "") << items[i];
  return s.str();
}

// Per marker: the frames in which each camera saw the keypoint (confidence >= 0.3) but a
// triangulation left it out, and how far the fit moved the point from our triangulation.
std::string views_left_out_table(const Pose2SimComparison& c) {
  std::ostringstream s;
  s << "\nViews left out: frames in which a camera saw the participant's keypoint (confidence >= "
       "0.3) but the point was not triangulated from it, per camera ("
    << joined(c.cameras)
    << "; in brackets the median distance of the point's projection to the keypoints left out); "
       "and how far the skeleton fit moved each point from our triangulation.\n\n"
    << "| marker |";
  for (const Pose2SimRun& r : c.runs)
    if (!r.fitted) s << " " << r.name << " |";
  s << " fit − ours triangulated, median mm |\n|---|";
  for (const Pose2SimRun& r : c.runs)
    if (!r.fitted) s << "---|";
  s << "---:|\n";
  for (std::size_t m = 0; m < c.markers.size(); ++m) {
    s << "| " << c.markers[m] << " |";
    std::vector<float> moved;
    for (const Pose2SimRun& r : c.runs) {
      const Pose2SimMarkerStats& stats = r.markers[m];
      if (r.fitted) {
        moved.insert(moved.end(), stats.from_triangulated_m.begin(),
                     stats.from_triangulated_m.end());
        continue;
      }
      const float error = median_of(stats.left_out_error_px);
      s << " " << joined(stats.left_out);
      if (std::isfinite(error)) s << " (" << fixed(error, 0) << " px)";
      s << " |";
    }
    const float median = median_of(moved);
    s << " " << (std::isfinite(median) ? fixed(1000 * median, 1) : "–") << " |\n";
  }
  return s.str();
}

}  // namespace

float median_of(std::vector<float> v) {
  v = finite_only(v);
  if (v.empty()) return std::nanf("");
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

float mean_of(const std::vector<float>& v) {
  double s = 0.0;
  std::size_t n = 0;
  for (const float x : v)
    if (std::isfinite(x)) s += x, ++n;
  return n == 0 ? std::nanf("") : static_cast<float>(s / static_cast<double>(n));
}

float limb_std_m(const std::vector<std::vector<float>>& lengths) {
  double sum = 0.0;
  int limbs = 0;
  for (const auto& l : lengths) {
    if (l.size() < 2) continue;
    const float m = mean_of(l);
    double var = 0.0;
    for (const float x : l) var += (x - m) * (x - m);
    sum += std::sqrt(var / static_cast<double>(l.size()));
    ++limbs;
  }
  return limbs > 0 ? static_cast<float>(sum / limbs) : std::nanf("");
}

const std::vector<std::pair<std::string, std::string>>& pose2sim_limbs() {
  static const std::vector<std::pair<std::string, std::string>> limbs = {
      {"RHip", "RKnee"},       {"RKnee", "RAnkle"},  {"LHip", "LKnee"},       {"LKnee", "LAnkle"},
      {"RShoulder", "RElbow"}, {"RElbow", "RWrist"}, {"LShoulder", "LElbow"}, {"LElbow", "LWrist"}};
  return limbs;
}

Pose2SimMarkerStats pooled(const Pose2SimRun& run) {
  Pose2SimMarkerStats all;
  for (const auto& m : run.markers) {
    all.distance_m.insert(all.distance_m.end(), m.distance_m.begin(), m.distance_m.end());
    all.views.insert(all.views.end(), m.views.begin(), m.views.end());
    all.error_used_px.insert(all.error_used_px.end(), m.error_used_px.begin(),
                             m.error_used_px.end());
    all.error_all_px.insert(all.error_all_px.end(), m.error_all_px.begin(), m.error_all_px.end());
    all.trc_error_all_px.insert(all.trc_error_all_px.end(), m.trc_error_all_px.begin(),
                                m.trc_error_all_px.end());
  }
  return all;
}

Pose2SimComparison pose2sim_comparison(const Pose2SimDemo& demo) {
  Pose2SimComparison c;
  c.trial = demo.trial;
  c.calibration = demo.calibration;
  c.reference = demo.trc.path;
  c.frames = demo.frames;
  c.markers = demo.trc.markers;
  for (const auto& camera : demo.cameras) c.cameras.push_back(camera.name);
  c.trc_limb_lengths.resize(pose2sim_limbs().size());
  const auto trc_rhip = demo.trc.marker("RHip"), trc_lhip = demo.trc.marker("LHip");
  for (std::size_t i = 0; i < demo.frames; ++i) {
    if (trc_rhip && trc_lhip)
      c.trc_hip_width_m.push_back(
          glm::distance(demo.trc.frames[i][*trc_rhip], demo.trc.frames[i][*trc_lhip]));
    for (std::size_t l = 0; l < pose2sim_limbs().size(); ++l) {
      const auto a = demo.trc.marker(pose2sim_limbs()[l].first);
      const auto b = demo.trc.marker(pose2sim_limbs()[l].second);
      if (a && b)
        c.trc_limb_lengths[l].push_back(
            glm::distance(demo.trc.frames[i][*a], demo.trc.frames[i][*b]));
    }
  }
  return c;
}

Pose2SimComparison compare_with_pose2sim(const std::filesystem::path& trial,
                                         const std::filesystem::path& calibration,
                                         std::size_t max_frames) {
  const Pose2SimDemo demo = load_pose2sim_demo(trial, calibration, max_frames);
  Pose2SimComparison c = pose2sim_comparison(demo);
  c.runs.push_back(run_pose2sim_demo(demo, "ours", {}));
  multiview::ReconstructionOptions no_prior;
  no_prior.tracker.prior = false;
  c.runs.push_back(run_pose2sim_demo(demo, "ours without the tracks' prior", no_prior));
  multiview::ReconstructionOptions rule;
  rule.triangulation.method = multiview::TriangulationMethod::pose2sim;
  c.runs.push_back(run_pose2sim_demo(demo, "Pose2Sim's rule (ours)", rule));
  c.runs.push_back(run_pose2sim_demo(demo, "ours + skeleton fit (full)", {}, true));
  return c;
}

std::string pose2sim_table(const Pose2SimComparison& c) {
  std::ostringstream s;
  s << c.frames << " frames of " << c.trial << " against " << c.reference << "\n\n";
  s << "| marker | reconstruction | − TRC median mm | mean mm | views used | error px (views "
       "used) | error px (all confident views) | TRC's error px (same views) |\n"
    << "|---|---|---:|---:|---:|---:|---:|---:|\n";
  const auto row = [&](const std::string& marker, const Pose2SimRun& r,
                       const Pose2SimMarkerStats& m) {
    if (m.distance_m.empty()) return;  // a marker this reconstruction does not have
    s << "| " << marker << " | " << r.name << " | " << fixed(1000 * median_of(m.distance_m), 1)
      << " | " << fixed(1000 * mean_of(m.distance_m), 1) << " | " << fixed(mean_of(m.views), 2)
      << " | "
      << (std::isfinite(mean_of(m.error_used_px)) ? fixed(mean_of(m.error_used_px), 1) : "–")
      << " | " << fixed(mean_of(m.error_all_px), 1) << " | "
      << fixed(mean_of(m.trc_error_all_px), 1) << " |\n";
  };
  for (std::size_t m = 0; m < c.markers.size(); ++m)
    for (const Pose2SimRun& r : c.runs) row(c.markers[m], r, r.markers[m]);
  for (const Pose2SimRun& r : c.runs) row("**all**", r, pooled(r));
  s << "\nLimb length std over the trial (mean of " << pose2sim_limbs().size() << " limbs), mm: ";
  for (const Pose2SimRun& r : c.runs)
    s << r.name << " " << fixed(1000 * limb_std_m(r.limb_lengths), 1) << ", ";
  s << "Pose2Sim's TRC " << fixed(1000 * limb_std_m(c.trc_limb_lengths), 1) << "\n";
  s << "\nHip width (RHip to LHip), median / std mm: ";
  for (const Pose2SimRun& r : c.runs)
    s << r.name << " " << fixed(1000 * median_of(r.hip_width_m), 0) << " / "
      << fixed(1000 * limb_std_m({r.hip_width_m}), 1) << ", ";
  s << "Pose2Sim's TRC " << fixed(1000 * median_of(c.trc_hip_width_m), 0) << " / "
    << fixed(1000 * limb_std_m({c.trc_hip_width_m}), 1) << "\n";
  s << views_left_out_table(c);
  s << "\nFrames with the participant: ";
  for (const Pose2SimRun& r : c.runs)
    s << r.name << " " << r.frames_with_participant << " (other people reported " << r.other_people
      << "); ";
  s << "\n";
  if (std::any_of(c.runs.begin(), c.runs.end(), [](const Pose2SimRun& r) { return r.fitted; }))
    s << "\nWith skeleton fitting: the fitted 15 body joints, compared on the markers that are "
         "body joints in BODY_25B's mapping (all 14 here: Neck is UpperNeck, Head HeadTop); "
         "\"views used\" counts the person's views, the fit uses every one of them.\n";
  return s.str();
}

}  // namespace mocap::eval
