#include "recon/matcher.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "posedb/cluster_search.hpp"
#include "posedb/exact_search.hpp"
#include "posedb/projection.hpp"

namespace mocap::recon {

struct Matcher::Search {
  std::unique_ptr<posedb::SearchIndex> index;
  std::vector<posedb::Neighbor> neighbors;
  float scale = 1.0f;  // the partial-body rescaling of the last search
};

Matcher::Matcher(const posedb::Database& db, const MatchOptions& options)
    : db_(db), options_(options), search_(std::make_unique<Search>()) {
  if (options.exact) {
    search_->index = std::make_unique<posedb::ExactSearch>(db.projections());
  } else {
    search_->index = std::make_unique<posedb::ClusterSearch>(db.projections(), db.centroids(),
                                                             db.cluster_begin(), options.probe);
  }
}

Matcher::~Matcher() = default;
Matcher::Matcher(Matcher&&) noexcept = default;

namespace {

// Height of the box around the rows' joints that have a weight (root at the origin included).
float partial_height(const float* row, const posedb::PoseVector& weights) {
  float lo = 0.0f, hi = 0.0f;
  for (int j = 0; j < kBodyJoints - 1; ++j) {
    if (weights[2 * j + 1] == 0.0f) continue;
    lo = std::min(lo, row[2 * j + 1]);
    hi = std::max(hi, row[2 * j + 1]);
  }
  return hi - lo;
}

// The candidate's database pose retargeted to `person` (when given) and moved into `layout`'s
// keypoint definition (when given), seen by its view and normalised as the database's rows are; its
// squared distance to `query` over the weighted dimensions, or +inf when the retargeted pose cannot
// be normalised.
float person_distance(const posedb::Database& db, const Candidate& c,
                      const std::optional<motion::BodyProportions>& person,
                      const std::optional<LayoutOffsets>& layout, const posedb::PoseVector& query,
                      const posedb::PoseVector& weights) {
  const auto j = db.joints(c.frame);
  motion::Body15 body;
  for (int b = 0; b < kBodyJoints; ++b) body[b] = {j[3 * b], j[3 * b + 1], j[3 * b + 2]};
  if (person) body = motion::retarget(body, *person);
  if (layout) apply_layout_offsets_3d(*layout, body, -1.0f);
  const camera::Camera camera =
      posedb::view_camera(db.views()[c.view], db.build_info().views.root_height_m);
  std::array<glm::vec2, kBodyJoints> image;
  posedb::project_body(body, camera, image);
  posedb::PoseVector row;
  if (!posedb::normalize_pose(image, db.build_info().scaling, row))
    return std::numeric_limits<float>::infinity();
  float sum = 0.0f;
  for (int d = 0; d < posedb::kPoseDims; ++d) {
    if (weights[d] == 0.0f) continue;
    const float e = row[d] - query[d];
    sum += weights[d] * e * e;
  }
  return std::isfinite(sum) ? sum : std::numeric_limits<float>::infinity();
}

}  // namespace

bool normalize_body(std::span<const float, kBodyJoints * 3> body, posedb::Scaling scaling,
                    const ScalerOptions& options, posedb::PoseVector& out) {
  std::array<glm::vec2, kBodyJoints> points;
  int present = 0;
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  for (int j = 0; j < kBodyJoints; ++j) {
    const bool ok = body[3 * j + 2] >= options.min_confidence && std::isfinite(body[3 * j]) &&
                    std::isfinite(body[3 * j + 1]);
    points[j] = ok ? glm::vec2(body[3 * j], body[3 * j + 1]) : glm::vec2(nan, nan);
    present += ok ? 1 : 0;
  }
  return present >= options.min_joints && posedb::normalize_pose(points, scaling, out);
}

// A partial body normalised by its own box is too large (the box of the visible joints is
// smaller than the whole body's). After a first search the best candidate tells how tall that
// partial box is in database units; the query is rescaled to it and searched again.
void Matcher::search(const posedb::PoseVector& normalized, std::vector<Candidate>& out) {
  out.clear();
  posedb::PoseVector query = normalized, weights;
  int present = 1;  // the root
  for (int d = 0; d < posedb::kPoseDims; ++d) {
    weights[d] = std::isfinite(query[d]) ? 1.0f : 0.0f;
    present += d % 2 == 0 && weights[d] > 0.0f ? 1 : 0;
  }
  auto& found = search_->neighbors;
  const bool partial =
      present < kBodyJoints && db_.build_info().scaling == posedb::Scaling::bbox_height;
  const int passes = partial ? 1 + options_.rescale_passes : 1;
  search_->scale = 1.0f;
  for (int pass = 0; pass < passes; ++pass) {
    search_->index->search(query.data(), weights.data(), options_.k, found);
    if (found.empty() || pass + 1 == passes) break;
    const float scale = partial_height(db_.projections().row(found.front().index), weights);
    const float own = partial_height(query.data(), weights);
    if (!(scale > 1e-4f) || !(own > 1e-4f)) break;
    for (int d = 0; d < posedb::kPoseDims; ++d) query[d] *= scale / own;
    search_->scale *= scale / own;
  }
  const auto records = db_.projection_records();
  for (const auto& n : found) {
    out.push_back({n.index, records[n.index].frame, records[n.index].view, n.distance});
  }
  if (person_ && !layout_) rescore(query, out);
}

void Matcher::rescore(const posedb::PoseVector& query, std::vector<Candidate>& out) const {
  posedb::PoseVector weights;
  for (int d = 0; d < posedb::kPoseDims; ++d) weights[d] = std::isfinite(query[d]) ? 1.0f : 0.0f;
  for (auto& c : out) c.distance = person_distance(db_, c, person_, layout_, query, weights);
  std::stable_sort(out.begin(), out.end(),
                   [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
}

bool Matcher::match(std::span<const float, kBodyJoints * 3> body, std::vector<Candidate>& out) {
  posedb::PoseVector query;
  if (!normalize_body(body, db_.build_info().scaling, options_.scaler, query)) {
    out.clear();
    return false;
  }
  if (!layout_) {
    search(query, out);
    return !out.empty();
  }
  // The search needs the canonical joints (the database's rows); the re-scoring compares the
  // input as it is with the candidates moved into the layout.
  std::array<float, kBodyJoints * 3> corrected;
  std::copy(body.begin(), body.end(), corrected.begin());
  apply_layout_offsets(*layout_, corrected);
  posedb::PoseVector canonical;
  if (!normalize_body(corrected, db_.build_info().scaling, options_.scaler, canonical)) {
    out.clear();
    return false;
  }
  // Both the corrected and the uncorrected input search: the 2D correction cannot express an
  // offset towards the front or back of the body, so the right candidates may lie nearer the
  // uncorrected keypoints. The union is re-scored.
  search(canonical, out);
  search(query, uncorrected_);  // a member: no allocation per call once it has grown
  for (const Candidate& c : uncorrected_)
    if (std::none_of(out.begin(), out.end(),
                     [&](const Candidate& o) { return o.projection == c.projection; }))
      out.push_back(c);
  for (float& v : query) v *= search_->scale;  // a partial body: as the search rescaled it
  rescore(query, out);
  if (out.size() > static_cast<std::size_t>(options_.k)) out.resize(options_.k);
  return !out.empty();
}

}  // namespace mocap::recon
