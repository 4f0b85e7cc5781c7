#include "multiview/view_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "camera/camera.hpp"

namespace mocap::multiview {
namespace {

constexpr std::size_t kAllPairsUpTo = 8;

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

// The level an explained camera must come down to: the median error of the cameras that were not
// flagged, by the flag rule itself (flag_ratio times it, or under min_flag_px). NaN: no such
// camera.
double allowed_px(const ViewErrorReport& given, const ViewErrorOptions& options) {
  std::vector<double> good;
  for (const ViewError& e : given.views)
    if (!e.flagged && e.points > 0) good.push_back(e.median_px);
  const double level = median(good);
  return std::isnan(level) ? level : std::max(options.min_flag_px, options.flag_ratio * level);
}

// An explanation holds when the cameras it touches come down to the allowed level, unflagged,
// and no camera that was not flagged before becomes flagged (other flagged cameras may stay so:
// they may have an explanation of their own).
bool accepted(const ViewErrorReport& before, const ViewErrorReport& after,
              std::span<const std::size_t> touched, double allowed) {
  if (std::isnan(allowed)) return false;
  for (std::size_t v = 0; v < after.views.size(); ++v)
    if (after.views[v].flagged && !before.views[v].flagged) return false;
  return std::all_of(touched.begin(), touched.end(), [&](std::size_t v) {
    return after.views[v].points > 0 && !after.views[v].flagged &&
           after.views[v].median_px <= allowed;
  });
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

// The median of the cameras' medians: the rig's common level.
double level_px(const ViewErrorReport& report) {
  std::vector<double> medians;
  for (const ViewError& e : report.views)
    if (e.points > 0) medians.push_back(e.median_px);
  return median(medians);
}

// The best exchange of two views of one image size that explains the errors; false if none.
// With cameras flagged: pairs with a flagged camera, accepted as `accepted` says. With nobody
// flagged (few cameras: an exchange spoils every camera's check, since the others' triangulation
// holds both exchanged views, and all read alike): every pair, accepted when it flags nobody and
// lowers the common level by the flag rule's own ratio.
bool find_exchange(std::span<const camera::Camera> cameras,
                   std::vector<camera::BodySequence>& views, const ViewErrorReport& given,
                   double allowed, const ViewErrorOptions& options, ExchangedViews& found) {
  const bool nobody_flagged = flagged_views(given).empty();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < views.size(); ++a) {
    for (std::size_t b = a + 1; b < views.size(); ++b) {
      if (!nobody_flagged && !(given.views[a].flagged || given.views[b].flagged)) continue;
      if (!same_size(cameras[a], cameras[b])) continue;
      std::swap(views[a], views[b]);
      const ViewErrorReport after = view_errors(cameras, views, options);
      std::swap(views[a], views[b]);
      const std::size_t touched[] = {a, b};
      const bool explains = nobody_flagged
                                ? flagged_views(after).empty() &&
                                      level_px(after) * options.flag_ratio <= level_px(given)
                                : accepted(given, after, touched, allowed);
      if (!explains) continue;
      const double worst = std::max(after.views[a].median_px, after.views[b].median_px);
      if (worst >= best) continue;
      best = worst;
      found = {a,
               b,
               {given.views[a].median_px, given.views[b].median_px},
               {after.views[a].median_px, after.views[b].median_px}};
    }
  }
  return std::isfinite(best);
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
  std::vector<std::size_t> flagged = flagged_views(check.errors);
  // Nobody flagged: an exchange among few cameras may still be behind errors all alike; tried on
  // every pair only up to kAllPairsUpTo cameras (28 evaluations): with more, the others'
  // consensus outvotes the exchanged pair, which is then flagged itself.
  if (flagged.empty() && views.size() > kAllPairsUpTo) return check;
  const double allowed = allowed_px(check.errors, options.errors);
  // Exchanges first (each found one applied before looking for the next), then the remaining
  // flagged views one by one as scaled.
  ViewErrorReport current = check.errors;
  ExchangedViews exchange;
  while (check.exchanged.size() < views.size() / 2 &&
         find_exchange(cameras, views, current, allowed, options.errors, exchange)) {
    std::swap(views[exchange.first], views[exchange.second]);
    check.exchanged.push_back(exchange);
    current = view_errors(cameras, views, options.errors);
    flagged = flagged_views(current);
    if (flagged.empty()) break;
  }
  for (const std::size_t v : flagged) {
    const ViewResiduals residuals = view_residuals(cameras, views, options.errors);
    const double factor = fit_scale(cameras[v], residuals.views[v]);
    if (!(std::abs(factor - 1) > options.min_scale_change)) {
      check.unexplained.push_back(v);
      continue;
    }
    camera::BodySequence original = std::exchange(views[v], scaled(views[v], factor));
    const ViewErrorReport after = view_errors(cameras, views, options.errors);
    const std::size_t touched[] = {v};
    if (!accepted(current, after, touched, allowed)) {
      views[v] = std::move(original);
      check.unexplained.push_back(v);
      continue;
    }
    check.scaled.push_back({v, factor, current.views[v].median_px, after.views[v].median_px,
                            static_cast<int>(std::lround(cameras[v].width / factor)),
                            static_cast<int>(std::lround(cameras[v].height / factor))});
    current = after;
  }
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
                    " images, but the camera is " + std::to_string(c.width) + "x" +
                    std::to_string(c.height) +
                    "; run the detector on the calibrated size (or calibrate at the size used)");
  }
  for (const std::size_t v : check.unexplained)
    lines.push_back(labels[v] + ": error " + px(check.errors.views[v].median_px) +
                    " px, far worse than the other cameras' " + px(others_median(check.errors, v)) +
                    " px, not explained by an exchange of views or another image size: check its "
                    "calibration (pose, intrinsics) and its keypoints");
  return lines;
}

}  // namespace mocap::multiview
