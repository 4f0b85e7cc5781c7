#include "multiview/reconstructor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

namespace mocap::multiview {

namespace {

constexpr float kForbidden = 1e6f;

std::uint64_t bit(int view) { return std::uint64_t{1} << view; }

TriangulatedPoint midpoint(const TriangulatedPoint& a, const TriangulatedPoint& b) {
  TriangulatedPoint m;
  m.position = 0.5f * (a.position + b.position);
  m.views = a.views | b.views;
  m.error_px = 0.5f * (a.error_px + b.error_px);
  m.error_m = 0.5f * (a.error_m + b.error_m);
  return m;
}

}  // namespace

std::span<const int> FrameResult::detections_of(std::size_t person) const {
  return std::span<const int>(detections)
      .subspan(person * static_cast<std::size_t>(views), static_cast<std::size_t>(views));
}

std::span<const TriangulatedPoint> FrameResult::keypoints_of(std::size_t person) const {
  return std::span<const TriangulatedPoint>(keypoint_points)
      .subspan(person * static_cast<std::size_t>(keypoints), static_cast<std::size_t>(keypoints));
}

std::span<const TriangulatedPoint> FrameResult::body_of(std::size_t person) const {
  return std::span<const TriangulatedPoint>(body_points).subspan(person * kBodyJoints, kBodyJoints);
}

void body_from_keypoints(const KeypointSet& set, std::span<const TriangulatedPoint> keypoints,
                         std::span<TriangulatedPoint> body) {
  for (int j = 0; j < kBodyJoints; ++j) {
    const JointSource& s = set.body[j];
    const TriangulatedPoint& a = keypoints[static_cast<std::size_t>(s.first)];
    if (s.second < 0) {
      body[j] = a;
      continue;
    }
    const TriangulatedPoint& b = keypoints[static_cast<std::size_t>(s.second)];
    if (a.valid() && b.valid()) {
      body[j] = midpoint(a, b);
    } else if (s.either_alone && (a.valid() || b.valid())) {
      body[j] = a.valid() ? a : b;
    } else {
      body[j] = TriangulatedPoint{};
    }
  }
}

MultiViewReconstructor::MultiViewReconstructor(std::vector<ViewGeometry> views,
                                               const KeypointSet& keypoints,
                                               const ReconstructionOptions& options)
    : views_(std::move(views)),
      keypoints_(keypoints),
      options_(options),
      tracker_(keypoints.count, options.tracker) {
  if (views_.empty() || views_.size() > static_cast<std::size_t>(kMaxViews)) {
    throw std::invalid_argument("MultiViewReconstructor: " + std::to_string(views_.size()) +
                                " views; 1 to " + std::to_string(kMaxViews) + " are supported");
  }
  for (const JointSource& s : keypoints_.body) {
    if (s.first < 0 || s.first >= keypoints_.count || s.second >= keypoints_.count) {
      throw std::invalid_argument("MultiViewReconstructor: keypoint set " +
                                  std::string(keypoints_.name) +
                                  " makes a body joint from a keypoint it does not have");
    }
  }
}

void MultiViewReconstructor::reset() { tracker_.reset(); }

std::span<TriangulatedPoint> MultiViewReconstructor::points(int group) {
  return std::span<TriangulatedPoint>(points_).subspan(
      static_cast<std::size_t>(group) * keypoints_.count,
      static_cast<std::size_t>(keypoints_.count));
}

int MultiViewReconstructor::add_group(int track) {
  groups_.push_back(Group{track});
  slots_.insert(slots_.end(), views_.size(), -1);
  points_.insert(points_.end(), static_cast<std::size_t>(keypoints_.count), TriangulatedPoint{});
  positions_.insert(positions_.end(), static_cast<std::size_t>(keypoints_.count), glm::vec3(0.0f));
  innovations_.insert(innovations_.end(), static_cast<std::size_t>(keypoints_.count), 0.0f);
  return static_cast<int>(groups_.size()) - 1;
}

void MultiViewReconstructor::add_member(int group, int detection) {
  const int view = table_[detection].view;
  slots_[static_cast<std::size_t>(group) * views_.size() + view] = detection;
  owner_[detection] = group;
  groups_[group].views |= bit(view);
  ++groups_[group].members;
}

void MultiViewReconstructor::remove_member(int group, int detection) {
  const int view = table_[detection].view;
  slots_[static_cast<std::size_t>(group) * views_.size() + view] = -1;
  owner_[detection] = -1;
  groups_[group].views &= ~bit(view);
  --groups_[group].members;
}

void MultiViewReconstructor::triangulate(int group) {
  sightings_.clear();
  sighting_detection_.clear();
  for (std::size_t v = 0; v < views_.size(); ++v) {
    const int d = slots_[static_cast<std::size_t>(group) * views_.size() + v];
    if (d < 0) continue;
    sightings_.push_back(
        {static_cast<int>(v), frame_->person(static_cast<int>(v), table_[d].index)});
    sighting_detection_.push_back(d);
  }
  residuals_.resize(sightings_.size());
  const std::span<TriangulatedPoint> out = points(group);
  const std::size_t k_count = static_cast<std::size_t>(keypoints_.count);
  const std::span<float> innovations =
      std::span<float>(innovations_).subspan(static_cast<std::size_t>(group) * k_count, k_count);
  Group& g = groups_[group];
  priors_.clear();
  if (options_.tracking && options_.tracker.prior && g.track >= 0) {
    const auto predicted = tracker_.prediction(g.track);
    const auto sigma = tracker_.prediction_sigma(g.track);
    for (std::size_t k = 0; k < k_count; ++k) priors_.push_back({predicted[k], sigma[k]});
  }
  g.threshold_m = triangulator_.triangulate(views_, sightings_, options_.triangulation, out,
                                            residuals_, priors_, innovations);
  g.triangulated = 0;
  for (int k = 0; k < keypoints_.count; ++k) {
    positions_[static_cast<std::size_t>(group) * keypoints_.count + k] = out[k].position;
    g.triangulated += out[k].valid();
  }
}

// How much larger a detection is than the person projected into its view: the ratio of their
// spreads about their centroids over the keypoints both have; 1 when unknown. A detection of
// someone standing in front of or behind the person, lined up in this view, passes the residual
// test near the line but not this one: its size belongs to another depth.
double MultiViewReconstructor::size_ratio(int group, const Sighting& sighting) const {
  const ViewGeometry& view = views_[static_cast<std::size_t>(sighting.view)];
  const std::size_t k_count = static_cast<std::size_t>(keypoints_.count);
  glm::dvec2 seen_sum(0.0), model_sum(0.0);
  int n = 0;
  for (std::size_t k = 0; k < k_count; ++k) {
    const TriangulatedPoint& p = points_[static_cast<std::size_t>(group) * k_count + k];
    const float* kp = &sighting.xyc[3 * k];
    if (!p.valid() || !usable_keypoint(kp[0], kp[1], kp[2])) continue;
    const glm::dvec2 model = view.project(glm::dvec3(p.position));
    if (!std::isfinite(model.x)) continue;
    seen_sum += glm::dvec2(kp[0], kp[1]);
    model_sum += model;
    ++n;
  }
  if (n < options_.rays.min_common) return 1.0;
  const glm::dvec2 seen_centre = seen_sum / static_cast<double>(n);
  const glm::dvec2 model_centre = model_sum / static_cast<double>(n);
  double seen_spread = 0.0, model_spread = 0.0;
  for (std::size_t k = 0; k < k_count; ++k) {
    const TriangulatedPoint& p = points_[static_cast<std::size_t>(group) * k_count + k];
    const float* kp = &sighting.xyc[3 * k];
    if (!p.valid() || !usable_keypoint(kp[0], kp[1], kp[2])) continue;
    const glm::dvec2 model = view.project(glm::dvec3(p.position));
    if (!std::isfinite(model.x)) continue;
    seen_spread +=
        glm::dot(glm::dvec2(kp[0], kp[1]) - seen_centre, glm::dvec2(kp[0], kp[1]) - seen_centre);
    model_spread += glm::dot(model - model_centre, model - model_centre);
  }
  return model_spread > 0.0 ? std::sqrt(seen_spread / model_spread) : 1.0;
}

// Triangulates the group and takes out, worst first, each detection that does not fit the
// result: a median residual above the gate, or (three views or more: with two, the points lie on
// both detections' rays) a size that belongs to another depth. A group left with one detection
// lets it go.
void MultiViewReconstructor::verify(int group) {
  const double size_limit = std::log(options_.size_tolerance);
  while (groups_[group].members >= 2) {
    triangulate(group);
    const float threshold = groups_[group].threshold_m;
    const float gate = std::isnan(threshold) ? options_.member_gate_m
                                             : std::max(options_.member_gate_m, threshold);
    int worst = -1;
    double worst_excess = 1.0;
    for (std::size_t s = 0; s < sightings_.size(); ++s) {
      double excess = residuals_[s] / gate;  // NaN (nothing to compare) passes
      if (groups_[group].members >= 3) {
        excess =
            std::max(excess, std::abs(std::log(size_ratio(group, sightings_[s]))) / size_limit);
      }
      if (excess > worst_excess) {
        worst = static_cast<int>(s);
        worst_excess = excess;
      }
    }
    if (worst < 0) return;
    remove_member(group, sighting_detection_[static_cast<std::size_t>(worst)]);
  }
  for (std::size_t v = 0; v < views_.size(); ++v) {
    const int d = slots_[static_cast<std::size_t>(group) * views_.size() + v];
    if (d >= 0) remove_member(group, d);
  }
}

void MultiViewReconstructor::match_tracks() {
  const int tracks = tracker_.size();
  track_group_.assign(static_cast<std::size_t>(tracks), -1);
  if (tracks == 0) return;
  int first = 0;
  while (first < table_.size()) {
    const int view = table_[first].view;
    int end = first;
    while (end < table_.size() && table_[end].view == view) ++end;
    const int cols = end - first;
    cost_.assign(static_cast<std::size_t>(tracks) * cols, kForbidden);
    for (int t = 0; t < tracks; ++t) {
      for (int c = 0; c < cols; ++c) {
        const float cost = table_.point_cost(first + c, tracker_.prediction(t), options_.rays);
        if (cost <= tracker_.gate(t)) cost_[static_cast<std::size_t>(t) * cols + c] = cost;
      }
    }
    assignment_.resize(static_cast<std::size_t>(tracks));
    solver_.solve(cost_, tracks, cols, assignment_);
    for (int t = 0; t < tracks; ++t) {
      const int c = assignment_[t];
      if (c < 0 || cost_[static_cast<std::size_t>(t) * cols + c] >= kForbidden) continue;
      if (track_group_[t] < 0) track_group_[t] = add_group(t);
      add_member(track_group_[t], first + c);
      view_track_[first + c] = t;
    }
    first = end;
  }
  for (int g = 0; g < static_cast<int>(groups_.size()); ++g) verify(g);
}

void MultiViewReconstructor::attach_leftovers(bool tracked_only) {
  offers_.clear();
  for (int d = 0; d < table_.size(); ++d) {
    if (owner_[d] >= 0) continue;
    for (int g = 0; g < static_cast<int>(groups_.size()); ++g) {
      const Group& group = groups_[g];
      if (group.members < 2 || (tracked_only && group.track < 0) ||
          (group.views & bit(table_[d].view))) {
        continue;
      }
      const std::span<const glm::vec3> at =
          std::span<const glm::vec3>(positions_)
              .subspan(static_cast<std::size_t>(g) * keypoints_.count,
                       static_cast<std::size_t>(keypoints_.count));
      const float cost = table_.point_cost(d, at, options_.rays);
      if (cost <= options_.attach_gate_m) offers_.push_back({cost, d, g});
    }
  }
  if (offers_.empty()) return;
  std::sort(offers_.begin(), offers_.end(), [](const Offer& a, const Offer& b) {
    if (a.cost != b.cost) return a.cost < b.cost;
    return a.detection != b.detection ? a.detection < b.detection : a.group < b.group;
  });
  scratch_.clear();
  for (const Offer& o : offers_) {
    if (owner_[o.detection] >= 0 || (groups_[o.group].views & bit(table_[o.detection].view))) {
      continue;
    }
    add_member(o.group, o.detection);
    scratch_.push_back(o.group);
  }
  std::sort(scratch_.begin(), scratch_.end());
  scratch_.erase(std::unique(scratch_.begin(), scratch_.end()), scratch_.end());
  for (const int g : scratch_) verify(g);
}

// Two groups of one person (a track that missed some views, and a cold group of those views):
// groups with no view in common whose keypoints lie within attach_gate_m of each other on
// average become one, the tracked one keeping its track.
void MultiViewReconstructor::merge_duplicates() {
  const std::size_t k_count = static_cast<std::size_t>(keypoints_.count);
  for (bool merged = true; merged;) {
    merged = false;
    for (int a = 0; a < static_cast<int>(groups_.size()) && !merged; ++a) {
      for (int b = a + 1; b < static_cast<int>(groups_.size()) && !merged; ++b) {
        const Group& ga = groups_[a];
        const Group& gb = groups_[b];
        if (ga.members < 2 || gb.members < 2 || (ga.views & gb.views)) continue;
        float sum = 0.0f;
        int common = 0;
        for (std::size_t k = 0; k < k_count; ++k) {
          const TriangulatedPoint& pa = points_[static_cast<std::size_t>(a) * k_count + k];
          const TriangulatedPoint& pb = points_[static_cast<std::size_t>(b) * k_count + k];
          if (!pa.valid() || !pb.valid()) continue;
          sum += glm::distance(pa.position, pb.position);
          ++common;
        }
        if (common < options_.rays.min_common || sum / common > options_.attach_gate_m) continue;
        const int into = gb.track >= 0 && ga.track < 0 ? b : a;
        const int from = into == a ? b : a;
        for (std::size_t v = 0; v < views_.size(); ++v) {
          const int d = slots_[static_cast<std::size_t>(from) * views_.size() + v];
          if (d < 0) continue;
          remove_member(from, d);
          add_member(into, d);
        }
        verify(into);
        merged = true;
      }
    }
  }
}

glm::dvec3 MultiViewReconstructor::group_centre(int group) const {
  const std::size_t k_count = static_cast<std::size_t>(keypoints_.count);
  glm::dvec3 sum(0.0);
  int n = 0;
  for (std::size_t k = 0; k < k_count; ++k) {
    const TriangulatedPoint& p = points_[static_cast<std::size_t>(group) * k_count + k];
    if (!p.valid()) continue;
    sum += glm::dvec3(p.position);
    ++n;
  }
  return n > 0 ? sum / static_cast<double>(n) : glm::dvec3(std::nan(""));
}

// A detection whose rays agree with two people (they stand one behind the other in its view)
// shows the nearer one, who hides the other: it moves to the nearer person when it agrees with
// every detection of theirs (complete linkage of ray costs, as the clustering) and its own group
// keeps two views.
void MultiViewReconstructor::reassign_hidden() {
  const std::size_t groups = groups_.size();
  centres_.clear();
  for (std::size_t g = 0; g < groups; ++g) centres_.push_back(group_centre(static_cast<int>(g)));
  scratch_.clear();
  for (std::size_t g = 0; g < groups; ++g) {
    for (std::size_t v = 0; v < views_.size() && groups_[g].members >= 3; ++v) {
      const int d = slots_[g * views_.size() + v];
      if (d < 0) continue;
      const ViewGeometry& view = views_[v];
      const double own_depth = view.depth(centres_[g]);
      const std::span<const float> xyc = frame_->person(static_cast<int>(v), table_[d].index);
      glm::dvec2 low(std::numeric_limits<double>::max()), high(-low);
      for (int k = 0; k < keypoints_.count; ++k) {
        if (!(table_.confidence(d, k) > 0.0f)) continue;
        low = glm::min(low, glm::dvec2(xyc[3 * k], xyc[3 * k + 1]));
        high = glm::max(high, glm::dvec2(xyc[3 * k], xyc[3 * k + 1]));
      }
      int best = -1;
      double best_depth = own_depth - options_.occlusion_margin_m;
      for (std::size_t h = 0; h < groups; ++h) {
        if (h == g || groups_[h].members < 2 || (groups_[h].views & bit(static_cast<int>(v)))) {
          continue;
        }
        const double depth = view.depth(centres_[h]);
        if (!(depth < best_depth)) continue;
        const glm::dvec2 at = view.project(centres_[h]);
        if (!(at.x >= low.x && at.x <= high.x && at.y >= low.y && at.y <= high.y)) continue;
        float link = -1.0f;
        for (std::size_t u = 0; u < views_.size() && link <= options_.pair_gate_m; ++u) {
          const int m = slots_[h * views_.size() + u];
          if (m < 0) continue;
          const float c = table_.pair_cost(d, m, options_.rays);
          if (!std::isnan(c)) link = std::max(link, c);
        }
        if (link < 0.0f || link > options_.pair_gate_m) continue;
        best = static_cast<int>(h);
        best_depth = depth;
      }
      if (best < 0) continue;
      remove_member(static_cast<int>(g), d);
      add_member(best, d);
      scratch_.push_back(static_cast<int>(g));
      scratch_.push_back(best);
    }
  }
  std::sort(scratch_.begin(), scratch_.end());
  scratch_.erase(std::unique(scratch_.begin(), scratch_.end()), scratch_.end());
  for (const int g : scratch_) verify(g);
}

bool MultiViewReconstructor::inside_volume(int group) const {
  const glm::vec3 lo = options_.volume_min, hi = options_.volume_max;
  if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return true;  // no volume
  const glm::dvec3 c = group_centre(group);
  return c.x >= lo.x && c.x <= hi.x && c.y >= lo.y && c.y <= hi.y && c.z >= lo.z && c.z <= hi.z;
}

// A person nobody tracks must be seen by enough of the views it is in front of: two false
// detections in two views of a large rig can agree by chance, a person in the room is seen by
// most views.
bool MultiViewReconstructor::seen_enough(int group) const {
  const Group& g = groups_[group];
  if (g.track >= 0) return true;
  glm::dvec3 centre(0.0);
  int n = 0;
  const std::size_t k_count = static_cast<std::size_t>(keypoints_.count);
  for (std::size_t k = 0; k < k_count; ++k) {
    const TriangulatedPoint& p = points_[static_cast<std::size_t>(group) * k_count + k];
    if (!p.valid()) continue;
    centre += glm::dvec3(p.position);
    ++n;
  }
  if (n == 0) return false;
  centre /= n;
  int expected = 0;
  for (const ViewGeometry& v : views_) expected += v.sees(centre);
  return g.members >= std::ceil(options_.min_view_fraction * expected) - 1e-6;
}

void MultiViewReconstructor::cluster_leftovers() {
  scratch_.clear();
  for (int d = 0; d < table_.size(); ++d) {
    if (owner_[d] < 0) scratch_.push_back(d);
  }
  if (scratch_.size() < 2) return;
  clustering_.cluster(table_, scratch_, options_.rays, options_.pair_gate_m);
  for (int i = 0; i < clustering_.groups(); ++i) {
    const int g = add_group(-1);
    for (const int d : clustering_.group(i)) add_member(g, d);
    verify(g);
  }
}

void MultiViewReconstructor::emit(std::int64_t frame_number) {
  FrameResult& r = result_;
  r.frame = frame_number;
  r.views = static_cast<int>(views_.size());
  r.keypoints = keypoints_.count;
  r.people.clear();
  r.detections.clear();
  r.keypoint_points.clear();
  r.body_points.clear();
  r.single_view.clear();
  r.sparse_detections = table_.sparse();
  r.tentative_people = 0;
  r.outside_people = 0;
  new_groups_.clear();
  for (int g = 0; g < static_cast<int>(groups_.size()); ++g) {
    const Group& group = groups_[g];
    if (group.members < 2) continue;
    if (!inside_volume(g)) {
      ++r.outside_people;
      continue;
    }
    if (group.triangulated < options_.min_keypoints || !seen_enough(g)) {
      for (std::size_t v = 0; v < views_.size(); ++v) {
        const int d = slots_[static_cast<std::size_t>(g) * views_.size() + v];
        if (d >= 0) remove_member(g, d);
      }
      continue;
    }
    r.people.push_back({-1, true, group.views, group.threshold_m});
    for (std::size_t v = 0; v < views_.size(); ++v) {
      const int d = slots_[static_cast<std::size_t>(g) * views_.size() + v];
      r.detections.push_back(d >= 0 ? table_[d].index : -1);
    }
    const std::span<const TriangulatedPoint> kp = points(g);
    r.keypoint_points.insert(r.keypoint_points.end(), kp.begin(), kp.end());
    r.body_points.resize(r.body_points.size() + kBodyJoints);
    body_from_keypoints(keypoints_, kp,
                        std::span<TriangulatedPoint>(r.body_points).last(kBodyJoints));
    new_groups_.push_back(g);
  }
  if (options_.tracking) {
    new_people_.clear();
    scratch_.clear();
    for (std::size_t p = 0; p < r.people.size(); ++p) {
      const std::size_t k_count = static_cast<std::size_t>(keypoints_.count);
      const TrackInput input{
          r.keypoints_of(p), r.body_of(p),
          std::span<const float>(innovations_)
              .subspan(static_cast<std::size_t>(new_groups_[p]) * k_count, k_count)};
      const int track = groups_[new_groups_[p]].track;
      if (track >= 0) {
        tracker_.update(track, input);
        r.people[p].id = tracker_.track(track).id;
        r.people[p].confirmed = tracker_.confirmed(track);
      } else {
        new_people_.push_back(input);
        scratch_.push_back(static_cast<int>(p));
      }
    }
    new_ids_.assign(new_people_.size(), -1);
    tracker_.place_new(new_people_, new_ids_);
    for (std::size_t i = 0; i < scratch_.size(); ++i) {
      r.people[scratch_[i]].id = tracker_.track(new_ids_[i]).id;
      r.people[scratch_[i]].confirmed = tracker_.confirmed(new_ids_[i]);
    }
  }
  for (int d = 0; d < table_.size(); ++d) {
    if (owner_[d] >= 0) continue;
    const int t = view_track_[d];
    r.single_view.push_back(
        {table_[d].view, table_[d].index, options_.tracking && t >= 0 ? tracker_.track(t).id : -1});
  }
  if (options_.tracking) tracker_.end_frame();
  if (!options_.report_tentative) drop_tentative();
}

void MultiViewReconstructor::drop_tentative() {
  FrameResult& r = result_;
  const std::size_t views = views_.size(), k_count = static_cast<std::size_t>(keypoints_.count);
  std::size_t kept = 0;
  for (std::size_t p = 0; p < r.people.size(); ++p) {
    if (!r.people[p].confirmed) {
      ++r.tentative_people;
      continue;
    }
    if (kept != p) {
      r.people[kept] = r.people[p];
      std::copy_n(r.detections.begin() + p * views, views, r.detections.begin() + kept * views);
      std::copy_n(r.keypoint_points.begin() + p * k_count, k_count,
                  r.keypoint_points.begin() + kept * k_count);
      std::copy_n(r.body_points.begin() + p * kBodyJoints, kBodyJoints,
                  r.body_points.begin() + kept * kBodyJoints);
    }
    ++kept;
  }
  r.people.resize(kept);
  r.detections.resize(kept * views);
  r.keypoint_points.resize(kept * k_count);
  r.body_points.resize(kept * kBodyJoints);
}

const FrameResult& MultiViewReconstructor::process(const FrameObservations& frame,
                                                   std::int64_t frame_number) {
  if (frame.keypoints() != keypoints_.count) {
    throw std::invalid_argument(
        "MultiViewReconstructor: frame " + std::to_string(frame_number) + " has " +
        std::to_string(frame.keypoints()) + " keypoints per person, the keypoint set " +
        std::string(keypoints_.name) + " " + std::to_string(keypoints_.count));
  }
  frame_ = &frame;
  table_.build(frame, views_, options_.rays);
  owner_.assign(static_cast<std::size_t>(table_.size()), -1);
  view_track_.assign(static_cast<std::size_t>(table_.size()), -1);
  groups_.clear();
  slots_.clear();
  points_.clear();
  positions_.clear();
  innovations_.clear();
  if (options_.tracking) {
    tracker_.begin_frame(frame_number);
    match_tracks();
    attach_leftovers(true);
  }
  cluster_leftovers();
  merge_duplicates();
  attach_leftovers(false);
  reassign_hidden();
  emit(frame_number);
  frame_ = nullptr;
  return result_;
}

}  // namespace mocap::multiview
