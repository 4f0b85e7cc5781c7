#include "multiview/view_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <utility>

#include "camera/camera.hpp"
#include "multiview/view_order.hpp"

namespace mocap::multiview {
namespace {

// Up to this many cameras every view is tried scaled, not only the flagged ones. With more, the
// others' consensus outvotes a wrong view, which is then flagged itself.
constexpr std::size_t kEveryViewUpTo = 6;

bool somebody(const std::vector<camera::BodyKeypoints>& people) { return !people.empty(); }

// The first `max_frames` frames in which every view shows somebody (those view_errors can use).
std::vector<camera::BodySequence> probe_frames(std::span<const camera::BodySequence> views,
                                               std::size_t max_frames) {
  std::vector<camera::BodySequence> out(views.size());
  if (views.empty()) return out;
  std::size_t frames = views.front().size();
  for (const camera::BodySequence& v : views) frames = std::min(frames, v.size());
  for (std::size_t f = 0; f < frames && out.front().size() < max_frames; ++f) {
    if (!std::all_of(views.begin(), views.end(),
                     [&](const camera::BodySequence& v) { return somebody(v[f]); }))
      continue;
    for (std::size_t v = 0; v < views.size(); ++v) out[v].push_back(views[v][f]);
  }
  return out;
}

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The mean of the cameras' median errors (those with points), and how many have points.
struct RigLevel {
  double mean_px = 0;
  std::size_t cameras = 0;
};

RigLevel level(const ViewErrorReport& report) {
  RigLevel out;
  for (const ViewError& e : report.views) {
    if (e.points == 0) continue;
    out.mean_px += e.median_px;
    ++out.cameras;
  }
  if (out.cameras) out.mean_px /= static_cast<double>(out.cameras);
  return out;
}

// An explanation holds when each camera it touches has its median error lowered by the flag
// rule's own ratio (or had none to compare: the others could not triangulate its joints, which
// the mistake itself may cause; at least one of them had one), and the whole rig's mean error
// too, no camera losing its points. A camera may stay flagged (its calibration may be off as
// well), but a partial explanation that leaves the rest as bad does not hold. On a right rig an
// exchange or a scale makes the cameras it touches worse, never twice better.
bool explains(const ViewErrorReport& before, const ViewErrorReport& after,
              std::span<const std::size_t> touched, const ViewErrorOptions& options) {
  bool compared = false;
  for (const std::size_t v : touched) {
    const ViewError &was = before.views[v], &is = after.views[v];
    if (is.points == 0) return false;
    if (was.points == 0) continue;
    if (is.median_px * options.flag_ratio > was.median_px) return false;
    compared = true;
  }
  const RigLevel was = level(before), is = level(after);
  return compared && is.cameras >= was.cameras && is.mean_px * options.flag_ratio <= was.mean_px;
}

std::vector<std::size_t> flagged_views(const ViewErrorReport& report) {
  std::vector<std::size_t> out;
  for (std::size_t v = 0; v < report.views.size(); ++v)
    if (report.views[v].flagged) out.push_back(v);
  return out;
}

// Whether view v is tried scaled: every view with few cameras (a scale there may spoil every
// camera's check alike and flag nobody), else the flagged ones.
bool candidate(const ViewErrorReport& report, std::size_t v) {
  return report.views.size() <= kEveryViewUpTo || report.views[v].flagged;
}

// The views moved to the cameras of `camera_of_view`.
std::vector<camera::BodySequence> reordered(std::vector<camera::BodySequence> views,
                                            std::span<const std::size_t> camera_of_view) {
  std::vector<camera::BodySequence> out(views.size());
  for (std::size_t v = 0; v < views.size(); ++v) out[camera_of_view[v]] = std::move(views[v]);
  return out;
}

// The order of the views that agrees best with the rig (view_order.hpp), when it explains the
// errors: the rig's mean error with it (infinity: the order given stays).
double find_order(std::span<const camera::Camera> cameras,
                  const std::vector<camera::BodySequence>& views, const ViewErrorReport& given,
                  const ViewErrorOptions& options, std::vector<std::size_t>& camera_of_view) {
  const ViewOrder order = best_view_order(cameras, views, options.min_confidence);
  std::vector<std::size_t> moved;
  for (std::size_t v = 0; v < views.size(); ++v)
    if (order.camera_of_view[v] != v) moved.push_back(v);
  if (moved.empty()) return std::numeric_limits<double>::infinity();
  const ViewErrorReport after =
      view_errors(cameras, reordered(views, order.camera_of_view), options);
  // The cameras given another view are those the moved views left.
  if (!explains(given, after, moved, options)) return std::numeric_limits<double>::infinity();
  camera_of_view = order.camera_of_view;
  return level(after).mean_px;
}

// The factor s that takes the view's keypoints (about the image origin) closest to where the
// other cameras put its joints, in least squares over the residuals within 3 medians of the fit
// (a wrong detection does not pull it), refitted three times from the ratio of the distances to
// the origin.
double fit_scale(const camera::Camera& camera, const std::vector<ViewResidual>& residuals) {
  std::vector<std::pair<glm::dvec2, glm::dvec2>> pairs;  // keypoint as read, target as it would be
  std::vector<double> ratios;
  for (const ViewResidual& r : residuals) {
    const glm::dvec2 target = camera.distort_pixel(r.projected);
    const double from_origin = std::hypot(r.keypoint.x, r.keypoint.y);
    if (!std::isfinite(target.x) || !std::isfinite(target.y) || from_origin <= 0) continue;
    pairs.emplace_back(r.keypoint, target);
    ratios.push_back(std::hypot(target.x, target.y) / from_origin);
  }
  double s = median(ratios);
  if (std::isnan(s)) return 1;
  for (int round = 0; round < 3; ++round) {
    std::vector<double> misses;
    for (const auto& [k, t] : pairs) misses.push_back(std::hypot(s * k.x - t.x, s * k.y - t.y));
    const double keep = 3 * median(misses);
    double kt = 0, kk = 0;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if (misses[i] > keep) continue;
      const auto& [k, t] = pairs[i];
      kt += k.x * t.x + k.y * t.y;
      kk += k.x * k.x + k.y * k.y;
    }
    if (kk <= 0) break;
    s = kt / kk;
  }
  return s;
}

camera::BodySequence scaled(camera::BodySequence view, double factor) {
  for (auto& people : view)
    for (camera::BodyKeypoints& person : people)
      for (Keypoint2D& k : person) {
        k.x = static_cast<float>(k.x * factor);
        k.y = static_cast<float>(k.y * factor);
      }
  return view;
}

// The view whose keypoints scaled (by their fitted factor) explain the errors best: the rig's
// mean error after it (infinity: none explains them). Factors within min_scale_change of 1 are no
// explanation, nor beyond 1/5..5 (4K keypoints for a 720p camera is 3x): a fit gone wrong.
double find_scale(std::span<const camera::Camera> cameras, std::vector<camera::BodySequence>& views,
                  const ViewErrorReport& given, const ViewCheckOptions& options,
                  ScaledView& found) {
  const ViewResiduals residuals = view_residuals(cameras, views, options.errors);
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (!candidate(given, v) || given.views[v].points == 0) continue;
    const double factor = fit_scale(cameras[v], residuals.views[v]);
    if (!(std::abs(factor - 1) > options.min_scale_change) || factor < 0.2 || factor > 5) continue;
    camera::BodySequence original = std::exchange(views[v], scaled(views[v], factor));
    const ViewErrorReport after = view_errors(cameras, views, options.errors);
    views[v] = std::move(original);
    const std::size_t touched[] = {v};
    if (!explains(given, after, touched, options.errors)) continue;
    const double mean = level(after).mean_px;
    if (mean >= best) continue;
    best = mean;
    found = {v,
             factor,
             given.views[v].median_px,
             after.views[v].median_px,
             static_cast<int>(std::lround(cameras[v].width / factor)),
             static_cast<int>(std::lround(cameras[v].height / factor))};
  }
  return best;
}

