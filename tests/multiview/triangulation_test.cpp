// The view geometry and the triangulation rules of components/multiview: exact on clean data,
// outlier views found by both of our strategies, and Pose2Sim's camera-exclusion rule as its
// source describes it.

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "eval/multiview_scene.hpp"
#include "multiview/person_triangulation.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "multiview/triangulation.hpp"
#include "multiview/view_geometry.hpp"

namespace mocap::multiview {
namespace {

std::vector<ViewGeometry> ring(int count) {
  std::vector<ViewGeometry> views;
  for (const auto& c : eval::ring_rig(count, 5.0, 1.5, 0.8, {0.0, 1.0, 0.0}, eval::Image{}))
    views.push_back(from_camera(c));
  return views;
}

std::vector<PointObservation> observe(const std::vector<ViewGeometry>& views,
                                      const glm::dvec3& point) {
  std::vector<PointObservation> seen;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const glm::dvec2 p = views[v].project(point);
    seen.push_back({static_cast<int>(v), static_cast<float>(p.x), static_cast<float>(p.y), 0.9f});
  }
  return seen;
}

std::uint64_t all_views(std::size_t n) { return (std::uint64_t{1} << n) - 1; }

TEST(ViewGeometry, AnyScaleAndSignOfTheMatrixIsTheSameView) {
  const auto camera = eval::ring_rig(3, 4.0, 1.6, 0.0, {0.0, 1.0, 0.0}, eval::Image{})[1];
  const ViewGeometry a = from_camera(camera);
  std::array<double, 12> scaled = a.projection();
  for (double& v : scaled) v *= -7.5;
  const ViewGeometry b = ViewGeometry::from_projection(scaled);
  EXPECT_NEAR(glm::distance(a.centre(), camera.centre()), 0.0, 1e-9);
  EXPECT_NEAR(glm::distance(a.centre(), b.centre()), 0.0, 1e-9);
  EXPECT_NEAR(a.focal(), camera.fx, 1e-6);
  EXPECT_NEAR(b.focal(), camera.fx, 1e-6);
  const glm::dvec3 point(0.3, 1.2, -0.4);
  EXPECT_GT(b.depth(point), 0.0);
  EXPECT_NEAR(a.depth(point), b.depth(point), 1e-9);
  EXPECT_NEAR(glm::distance(a.project(point), b.project(point)), 0.0, 1e-6);
  // The ray through the projection passes through the point.
  const glm::dvec2 pixel = a.project(point);
  const glm::dvec3 ray = a.ray(pixel.x, pixel.y);
  EXPECT_NEAR(glm::length(glm::cross(ray, point - a.centre())), 0.0, 1e-9);
  EXPECT_GT(glm::dot(ray, point - a.centre()), 0.0);
  // Behind the camera: no pixel.
  EXPECT_FALSE(std::isfinite(a.project(2.0 * a.centre() - point).x));
}

TEST(ViewGeometry, RefusesSingularOrNonFiniteMatrices) {
  std::array<double, 12> zero{};
  EXPECT_THROW(ViewGeometry::from_projection(zero), std::invalid_argument);
  std::array<double, 12> p = ring(1)[0].projection();
  p[5] = std::nan("");
  EXPECT_THROW(ViewGeometry::from_projection(p), std::invalid_argument);
}

TEST(Triangulation, EveryMethodIsExactOnCleanData) {
  const auto views = ring(5);
  const glm::dvec3 point(0.4, 1.3, -0.2);
  const auto seen = observe(views, point);
  EXPECT_NEAR(glm::distance(*triangulate_least_squares(views, seen), point), 0.0, 1e-6);
  EXPECT_NEAR(glm::distance(*triangulate_dlt(views, seen), point), 0.0, 1e-6);
  for (const TriangulatedPoint& t :
       {triangulate_robust(views, seen), triangulate_pose2sim(views, seen)}) {
    ASSERT_TRUE(t.valid());
    EXPECT_EQ(t.views, all_views(5));
    EXPECT_NEAR(glm::distance(glm::dvec3(t.position), point), 0.0, 1e-5);
    EXPECT_LT(t.error_px, 1e-3f);
  }
  // One view is not enough; neither are parallel rays (the same view twice).
  EXPECT_FALSE(triangulate_least_squares(views, std::span(seen).first(1)));
  const std::vector<PointObservation> twice = {seen[0], seen[0]};
  EXPECT_FALSE(triangulate_robust(views, twice).valid());
}

TEST(Triangulation, OursDropsOutlierViewsAtFewAndManyViews) {
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  for (const int count : {4, 16}) {
    const auto views = ring(count);
    const glm::dvec3 point(-0.3, 0.9, 0.5);
    auto seen = observe(views, point);
    for (auto& o : seen) {
      o.x += noise(rng);
      o.y += noise(rng);
    }
    // A quarter of the views see something else 60 px away (a swap, another person's joint).
    std::uint64_t bad = 0;
    for (int v = 1; v < count; v += 4) {
      seen[v].x += 60.0f;
      bad |= std::uint64_t{1} << v;
    }
    const TriangulatedPoint t = triangulate_robust(views, seen);
    ASSERT_TRUE(t.valid()) << count << " views";
    EXPECT_EQ(t.views, all_views(count) & ~bad) << count << " views";
    EXPECT_LT(glm::distance(glm::dvec3(t.position), point), 0.01) << count << " views";
    EXPECT_LT(t.error_px, 3.0f);
    // Without the exclusion the outliers pull the point away.
    EXPECT_LT(glm::distance(glm::dvec3(t.position), point),
              0.5 * glm::distance(*triangulate_least_squares(views, seen), point));
  }
}

TEST(Triangulation, TwoViewsThatDisagreeGiveNoPoint) {
  const auto views = ring(2);
  const glm::dvec3 point(0.0, 1.0, 0.0);
  auto seen = observe(views, point);
  // 80 px across view 1's epipolar line of the point (along it, another depth would fit).
  const glm::dvec3 ray = point - views[0].centre();
  const glm::dvec2 along = glm::normalize(views[1].project(views[0].centre() + 0.5 * ray) -
                                          views[1].project(views[0].centre() + 1.5 * ray));
  seen[1].x += 80.0f * static_cast<float>(-along.y);
  seen[1].y += 80.0f * static_cast<float>(along.x);
  EXPECT_FALSE(triangulate_robust(views, seen).valid());
  EXPECT_FALSE(triangulate_pose2sim(views, seen).valid());
}

TEST(Triangulation, Pose2SimRuleDropsViewsUntilTheMeanErrorIsUnder15Px) {
  const auto views = ring(4);
  const glm::dvec3 point(0.2, 1.1, 0.1);
  auto seen = observe(views, point);
  // Below the likelihood threshold a view is left out before anything else.
  seen[3].confidence = 0.29f;
  seen[3].x += 500.0f;
  TriangulatedPoint t = triangulate_pose2sim(views, seen);
  EXPECT_EQ(t.views, 0b0111u);
  EXPECT_NEAR(glm::distance(glm::dvec3(t.position), point), 0.0, 1e-5);
  // A view 100 px off: the four views' mean error is above 15 px, the best three are kept.
  seen[3].confidence = 0.9f;
  seen[3].x -= 500.0f;
  seen[2].x += 100.0f;
  t = triangulate_pose2sim(views, seen);
  ASSERT_TRUE(t.valid());
  EXPECT_EQ(t.view_count(), 3);
  EXPECT_EQ(t.views & 0b0100u, 0u);
  EXPECT_LE(t.error_px, 15.0f);
  // 12 px off passes with every view (its share of the mean error stays under 15 px): the rule
  // keeps a moderate outlier that ours leaves out.
  seen[2].x -= 88.0f;
  t = triangulate_pose2sim(views, seen);
  EXPECT_EQ(t.views, all_views(4));
  EXPECT_GT(t.error_px, 1.0f);
}

TEST(PersonTriangulation, TheThresholdFollowsTheNoiseAndResidualsFindAnotherPerson) {
  const auto views = ring(4);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  constexpr int kKeypoints = 12;
  std::vector<glm::dvec3> person;
  for (int k = 0; k < kKeypoints; ++k) person.emplace_back(0.1 * k - 0.5, 0.15 * k, 0.05 * k);
  for (const float sigma_px : {0.5f, 12.0f}) {
    std::vector<std::vector<float>> xyc(views.size());
    for (std::size_t v = 0; v < views.size(); ++v) {
      for (const glm::dvec3& p : person) {
        // View 3 sees someone else: 0.6 m away.
        const glm::dvec2 px = views[v].project(v == 3 ? p + glm::dvec3(0.6, 0.0, 0.0) : p);
        xyc[v].insert(xyc[v].end(), {static_cast<float>(px.x) + sigma_px * noise(rng),
                                     static_cast<float>(px.y) + sigma_px * noise(rng), 0.9f});
      }
    }
    std::vector<Sighting> sightings;
    for (std::size_t v = 0; v < views.size(); ++v)
      sightings.push_back({static_cast<int>(v), xyc[v]});
    std::vector<TriangulatedPoint> out(kKeypoints);
    std::vector<float> residual(views.size());
    PersonTriangulator triangulator;
    const float threshold = triangulator.triangulate(views, sightings, {}, out, residual);
    // The floor for clean input, three times the median held-out residual for noisy input
    // (12 px at 5 m is 3.6 cm per axis).
    if (sigma_px < 1.0f) {
      EXPECT_FLOAT_EQ(threshold, RobustRule{}.outlier_m);
    } else {
      EXPECT_GT(threshold, 0.08f);
      EXPECT_LT(threshold, 0.25f);
    }
    for (int v = 0; v < 3; ++v) EXPECT_LT(residual[v], 0.6f * residual[3]) << sigma_px;
    EXPECT_GT(residual[3], threshold);
  }
}

}  // namespace
}  // namespace mocap::multiview
