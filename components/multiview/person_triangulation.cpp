#include "multiview/person_triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "multiview/observations.hpp"

namespace mocap::multiview {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Residuals a noise estimate needs.
constexpr std::size_t kMinResiduals = 8;

float median(std::vector<float>& values) {
  if (values.empty()) return kNaN;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

void PersonTriangulator::gather(std::span<const Sighting> sightings, int keypoint) {
  seen_.clear();
  for (const Sighting& s : sightings) {
    const float* k = &s.xyc[static_cast<std::size_t>(keypoint) * 3];
    seen_.push_back({s.view, k[0], k[1], k[2]});
  }
}

float PersonTriangulator::noise_threshold(std::span<const ViewGeometry> views,
                                          std::span<const Sighting> sightings, int keypoints,
                                          const TriangulationOptions& options) {
  RobustRule generous = options.robust;
  generous.outlier_m = options.noise_ceiling_m;
  residuals_.clear();
  gaps_.clear();
  for (int k = 0; k < keypoints; ++k) {
    gather(sightings, k);
    held_out_residuals(views, seen_, generous, residuals_, gaps_);
  }
  // A handful of residuals says little about the noise: a person seen by two views has the gaps
  // between their rays; without either, the base threshold stays.
  if (residuals_.size() >= kMinResiduals) {
    noise_m_ = median(residuals_);
  } else if (gaps_.size() >= kMinResiduals) {
    noise_m_ = median(gaps_);
  } else {
    noise_m_ = options.robust.outlier_m / options.noise_factor;
  }
  return std::clamp(options.noise_factor * noise_m_, options.robust.outlier_m,
                    std::max(options.robust.outlier_m, options.noise_ceiling_m));
}

float PersonTriangulator::triangulate(std::span<const ViewGeometry> views,
                                      std::span<const Sighting> sightings,
                                      const TriangulationOptions& options,
                                      std::span<TriangulatedPoint> out,
                                      std::span<float> sighting_residual_m,
                                      std::span<const KeypointPrior> priors,
                                      std::span<float> innovations) {
  if (sighting_residual_m.size() != sightings.size()) {
    throw std::invalid_argument("PersonTriangulator: one residual per sighting");
  }
  const int keypoints = static_cast<int>(out.size());
  for (const Sighting& s : sightings) {
    if (s.xyc.size() != static_cast<std::size_t>(keypoints) * 3) {
      throw std::invalid_argument("PersonTriangulator: a sighting has the wrong keypoint count");
    }
  }
  if ((!priors.empty() && priors.size() != out.size()) ||
      (!innovations.empty() && innovations.size() != out.size())) {
    throw std::invalid_argument("PersonTriangulator: one prior and innovation per keypoint");
  }
  for (float& i : innovations) i = kNaN;
  float threshold = kNaN;
  if (options.method == TriangulationMethod::robust) {
    RobustRule rule = options.robust;
    threshold = noise_threshold(views, sightings, keypoints, options);
    rule.outlier_m = threshold;
    // The noise of one view per axis: the median held-out residual (2D) is about 1.4 σ.
    const double view_sigma = std::max(1e-3, noise_m_ / 1.4);
    for (int k = 0; k < keypoints; ++k) {
      gather(sightings, k);
      PointPrior prior;
      const bool has_prior =
          !priors.empty() && std::isfinite(priors[k].point.x) && priors[k].sigma_m > 0.0f;
      if (has_prior) {
        double confidence2 = 0.0;
        int n = 0;
        for (const PointObservation& o : seen_) {
          if (!usable_keypoint(o.x, o.y, o.confidence, rule.min_confidence)) continue;
          confidence2 += static_cast<double>(o.confidence) * o.confidence;
          ++n;
        }
        const double ratio = view_sigma / priors[k].sigma_m;
        prior.point = glm::dvec3(priors[k].point);
        prior.weight = (n > 0 ? confidence2 / n : 0.0) * ratio * ratio;
      }
      out[k] = triangulate_robust(views, seen_, rule, has_prior ? &prior : nullptr,
                                  innovations.empty() ? nullptr : &innovations[k]);
    }
  } else {
    for (int k = 0; k < keypoints; ++k) {
      gather(sightings, k);
      out[k] = triangulate_pose2sim(views, seen_, options.pose2sim);
    }
  }
  // Each sighting's agreement with the others: its held-out residuals, keypoint by keypoint.
  const std::size_t n = sightings.size();
  table_.assign(static_cast<std::size_t>(keypoints) * n, kNaN);
  for (int k = 0; k < keypoints; ++k) {
    gather(sightings, k);
    observation_residuals(views, seen_, out[k],
                          std::span<float>(table_).subspan(static_cast<std::size_t>(k) * n, n));
  }
  for (std::size_t s = 0; s < n; ++s) {
    residuals_.clear();
    for (int k = 0; k < keypoints; ++k) {
      const float r = table_[static_cast<std::size_t>(k) * n + s];
      if (!std::isnan(r)) residuals_.push_back(r);
    }
    sighting_residual_m[s] = median(residuals_);
  }
  return threshold;
}

}  // namespace mocap::multiview
