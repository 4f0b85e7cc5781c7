#include "multiview/view_order.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <glm/glm.hpp>

#include "multiview/view_errors.hpp"

namespace mocap::multiview {
namespace {

// A joint of a view seen through a camera: its undistorted pixel (homogeneous) and the world
// direction of its ray from the camera centre.
struct Ray {
  glm::dvec3 pixel{0.0};
  glm::dvec3 direction{0.0};
  bool seen = false;
};

constexpr std::size_t kJoints = kBodyJoints;

// rays[frame * kJoints + joint] of one view's first `frames` frames through one camera.
using Rays = std::vector<Ray>;

glm::dmat3 intrinsic(const camera::Camera& c) {
  glm::dmat3 k(1.0);  // column-major: k[col][row]
  k[0][0] = c.fx;
  k[1][1] = c.fy;
  k[2][0] = c.cx;
  k[2][1] = c.cy;
  return k;
}

glm::dvec3 centre(const camera::Camera& c) { return -glm::transpose(c.rotation) * c.translation; }

Rays rays(const camera::Camera& c, const camera::BodySequence& view, std::size_t frames,
          double min_confidence) {
  Rays out(frames * kJoints);
  const glm::dmat3 back = glm::transpose(c.rotation) * glm::inverse(intrinsic(c));
  for (std::size_t f = 0; f < frames; ++f) {
    const int person = tallest_person(view[f], min_confidence).index;
    if (person < 0) continue;
    const camera::BodyKeypoints& joints = view[f][static_cast<std::size_t>(person)];
    for (std::size_t k = 0; k < kJoints; ++k) {
      const Keypoint2D& p = joints[k];
      if (!(p.confidence >= min_confidence) || !std::isfinite(p.x) || !std::isfinite(p.y)) continue;
      const glm::dvec2 u = c.undistort_pixel({p.x, p.y});
      if (!std::isfinite(u.x) || !std::isfinite(u.y)) continue;
      Ray& r = out[f * kJoints + k];
      r.pixel = {u.x, u.y, 1.0};
      r.direction = back * r.pixel;
      r.seen = true;
    }
  }
  return out;
}

// Distance of `pixel` (camera j) to the epipolar line of a ray of camera i: the line through the
// epipole (camera i's centre seen by j) and the ray's direction seen by j.
double line_distance(const glm::dvec3& epipole, const glm::dmat3& to_pixels, const Ray& from,
                     const glm::dvec3& pixel) {
  const glm::dvec3 line = glm::cross(epipole, to_pixels * from.direction);
  const double norm = std::hypot(line.x, line.y);
  return norm > 0 ? std::abs(glm::dot(line, pixel)) / norm
                  : std::numeric_limits<double>::infinity();
}

double median(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// cost(a, i, b, j) for all views a != b and cameras i != j of a's and b's image sizes; 0 for a
// pair of views with no joint seen in both (the same for every order).
class PairCosts {
 public:
  PairCosts(std::span<const camera::Camera> cameras, std::span<const camera::BodySequence> views,
            double min_confidence)
      : n_(cameras.size()), cost_(n_ * n_ * n_ * n_, 0.0) {
    std::size_t frames = views.empty() ? 0 : views.front().size();
    for (const auto& v : views) frames = std::min(frames, v.size());
    std::vector<Rays> through(n_ * n_);  // view a through camera i
    for (std::size_t a = 0; a < n_; ++a)
      for (std::size_t i = 0; i < n_; ++i)
        if (fits(cameras, a, i))
          through[a * n_ + i] = rays(cameras[i], views[a], frames, min_confidence);
    std::vector<glm::dmat3> to_pixels(n_);
    for (std::size_t j = 0; j < n_; ++j) to_pixels[j] = intrinsic(cameras[j]) * cameras[j].rotation;
    std::vector<double> distances;
    for (std::size_t i = 0; i < n_; ++i)
      for (std::size_t j = 0; j < n_; ++j) {
        if (i == j) continue;
        const glm::dvec3 epipole_in_j =
            to_pixels[j] * centre(cameras[i]) + intrinsic(cameras[j]) * cameras[j].translation;
        const glm::dvec3 epipole_in_i =
            to_pixels[i] * centre(cameras[j]) + intrinsic(cameras[i]) * cameras[i].translation;
        for (std::size_t a = 0; a < n_; ++a)
          for (std::size_t b = 0; b < n_; ++b) {
            if (a == b || !fits(cameras, a, i) || !fits(cameras, b, j)) continue;
            const Rays &ra = through[a * n_ + i], &rb = through[b * n_ + j];
            distances.clear();
            for (std::size_t m = 0; m < ra.size() && m < rb.size(); ++m) {
              if (!ra[m].seen || !rb[m].seen) continue;
              const double d =
                  0.5 * (line_distance(epipole_in_j, to_pixels[j], ra[m], rb[m].pixel) +
                         line_distance(epipole_in_i, to_pixels[i], rb[m], ra[m].pixel));
              if (std::isfinite(d)) distances.push_back(d);  // NaN breaks nth_element's order
            }
            if (!distances.empty()) at(a, i, b, j) = median(distances);
          }
      }
  }

  static bool fits(std::span<const camera::Camera> cameras, std::size_t a, std::size_t i) {
    return cameras[a].width == cameras[i].width && cameras[a].height == cameras[i].height;
  }

  double total(std::span<const std::size_t> order) const {
    double sum = 0;
    for (std::size_t a = 0; a < n_; ++a)
      for (std::size_t b = a + 1; b < n_; ++b) sum += at(a, order[a], b, order[b]);
    return sum;
  }

 private:
  double& at(std::size_t a, std::size_t i, std::size_t b, std::size_t j) {
    return cost_[((a * n_ + i) * n_ + b) * n_ + j];
  }
  double at(std::size_t a, std::size_t i, std::size_t b, std::size_t j) const {
    return cost_[((a * n_ + i) * n_ + b) * n_ + j];
  }
  std::size_t n_;
  std::vector<double> cost_;
};

bool sizes_kept(std::span<const camera::Camera> cameras, std::span<const std::size_t> order) {
  for (std::size_t a = 0; a < order.size(); ++a)
    if (!PairCosts::fits(cameras, a, order[a])) return false;
  return true;
}

// Every order (views of one size among cameras of that size), the cheapest kept.
void exhaustive(std::span<const camera::Camera> cameras, const PairCosts& costs, ViewOrder& best) {
  std::vector<std::size_t> order(cameras.size());
  std::iota(order.begin(), order.end(), 0);
  do {
    if (!sizes_kept(cameras, order)) continue;
    const double cost = costs.total(order);
    if (cost < best.cost_px) {
      best.cost_px = cost;
      best.camera_of_view = order;
    }
  } while (std::next_permutation(order.begin(), order.end()));
}

// From the order given, the exchange of two views (of one size) that lowers the cost most,
// applied while one does.
void by_exchanges(std::span<const camera::Camera> cameras, const PairCosts& costs,
                  ViewOrder& best) {
  std::vector<std::size_t>& order = best.camera_of_view;
  for (bool lowered = true; lowered;) {
    lowered = false;
    std::size_t best_a = 0, best_b = 0;
    for (std::size_t a = 0; a < order.size(); ++a)
      for (std::size_t b = a + 1; b < order.size(); ++b) {
        if (!PairCosts::fits(cameras, a, order[b]) || !PairCosts::fits(cameras, b, order[a]))
          continue;
        std::swap(order[a], order[b]);
        const double cost = costs.total(order);
        std::swap(order[a], order[b]);
        if (cost < best.cost_px) {
          best.cost_px = cost;
          best_a = a;
          best_b = b;
          lowered = true;
        }
      }
    if (lowered) std::swap(order[best_a], order[best_b]);
  }
}

}  // namespace

ViewOrder best_view_order(std::span<const camera::Camera> cameras,
                          std::span<const camera::BodySequence> views, double min_confidence) {
  ViewOrder best;
  best.camera_of_view.resize(cameras.size());
  std::iota(best.camera_of_view.begin(), best.camera_of_view.end(), 0);
  if (cameras.size() < 3 || views.size() != cameras.size()) return best;
  const PairCosts costs(cameras, views, min_confidence);
  best.given_cost_px = best.cost_px = costs.total(best.camera_of_view);
  if (cameras.size() <= kExhaustiveUpTo)
    exhaustive(cameras, costs, best);
  else
    by_exchanges(cameras, costs, best);
  return best;
}

}  // namespace mocap::multiview