std::string px(double value) {
  char text[32];
  std::snprintf(text, sizeof text, value < 10 ? "%.1f" : "%.0f", value);
  return text;
}

// "the views look given in the order 4 3 2 1 of the rig's cameras (...)", the moved views' errors
// and the order to give them in.
std::string describe_order(const ReorderedViews& r, std::span<const camera::Camera> cameras,
                           std::span<const std::string> labels) {
  const std::vector<std::size_t> moved = r.moved();
  std::string text;
  if (moved.size() == 2) text = labels[moved[0]] + " and " + labels[moved[1]] + " look exchanged: ";
  std::string order, names, before, after, give;
  std::vector<std::size_t> view_at(r.camera_of_view.size());
  for (std::size_t v = 0; v < r.camera_of_view.size(); ++v) {
    const std::string space = v ? " " : "";
    order += space + std::to_string(r.camera_of_view[v] + 1);
    names += space + cameras[r.camera_of_view[v]].name;
    view_at[r.camera_of_view[v]] = v;
  }
  for (const std::size_t v : moved) {
    before += (before.empty() ? "" : ", ") + px(r.before_px[v]);
    after += (after.empty() ? "" : ", ") + px(r.after_px[v]);
  }
  for (const std::size_t v : view_at) give += (give.empty() ? "" : ", ") + labels[v];
  return text + "the views look given in the order " + order + " of the rig's cameras (" + names +
         "): the moved views' errors " + before + " px as given, " + after +
         " px reordered; give them as " + give;
}

