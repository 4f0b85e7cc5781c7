#include "calibration/people_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <opencv2/calib3d.hpp>

#include "camera/rig_calibration.hpp"
#include "core/input_error.hpp"
#include "fit/ground_estimation.hpp"
#include "motion/canonical_body.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "multiview/triangulation.hpp"

namespace mocap::calibration {
namespace {

using camera::BodyKeypoints;
using camera::Camera;
namespace detail = camera::rig_calibration_detail;
constexpr std::size_t kJoints = kBodyJoints;
constexpr double kAnkleClearanceM = 0.07;  // fit::GroundEstimationOptions' ankle over the sole

// The person used in one view and frame: distorted and undistorted pixels, confidences (0: not
// used).
struct Sighting {
  std::array<glm::dvec2, kJoints> pixel{}, ideal{};
  std::array<double, kJoints> confidence{};
  bool present = false;
};
using ViewSightings = std::vector<Sighting>;  // per frame

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

int confident_joints(const BodyKeypoints& body, double min_confidence) {
  int n = 0;
  for (const Keypoint2D& k : body)
    if (k.confidence >= min_confidence && std::isfinite(k.x) && std::isfinite(k.y)) ++n;
  return n;
}

double body_height_px(const BodyKeypoints& body, double min_confidence) {
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  for (const Keypoint2D& k : body)
    if (k.confidence >= min_confidence && std::isfinite(k.y))
      lo = std::min<double>(lo, k.y), hi = std::max<double>(hi, k.y);
  return hi > lo ? hi - lo : 0.0;
}

Sighting sighting_of(const BodyKeypoints& body, const Camera& camera, double min_confidence) {
  Sighting s;
  s.present = true;
  for (std::size_t j = 0; j < kJoints; ++j) {
    const Keypoint2D& k = body[j];
    if (!(k.confidence >= min_confidence && std::isfinite(k.x) && std::isfinite(k.y))) continue;
    s.pixel[j] = {k.x, k.y};
    s.ideal[j] = camera.undistort_pixel(s.pixel[j]);
    s.confidence[j] = k.confidence;
  }
  return s;
}

// Without a rig: the detection with the most confident joints times its height (the person
// walking through the room, not a bystander cut by the image border).
ViewSightings first_choice(const camera::BodySequence& view, const Camera& camera,
                           const PeopleCalibrationOptions& o) {
  ViewSightings out(view.size());
  for (std::size_t f = 0; f < view.size(); ++f) {
    const BodyKeypoints* best = nullptr;
    double best_score = 0.0;
    for (const BodyKeypoints& body : view[f]) {
      const int joints = confident_joints(body, o.min_confidence);
      if (joints < o.min_joints) continue;
      const double score = joints * body_height_px(body, o.min_confidence);
      if (score > best_score) best_score = score, best = &body;
    }
    if (best) out[f] = sighting_of(*best, camera, o.min_confidence);
  }
  return out;
}

// How much the person moves in a view: the median joint's RMS distance from its mean position,
// in median body heights; NaN without frames.
double motion_of(const ViewSightings& view) {
  std::vector<double> heights, spreads;
  for (const Sighting& s : view) {
    if (!s.present) continue;
    double lo = 1e300, hi = -1e300;
    for (std::size_t j = 0; j < kJoints; ++j)
      if (s.confidence[j] > 0) lo = std::min(lo, s.pixel[j].y), hi = std::max(hi, s.pixel[j].y);
    if (hi > lo) heights.push_back(hi - lo);
  }
  if (heights.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(heights.begin(), heights.begin() + static_cast<long>(heights.size() / 2),
                   heights.end());
  const double height = heights[heights.size() / 2];
  for (std::size_t j = 0; j < kJoints; ++j) {
    glm::dvec2 sum(0.0);
    int n = 0;
    for (const Sighting& s : view)
      if (s.present && s.confidence[j] > 0) sum += s.pixel[j], ++n;
    if (n < 2) continue;
    const glm::dvec2 mean = sum / static_cast<double>(n);
    double squared = 0.0;
    for (const Sighting& s : view)
      if (s.present && s.confidence[j] > 0) {
        const glm::dvec2 d = s.pixel[j] - mean;
        squared += glm::dot(d, d);
      }
    spreads.push_back(std::sqrt(squared / n) / height);
  }
  if (spreads.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(spreads.begin(), spreads.begin() + static_cast<long>(spreads.size() / 2),
                   spreads.end());
  return spreads[spreads.size() / 2];
}

int shared_keypoints(const ViewSightings& a, const ViewSightings& b) {
  int n = 0;
  for (std::size_t f = 0; f < a.size(); ++f)
    if (a[f].present && b[f].present)
      for (std::size_t j = 0; j < kJoints; ++j)
        if (a[f].confidence[j] > 0 && b[f].confidence[j] > 0) ++n;
  return n;
}

int shared_frames(const ViewSightings& a, const ViewSightings& b) {
  int n = 0;
  for (std::size_t f = 0; f < a.size(); ++f)
    if (a[f].present && b[f].present) ++n;
  return n;
}

cv::Matx33d matrix_of(const Camera& c) { return {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1}; }

void set_pose(Camera& c, const cv::Matx33d& R, const cv::Vec3d& t) {
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.rotation[k][r] = R(r, k);
  c.translation = {t[0], t[1], t[2]};
}

// Per frame and joint, the point triangulated from the placed cameras that see it (two or more).
using Points = std::vector<std::array<std::optional<glm::dvec3>, kJoints>>;

Points triangulate(const std::vector<Camera>& cameras, const std::vector<bool>& placed,
                   const std::vector<ViewSightings>& views) {
  std::vector<multiview::ViewGeometry> geometry;
  for (const Camera& c : cameras) geometry.push_back(multiview::from_camera(c));
  const std::size_t frames = views.front().size();
  Points points(frames);
  std::vector<multiview::PointObservation> seen;
  for (std::size_t f = 0; f < frames; ++f)
    for (std::size_t j = 0; j < kJoints; ++j) {
      seen.clear();
      for (std::size_t k = 0; k < views.size(); ++k) {
        const Sighting& s = views[k][f];
        if (!placed[k] || !s.present || s.confidence[j] <= 0) continue;
        seen.push_back({static_cast<int>(k), static_cast<float>(s.ideal[j].x),
                        static_cast<float>(s.ideal[j].y), static_cast<float>(s.confidence[j])});
      }
      if (seen.size() < 2) continue;
      const auto p = multiview::triangulate_least_squares(geometry, seen);
      if (!p) continue;
      // In front of every camera that saw it.
      bool in_front = true;
      for (const auto& o : seen)
        in_front = in_front && cameras[static_cast<std::size_t>(o.view)].to_camera(*p).z > 0;
      if (in_front) points[f][j] = *p;
    }
  return points;
}

// The first pair: relative pose from the essential matrix of their shared keypoints.
void place_pair(std::vector<Camera>& cameras, std::size_t a, std::size_t b,
                const std::vector<ViewSightings>& views, const std::vector<std::string>& names) {
  std::vector<cv::Point2d> pa, pb;
  const auto normalised = [](const Camera& c, const glm::dvec2& p) {
    return cv::Point2d((p.x - c.cx) / c.fx, (p.y - c.cy) / c.fy);
  };
  for (std::size_t f = 0; f < views[a].size(); ++f) {
    const Sighting &sa = views[a][f], &sb = views[b][f];
    if (!sa.present || !sb.present) continue;
    for (std::size_t j = 0; j < kJoints; ++j)
      if (sa.confidence[j] > 0 && sb.confidence[j] > 0) {
        pa.push_back(normalised(cameras[a], sa.ideal[j]));
        pb.push_back(normalised(cameras[b], sb.ideal[j]));
      }
  }
  // A keypoint is an inlier within ~1 % of the image width (detectors are off by pixels).
  const double threshold = 0.01 * cameras[a].width / cameras[a].fx;
  cv::Mat mask;
  const cv::Mat E =
      cv::findEssentialMat(pa, pb, cv::Mat::eye(3, 3, CV_64F), cv::RANSAC, 0.999, threshold, mask);
  if (E.rows != 3 || E.cols != 3)
    throw InputError(names[b], "no relative pose to " + names[a] +
                                   " from their shared keypoints (essential matrix not found)");
  cv::Mat R, t;
  const int good = cv::recoverPose(E, pa, pb, cv::Mat::eye(3, 3, CV_64F), R, t, mask);
  if (good < 30)
    throw InputError(names[b], "only " + std::to_string(good) + " keypoints agree with " +
                                   names[a] + " on a relative pose: too few shared views");
  set_pose(cameras[a], cv::Matx33d::eye(), cv::Vec3d(0, 0, 0));
  set_pose(cameras[b], cv::Matx33d(R), cv::Vec3d(t));
}

// Another camera by PnP against the joints triangulated so far.
bool place_by_pnp(Camera& camera, const ViewSightings& view, const Points& points) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (std::size_t f = 0; f < view.size(); ++f) {
    if (!view[f].present) continue;
    for (std::size_t j = 0; j < kJoints; ++j)
      if (view[f].confidence[j] > 0 && points[f][j]) {
        const glm::dvec3& p = *points[f][j];
        object.emplace_back(p.x, p.y, p.z);
        image.emplace_back(view[f].ideal[j].x, view[f].ideal[j].y);
      }
  }
  if (object.size() < 20) return false;
  cv::Vec3d r, t;
  std::vector<int> inliers;
  const bool ok = cv::solvePnPRansac(object, image, matrix_of(camera), cv::noArray(), r, t, false,
                                     500, 0.01f * static_cast<float>(camera.width), 0.999, inliers,
                                     cv::SOLVEPNP_EPNP);
  if (!ok || inliers.size() < 20) return false;
  cv::Matx33d R;
  cv::Rodrigues(r, R);
  set_pose(camera, R, t);
  return true;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Two views whose people sit at the same pixels show one viewpoint: the same video given twice, or
// two cameras at one place. No baseline, no depth: the relative pose is undetermined.
void refuse_views_without_baseline(const std::vector<ViewSightings>& views,
                                   const std::vector<Camera>& cameras,
                                   const std::vector<std::string>& names) {
  for (std::size_t b = 1; b < views.size(); ++b)
    for (std::size_t a = 0; a < b; ++a) {
      std::vector<double> apart;
      for (std::size_t f = 0; f < views[a].size(); ++f) {
        const Sighting &sa = views[a][f], &sb = views[b][f];
        if (!sa.present || !sb.present) continue;
        for (std::size_t j = 0; j < kJoints; ++j)
          if (sa.confidence[j] > 0 && sb.confidence[j] > 0)
            apart.push_back(glm::distance(sa.pixel[j], sb.pixel[j]));
      }
      if (apart.size() < 8) continue;
      const double m = median(apart);
      // 0.2 % of the width: 4 px at 1920. Cameras 10 cm apart see a person 5 m away ~30 px apart.
      if (m < 0.002 * std::max(cameras[a].width, cameras[b].width))
        throw InputError(names[b], "sees the people at the same pixels as " + names[a] +
                                       " (median " + fixed(m, 2) + " px apart over " +
                                       std::to_string(apart.size()) +
                                       " keypoints): the same video given twice, or two cameras "
                                       "at one place; calibration needs cameras standing apart "
                                       "(no baseline, no depth)");
    }
}

// Head top to ankle along the bones that stack up when standing (head, trunk, thigh, shin).
double stature_bones(const std::array<double, kJoints>& bone) {
  const auto at = [&](Joint j) { return bone[index(j)]; };
  return at(Joint::head) + at(Joint::neck) + 0.5 * (at(Joint::right_knee) + at(Joint::left_knee)) +
         0.5 * (at(Joint::right_ankle) + at(Joint::left_ankle));
}

std::array<double, kJoints> canonical_bones() {
  std::array<double, kJoints> out{};
  for (std::size_t j = 0; j < kJoints; ++j) out[j] = motion::canonical_proportions().bone_m[j];
  return out;
}

// Median length of each bone over the frames.
std::array<double, kJoints> bone_medians(const Points& points) {
  std::array<double, kJoints> out{};
  for (std::size_t j = 0; j < kJoints; ++j) {
    const int parent = kJointParent[j];
    if (parent < 0) continue;
    std::vector<double> lengths;
    for (const auto& frame : points)
      if (frame[j] && frame[static_cast<std::size_t>(parent)])
        lengths.push_back(glm::distance(*frame[j], *frame[static_cast<std::size_t>(parent)]));
    out[j] = lengths.empty() ? 0.0 : median(lengths);
  }
  return out;
}

void scale_world(std::vector<Camera>& cameras, Points& points, double s) {
  for (Camera& c : cameras) c.translation *= s;
  for (auto& frame : points)
    for (auto& p : frame)
      if (p) *p *= s;
}

detail::Pose pose_of(const Camera& c) {
  const glm::dvec3 r = c.rodrigues();
  return {{r.x, r.y, r.z}, {c.translation.x, c.translation.y, c.translation.z}};
}

void set_pose(Camera& c, const detail::Pose& p) {
  c.set_rodrigues({p.rotation[0], p.rotation[1], p.rotation[2]});
  c.translation = {p.translation[0], p.translation[1], p.translation[2]};
}

// The detections of a view's frame with enough confident joints.
std::vector<Sighting> confident_people(const std::vector<BodyKeypoints>& frame,
                                       const Camera& camera, const PeopleCalibrationOptions& o) {
  std::vector<Sighting> out;
  for (const BodyKeypoints& body : frame)
    if (confident_joints(body, o.min_confidence) >= o.min_joints)
      out.push_back(sighting_of(body, camera, o.min_confidence));
  return out;
}

// The fundamental matrix from camera a's ideal pixels to camera b's lines (glm, column-major).
glm::dmat3 fundamental(const Camera& a, const Camera& b) {
  const glm::dmat3 R = b.rotation * glm::transpose(a.rotation);
  const glm::dvec3 t = b.translation - R * a.translation;
  const glm::dmat3 tx(0, t.z, -t.y, -t.z, 0, t.x, t.y, -t.x, 0);  // columns of [t]x
  const auto k_inverse = [](const Camera& c) {
    return glm::inverse(glm::dmat3(c.fx, 0, 0, 0, c.fy, 0, c.cx, c.cy, 1));
  };
  return glm::transpose(k_inverse(b)) * tx * R * k_inverse(a);
}

// Median over the joints both see of the symmetric distance (px) of each to the other's line.
double epipolar_distance(const Sighting& a, const Sighting& b, const glm::dmat3& F) {
  std::vector<double> d;
  for (std::size_t j = 0; j < kJoints; ++j) {
    if (a.confidence[j] <= 0 || b.confidence[j] <= 0) continue;
    const glm::dvec3 xa(a.ideal[j], 1.0), xb(b.ideal[j], 1.0);
    const glm::dvec3 in_b = F * xa, in_a = glm::transpose(F) * xb;
    const double e = glm::dot(xb, in_b);
    d.push_back(0.5 * (std::abs(e) / std::hypot(in_b.x, in_b.y) +
                       std::abs(e) / std::hypot(in_a.x, in_a.y)));
  }
  return d.size() < 4 ? std::numeric_limits<double>::max() : median(d);
}

// With a rig: per frame the detections of one person across the views, by epipolar consistency
// (several people, bystanders, false detections). Each detection of each view in turn anchors a
// group: every other view adds its detection nearest the anchor's epipolar lines, within 2 % of
// the image width; the group with the most views (then the closest) is the frame's person.
void associate(const std::vector<Camera>& cameras, std::span<const camera::BodySequence> input,
               std::vector<ViewSightings>& views, const PeopleCalibrationOptions& o) {
  const std::size_t n = views.size();
  std::vector<std::vector<glm::dmat3>> F(n, std::vector<glm::dmat3>(n));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b)
      if (a != b) F[a][b] = fundamental(cameras[a], cameras[b]);
  for (std::size_t f = 0; f < views.front().size(); ++f) {
    std::vector<std::vector<Sighting>> candidates;
    for (std::size_t k = 0; k < n; ++k)
      candidates.push_back(confident_people(input[k][f], cameras[k], o));
    std::vector<int> best_group;
    int best_views = 1;
    double best_cost = std::numeric_limits<double>::max();
    for (std::size_t r = 0; r < n; ++r)
      for (std::size_t d = 0; d < candidates[r].size(); ++d) {
        std::vector<int> group(n, -1);
        group[r] = static_cast<int>(d);
        int count = 1;
        double cost = 0.0;
        for (std::size_t k = 0; k < n; ++k) {
          if (k == r) continue;
          double nearest = 0.02 * cameras[k].width;
          for (std::size_t e = 0; e < candidates[k].size(); ++e)
            if (const double dist = epipolar_distance(candidates[r][d], candidates[k][e], F[r][k]);
                dist < nearest)
              nearest = dist, group[k] = static_cast<int>(e);
          if (group[k] >= 0) ++count, cost += nearest;
        }
        if (count > best_views || (count == best_views && count > 1 && cost < best_cost))
          best_views = count, best_cost = cost, best_group = group;
      }
    for (std::size_t k = 0; k < n; ++k)
      views[k][f] = !best_group.empty() && best_group[k] >= 0
                        ? candidates[k][static_cast<std::size_t>(best_group[k])]
                        : Sighting{};
  }
}

struct Solved {
  detail::BundleProblem problem;
  std::vector<double> errors;
  std::vector<std::size_t> frames;                                        // the frames used
  std::vector<std::array<std::optional<std::size_t>, kJoints>> point_of;  // per frame used
};

// Bundle adjustment over the frames used (at most max_frames, evenly spread), starting from
// `cameras` and `points`; the cameras and points are updated.
Solved adjust(std::vector<Camera>& cameras, Points& points, const std::vector<ViewSightings>& views,
              std::size_t fixed, const PeopleCalibrationOptions& o) {
  Solved s;
  std::vector<std::size_t> usable;
  for (std::size_t f = 0; f < points.size(); ++f) {
    int n = 0;
    for (const auto& p : points[f]) n += p.has_value();
    if (n >= o.min_joints) usable.push_back(f);
  }
  const std::size_t take =
      std::min<std::size_t>(usable.size(), static_cast<std::size_t>(o.max_frames));
  for (std::size_t i = 0; i < take; ++i) s.frames.push_back(usable[i * usable.size() / take]);

  detail::BundleProblem& p = s.problem;
  p.cameras = cameras;
  for (const Camera& c : cameras) p.camera_poses.push_back(pose_of(c));
  p.fixed_camera = fixed;
  p.loss_px = o.loss_px;
  p.link_weight_px_per_m = o.bone_weight_px_per_m;
  const std::array<double, kJoints> bones = bone_medians(points);
  p.lengths.assign(bones.begin(), bones.end());
  // The trunk's length holds the scale (it is seen in every frame; metres come later).
  p.fixed_length = static_cast<std::size_t>(index(Joint::neck));
  s.point_of.resize(s.frames.size());
  for (std::size_t i = 0; i < s.frames.size(); ++i) {
    const std::size_t f = s.frames[i];
    for (std::size_t j = 0; j < kJoints; ++j) {
      if (!points[f][j]) continue;
      s.point_of[i][j] = p.points.size();
      p.points.push_back({points[f][j]->x, points[f][j]->y, points[f][j]->z});
      for (std::size_t k = 0; k < views.size(); ++k) {
        const Sighting& v = views[k][f];
        if (!v.present || v.confidence[j] <= 0) continue;
        p.sightings.push_back(
            {k, *s.point_of[i][j], {v.pixel[j].x, v.pixel[j].y}, v.confidence[j], true});
      }
    }
    for (std::size_t j = 0; j < kJoints; ++j) {
      const int parent = kJointParent[j];
      if (parent >= 0 && s.point_of[i][j] && s.point_of[i][static_cast<std::size_t>(parent)])
        p.links.push_back({*s.point_of[i][j], *s.point_of[i][static_cast<std::size_t>(parent)], j});
    }
  }
  for (int round = 0; round <= o.outlier_rounds; ++round) {
    detail::bundle_adjust(p, s.errors);
    if (round == o.outlier_rounds) break;
    if (!detail::drop_outliers(p, s.errors, o.outlier_factor, o.outlier_floor_px)) break;
  }
  for (std::size_t k = 0; k < cameras.size(); ++k) set_pose(cameras[k], p.camera_poses[k]);
  for (std::size_t i = 0; i < s.frames.size(); ++i)
    for (std::size_t j = 0; j < kJoints; ++j)
      if (s.point_of[i][j]) {
        const auto& q = p.points[*s.point_of[i][j]];
        points[s.frames[i]][j] = glm::dvec3(q[0], q[1], q[2]);
      }
  return s;
}

// The world: the floor from the feet, z up, origin under the mean root, x along camera 0's
// heading. Returns world <- current as (rotation, origin): p_world = R (p - origin).
struct WorldFrame {
  glm::dmat3 rotation{1.0};
  glm::dvec3 origin{0.0};
  bool floor_from_contacts = false;
};

WorldFrame world_from_people(const std::vector<Camera>& cameras, const Points& points,
                             const std::vector<std::size_t>& frames) {
  std::vector<std::array<glm::dvec3, kJoints>> bodies;
  glm::dvec3 up_sum(0.0);
  for (std::size_t f : frames) {
    std::array<glm::dvec3, kJoints> b{};
    bool complete = true;
    for (std::size_t j = 0; j < kJoints; ++j) {
      if (!points[f][j])
        complete = false;
      else
        b[j] = *points[f][j];
    }
    if (!complete) continue;
    bodies.push_back(b);
    const glm::dvec3 up = b[index(Joint::neck)] - b[index(Joint::root)];
    if (glm::length(up) > 0) up_sum += glm::normalize(up);
  }
  WorldFrame w;
  if (bodies.empty() || glm::length(up_sum) == 0)
    throw InputError("views", "no frame shows a whole person in two cameras: no floor");
  const glm::dvec3 up = glm::normalize(up_sum);
  fit::GroundEstimator ground;
  glm::dvec3 root_sum(0.0);
  for (const auto& b : bodies) {
    fit::Body body;
    for (std::size_t j = 0; j < kJoints; ++j) body[j] = glm::vec3(b[j]);
    // The lower ankle stands (both within 5 cm).
    const double right = glm::dot(b[index(Joint::right_ankle)], up);
    const double left = glm::dot(b[index(Joint::left_ankle)], up);
    ground.add(body, {right <= left + 0.05, left <= right + 0.05});
    root_sum += b[index(Joint::root)];
  }
  glm::dvec3 normal = up;
  double offset = 0.0;
  if (const auto estimate = ground.estimate()) {
    normal = glm::normalize(estimate->plane.normal);
    offset = estimate->plane.offset;
    w.floor_from_contacts = estimate->normal_from_contacts;
  } else {
    // Too few frames for the estimator: up from the trunks, the floor under the lowest ankles.
    std::vector<double> lows;
    for (const auto& b : bodies)
      lows.push_back(std::min(glm::dot(b[index(Joint::right_ankle)], up),
                              glm::dot(b[index(Joint::left_ankle)], up)));
    offset = -(median(lows) - kAnkleClearanceM);
  }
  const glm::dvec3 mean_root = root_sum / static_cast<double>(bodies.size());
  w.origin = mean_root - (glm::dot(normal, mean_root) + offset) * normal;
  glm::dvec3 heading = cameras.front().optical_axis();
  heading -= glm::dot(heading, normal) * normal;
  if (glm::length(heading) < 1e-6)
    heading = cameras.front().to_world({1, 0, 0}) - cameras.front().centre();
  heading -= glm::dot(heading, normal) * normal;
  const glm::dvec3 x = glm::normalize(heading);
  const glm::dvec3 y = glm::cross(normal, x);
  // Rows x, y, z: world <- current.
  w.rotation = glm::transpose(glm::dmat3(x, y, normal));
  return w;
}

// A first rig: the pair (a, b) from their essential matrix, the others one by one by PnP (most
// keypoints shared with the placed cameras first); the joints triangulated, and the median
// reprojection error over every keypoint.
struct Start {
  std::vector<Camera> cameras;
  Points points;
  std::size_t fixed = 0;
  double median_px = 0.0;
};

Start initialise(std::vector<Camera> cameras, std::size_t a, std::size_t b,
                 const std::vector<ViewSightings>& views, const std::vector<std::string>& names) {
  const std::size_t n = cameras.size();
  place_pair(cameras, a, b, views, names);
  std::vector<bool> placed(n, false);
  placed[a] = placed[b] = true;
  Points points = triangulate(cameras, placed, views);
  for (std::size_t round = 2; round < n; ++round) {
    std::size_t next = n;
    int most = -1;
    for (std::size_t k = 0; k < n; ++k) {
      if (placed[k]) continue;
      int shared = 0;
      for (std::size_t m = 0; m < n; ++m)
        if (placed[m]) shared += shared_keypoints(views[k], views[m]);
      if (shared > most) most = shared, next = k;
    }
    if (!place_by_pnp(cameras[next], views[next], points))
      throw InputError(names[next],
                       "cannot be placed against the joints the others triangulate "
                       "(too few keypoints agree): film people where it overlaps");
    placed[next] = true;
    points = triangulate(cameras, placed, views);
  }
  std::vector<double> errors;
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t f = 0; f < points.size(); ++f)
      for (std::size_t j = 0; j < kJoints; ++j)
        if (views[k][f].present && views[k][f].confidence[j] > 0 && points[f][j])
          errors.push_back(glm::distance(cameras[k].project(*points[f][j]), views[k][f].pixel[j]));
  const double m = median(errors);
  return {std::move(cameras), std::move(points), a, std::isfinite(m) ? m : 1e300};
}

}  // namespace

PeopleCalibration calibrate_rig_from_people(std::span<const Camera> given,
                                            std::span<const camera::BodySequence> input,
                                            std::span<const std::string> sources,
                                            const PeopleCalibrationOptions& o) {
  const std::size_t n = given.size();
  if (n < 2) throw InputError("views", "give at least 2 views");
  if (input.size() != n || sources.size() != n)
    throw std::invalid_argument("calibrate_rig_from_people: one view and source per camera");
  for (std::size_t k = 1; k < n; ++k)
    if (input[k].size() != input[0].size())
      throw InputError(sources[k], "has " + std::to_string(input[k].size()) + " frames, " +
                                       sources[0] + " has " + std::to_string(input[0].size()) +
                                       ": the views must be in step (frame i of every view taken "
                                       "at the same instant); trim them to one length");
  std::vector<std::string> names;
  std::vector<Camera> cameras(given.begin(), given.end());
  for (std::size_t k = 0; k < n; ++k) {
    names.push_back("camera " + cameras[k].name + " (" + sources[k] + ")");
    if (!cameras[k].has_intrinsics())
      throw InputError(names[k], "has no intrinsics (give --intrinsics or --hfov)");
  }

  std::vector<ViewSightings> views;
  PeopleCalibration result;
  std::vector<double> motions;
  for (std::size_t k = 0; k < n; ++k) {
    views.push_back(first_choice(input[k], cameras[k], o));
    const double m = motion_of(views.back());
    if (!std::isfinite(m))
      throw InputError(names[k], "no person with " + std::to_string(o.min_joints) +
                                     " keypoints of confidence >= " + fixed(o.min_confidence, 2) +
                                     " in any of its " + std::to_string(input[k].size()) +
                                     " frames");
    motions.push_back(m);
  }
  refuse_views_without_baseline(views, cameras, names);
  result.motion = median(motions);
  if (result.motion < o.min_motion)
    throw InputError("views", "the person hardly moves (keypoints spread " +
                                  fixed(result.motion, 4) + " body heights, at least " +
                                  fixed(o.min_motion, 2) +
                                  " needed): one person standing still gives one pose, too few "
                                  "points to place the cameras; film people walking through the "
                                  "space all cameras see");
  for (std::size_t k = 0; k < n; ++k) {
    int best = 0;
    std::size_t with = k;
    for (std::size_t m = 0; m < n; ++m)
      if (m != k && shared_frames(views[k], views[m]) > best)
        best = shared_frames(views[k], views[m]), with = m;
    if (best < o.min_shared_frames)
      throw InputError(names[k], "shares " + std::to_string(best) + " frames with a person" +
                                     (with != k ? " with camera " + cameras[with].name : "") +
                                     ", at least " + std::to_string(o.min_shared_frames) +
                                     " needed: film people where it overlaps the others");
  }

  // Starts from the best-connected pairs (an essential matrix can pick the wrong one of its
  // poses on noisy keypoints), keeping the one whose whole rig reprojects best.
  std::vector<std::pair<int, std::pair<std::size_t, std::size_t>>> pairs;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      pairs.push_back({shared_keypoints(views[i], views[j]), {i, j}});
  std::sort(pairs.rbegin(), pairs.rend());
  pairs.resize(std::min<std::size_t>(pairs.size(), 3));
  std::optional<Start> start;
  std::string failure;
  for (const auto& [shared, pair] : pairs) {
    try {
      Start s = initialise(cameras, pair.first, pair.second, views, names);
      if (!start || s.median_px < start->median_px) start = std::move(s);
    } catch (const InputError& e) {
      if (failure.empty()) failure = e.what();
    }
  }
  if (!start) throw InputError("views", failure);
  cameras = start->cameras;
  Points points = std::move(start->points);
  const std::size_t a = start->fixed;
  // Roughly metres before the bundle (its bone weight is per metre).
  const double first_scale = stature_bones(canonical_bones()) / stature_bones(bone_medians(points));
  if (!(std::isfinite(first_scale) && first_scale > 0))
    throw InputError("views", "no bone was triangulated: the cameras do not agree on the person");
  scale_world(cameras, points, first_scale);

  Solved solved = adjust(cameras, points, views, a, o);
  // Several people or false detections: choose again with this rig, solve again.
  bool several = false;
  for (std::size_t k = 0; k < n && !several; ++k)
    for (const auto& frame : input[k]) several = several || frame.size() > 1;
  if (several) {
    // Twice: the first rig comes from a person chosen per view, not across the views.
    for (int round = 0; round < o.association_rounds; ++round) {
      associate(cameras, input, views, o);
      points = triangulate(cameras, std::vector<bool>(n, true), views);
      solved = adjust(cameras, points, views, a, o);
    }
    result.notes.push_back(
        "several detections per frame: one person per frame associated across the views by "
        "epipolar consistency with the first rig");
  }

  // Metres from the bones.
  std::array<double, kJoints> bones{};
  for (std::size_t j = 0; j < kJoints; ++j) bones[j] = solved.problem.lengths[j];
  // The standing height is kStatureOverJointSpan joint spans (measured on the CMU train
  // subjects, motion/canonical_body.hpp).
  const double span = stature_bones(bones);
  result.height_m = o.height_m > 0 ? o.height_m : motion::canonical_stature_m();
  if (o.height_m <= 0)
    result.notes.push_back("scale from the canonical body's standing height, " +
                           fixed(result.height_m, 3) + " m (give --height)");
  const double s = result.height_m / (motion::kStatureOverJointSpan * span);
  scale_world(cameras, points, s);

  const WorldFrame w = world_from_people(cameras, points, solved.frames);
  if (!w.floor_from_contacts) result.notes.push_back("the floor's tilt from the trunks alone");
  for (std::size_t k = 0; k < n; ++k) {
    Camera c = cameras[k];
    // x_c = R p + t, p = Wᵀ p_w + origin.
    c.rotation = cameras[k].rotation * glm::transpose(w.rotation);
    c.translation = cameras[k].rotation * w.origin + cameras[k].translation;
    result.rig.cameras.push_back(c);
  }
  result.rig.floor = GroundPlane{{0.0, 0.0, 1.0}, 0.0};

  const auto residuals = detail::camera_residuals(solved.problem, solved.errors);
  double squared = 0.0;
  int count = 0;
  for (std::size_t k = 0; k < n; ++k) {
    PeopleCameraReport r;
    r.name = cameras[k].name;
    for (std::size_t f : solved.frames) r.frames += views[k][f].present;
    r.observations = residuals[k].observations;
    r.dropped = residuals[k].dropped;
    r.rms_px = residuals[k].rms_px;
    squared += r.rms_px * r.rms_px * r.observations;
    count += r.observations;
    result.cameras.push_back(r);
  }
  result.frames_used = static_cast<int>(solved.frames.size());
  result.rms_px = count ? std::sqrt(squared / count) : 0.0;
  return result;
}

}  // namespace mocap::calibration
