#include "multiview/view_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "camera/camera.hpp"

namespace mocap::multiview {
namespace {

// Up to this many cameras every view (and pair) is tried, not only the flagged ones: at most 15
// pairs. With more, the others' consensus outvotes a wrong view, which is then flagged itself.
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

bool same_size(const camera::Camera& a, const camera::Camera& b) {
  return a.width == b.width && a.height == b.height;
}

// Whether views a and b are candidates: every view with few cameras (an exchange or a scale
// there spoils every camera's check alike, since the others' triangulation holds the wrong view,
// and may flag nobody), else the flagged ones.
bool candidate(const ViewErrorReport& report, std::size_t v) {
  return report.views.size() <= kEveryViewUpTo || report.views[v].flagged;
}

// The exchange of two views of one image size that explains the errors best: the rig's mean
// error after it (infinity: none explains them).
double find_exchange(std::span<const camera::Camera> cameras,
                     std::vector<camera::BodySequence>& views, const ViewErrorReport& given,
                     const ViewErrorOptions& options, ExchangedViews& found) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < views.size(); ++a) {
    for (std::size_t b = a + 1; b < views.size(); ++b) {
      if (!(candidate(given, a) || candidate(given, b))) continue;
      if (!same_size(cameras[a], cameras[b])) continue;
      std::swap(views[a], views[b]);
      const ViewErrorReport after = view_errors(cameras, views, options);
      std::swap(views[a], views[b]);
      const std::size_t touched[] = {a, b};
      if (!explains(given, after, touched, options)) continue;
      const double mean = level(after).mean_px;
      if (mean >= best) continue;
      best = mean;
      found = {a,
               b,
               {given.views[a].median_px, given.views[b].median_px},
               {after.views[a].median_px, after.views[b].median_px}};
    }
  }
  return best;
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

}  // namespace

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
  // Round by round the explanation, exchange or scale, that leaves the lowest mean error is
  // applied, until none explains what is left (a view scaled and another pair exchanged can
  // mimic each other with three cameras: the better one wins).
  ViewErrorReport current = check.errors;
  for (std::size_t round = 0; round < views.size(); ++round) {
    ExchangedViews exchange;
    ScaledView scale;
    const double by_exchange = find_exchange(cameras, views, current, options.errors, exchange);
    const double by_scale = find_scale(cameras, views, current, options, scale);
    if (!std::isfinite(std::min(by_exchange, by_scale))) break;
    if (by_exchange <= by_scale) {
      std::swap(views[exchange.first], views[exchange.second]);
      check.exchanged.push_back(exchange);
    } else {
      views[scale.view] = scaled(views[scale.view], scale.factor);
      check.scaled.push_back(scale);
    }
    current = view_errors(cameras, views, options.errors);
  }
  check.explained_errors = current;
  check.unexplained = flagged_views(current);
  return check;
}

std::vector<std::string> describe(const ViewCheck& check, std::span<const camera::Camera> cameras,
                                  std::span<const std::string> labels) {
  std::vector<std::string> lines;
  for (const ExchangedViews& e : check.exchanged)
    lines.push_back(labels[e.first] + " and " + labels[e.second] +
                    " look exchanged: their errors " + px(e.before_px[0]) + " and " +
                    px(e.before_px[1]) + " px as given, " + px(e.after_px[0]) + " and " +
                    px(e.after_px[1]) + " px exchanged; give the views in the rig's camera order");
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
                    " px, not explained by an exchange of views or another image size: check its "
                    "calibration (pose, intrinsics) and its keypoints");
  return lines;
}

}  // namespace mocap::multiview