std::string describe_foreign_rig(const ViewCheck& check, std::span<const std::string> labels) {
  std::string errors;
  for (std::size_t v = 0; v < check.explained_errors.views.size(); ++v) {
    const ViewError& e = check.explained_errors.views[v];
    if (e.points == 0) continue;
    errors += (errors.empty() ? "" : ", ") + labels[v] + " " + px(e.median_px) + " px of " +
              px(check.person_height_px[v]);
  }
  return "every camera disagrees with the others by more than a tenth of the person's height in "
         "its image (" +
         errors + ")" + (check.explained() ? ", even with the views' explanation above" : "") +
         ": the rig may not be these views' rig; check the calibration file and that the views "
         "come from its cameras";
}

}  // namespace

// Per camera the median over the frames of the tallest person's height in its image.
std::vector<double> person_heights(std::span<const camera::BodySequence> views,
                                   double min_confidence) {
  std::vector<double> out;
  for (const camera::BodySequence& view : views) {
    std::vector<double> heights;
    for (const auto& people : view) {
      const TallestPerson tallest = tallest_person(people, min_confidence);
      if (tallest.index >= 0) heights.push_back(tallest.height_px);
    }
    out.push_back(median(heights));
  }
  return out;
}

// Every camera with points (at least 3) disagrees with the others by more than `fraction` of the
// person's height in its image.
bool every_camera_far_off(const ViewErrorReport& report, std::span<const double> heights,
                          double fraction) {
  std::size_t cameras = 0;
  for (std::size_t v = 0; v < report.views.size(); ++v) {
    const ViewError& e = report.views[v];
    if (e.points == 0) continue;
    if (!(e.median_px > fraction * heights[v])) return false;
    ++cameras;
  }
  return cameras >= 3;
}

ViewCheck check_views(std::span<const camera::Camera> cameras,
                      std::span<const camera::BodySequence> given,
                      const ViewCheckOptions& options) {
  std::vector<camera::BodySequence> views = probe_frames(given, options.max_frames);
  ViewCheck check;
  check.errors = view_errors(cameras, views, options.errors);
  check.errors.frames = 0;  // the frames given, not those of the probe
  if (!given.empty())
    check.errors.frames = std::min_element(given.begin(), given.end(), [](auto& a, auto& b) {
                            return a.size() < b.size();
                          })->size();
  // Round by round the explanation, another order or a scale, that leaves the lowest mean error
  // is applied, until none explains what is left (a view scaled and two views exchanged can
  // mimic each other with three cameras: the better one wins). given_at[c]: the view given that
  // camera c now holds.
  std::vector<std::size_t> given_at(views.size());
  std::iota(given_at.begin(), given_at.end(), 0);
  ViewErrorReport current = check.errors;
  for (std::size_t round = 0; round < views.size(); ++round) {
    std::vector<std::size_t> order;
    ScaledView scale;
    const double by_order = find_order(cameras, views, current, options.errors, order);
    const double by_scale = find_scale(cameras, views, current, options, scale);
    if (!std::isfinite(std::min(by_order, by_scale))) break;
    if (by_order <= by_scale) {
      views = reordered(std::move(views), order);
      std::vector<std::size_t> was = given_at;
      for (std::size_t c = 0; c < views.size(); ++c) given_at[order[c]] = was[c];
    } else {
      views[scale.view] = scaled(views[scale.view], scale.factor);
      scale.view = given_at[scale.view];
      check.scaled.push_back(scale);
    }
    current = view_errors(cameras, views, options.errors);
  }
  check.explained_errors = current;
  check.unexplained = flagged_views(current);
  if (!std::is_sorted(given_at.begin(), given_at.end())) {
    ReorderedViews& r = check.reordered.emplace();
    r.camera_of_view.resize(views.size());
    for (std::size_t c = 0; c < views.size(); ++c) r.camera_of_view[given_at[c]] = c;
    for (std::size_t v = 0; v < views.size(); ++v) {
      r.before_px.push_back(check.errors.views[v].median_px);
      r.after_px.push_back(current.views[r.camera_of_view[v]].median_px);
    }
  }
  check.person_height_px = person_heights(views, options.errors.min_confidence);
  check.foreign_rig =
      every_camera_far_off(current, check.person_height_px, options.foreign_rig_fraction);
  return check;
}

std::vector<std::size_t> ReorderedViews::moved() const {
  std::vector<std::size_t> out;
  for (std::size_t v = 0; v < camera_of_view.size(); ++v)
    if (camera_of_view[v] != v) out.push_back(v);
  return out;
}

std::vector<std::string> describe(const ViewCheck& check, std::span<const camera::Camera> cameras,
                                  std::span<const std::string> labels) {
  std::vector<std::string> lines;
  if (check.reordered) lines.push_back(describe_order(*check.reordered, cameras, labels));
  for (const ScaledView& s : check.scaled) {
    const camera::Camera& c = cameras[s.view];
    char factor[32];
    std::snprintf(factor, sizeof factor, "%.3f", s.factor);
    lines.push_back(labels[s.view] + " looks made at another image size: its keypoints times " +
                    factor + " fit the other cameras (error " + px(s.before_px) + " -> " +
                    px(s.after_px) + " px), as from images of about " +
                    std::to_string(s.image_width) + "x" + std::to_string(s.image_height) +
                    ", but the camera is " + std::to_string(c.width) + "x" +
                    std::to_string(c.height) +
                    "; run the detector on the calibrated size (or calibrate at the size used)");
  }
  for (const std::size_t v : check.unexplained)
    lines.push_back(labels[v] + ": error " + px(check.explained_errors.views[v].median_px) +
                    " px, far worse than the other cameras' " +
                    px(others_median(check.explained_errors, v)) +
                    " px, not explained by another order of the views or another image size: check "
                    "its calibration (pose, intrinsics) and its keypoints");
  if (check.foreign_rig) lines.push_back(describe_foreign_rig(check, labels));
  return lines;
}

}  // namespace mocap::multiview
