#include "recon/temporal_selector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mocap::recon {

FrameBones::FrameBones(const posedb::Database& db) {
  const auto frames = db.frames();
  bones_.reserve(frames.size());
  clip_frame_.reserve(frames.size());
  for (std::uint32_t f = 0; f < frames.size(); ++f) {
    bones_.push_back(bone_rotations(db.joints(f)));
    clip_frame_.push_back(frames[f].clip_frame);
  }
}

std::int64_t FrameBones::earlier(std::uint32_t frame, int lag) const {
  return clip_frame_[frame] >= static_cast<std::uint32_t>(lag)
             ? static_cast<std::int64_t>(frame) - lag
             : -1;
}

float bone_distance(const BoneRotations& a, const BoneRotations& b) {
  return pose_distance(a, b, kLeeBoneWeights);
}

TemporalSelector::TemporalSelector(const FrameBones& bones, const SelectorOptions& options)
    : bones_(bones), options_(options) {
  if (options.window < 1)
    throw std::invalid_argument("temporal selector: window must be at least 1");
}

// Mean over the lags of the distance between the candidate's earlier mocap frames and the frames
// chosen before; a candidate at the start of its clip is compared by its own pose instead.
float TemporalSelector::cost(const Candidate& c) const {
  float sum = 0.0f, weight_sum = 0.0f, w = 1.0f;
  const int lags = std::min<int>(options_.window, static_cast<int>(history_.size()));
  for (int lag = 1; lag <= lags; ++lag, w *= options_.lag_decay) {
    const std::int64_t earlier = bones_.earlier(c.frame, lag);
    const std::uint32_t frame = earlier >= 0 ? static_cast<std::uint32_t>(earlier) : c.frame;
    sum += w * bone_distance(bones_[frame], bones_[history_[lag - 1]]);
    weight_sum += w;
  }
  const float time_cost = weight_sum > 0.0f ? sum / weight_sum : 0.0f;
  return time_cost + options_.data_weight * c.distance;
}

std::size_t TemporalSelector::select(std::span<const Candidate> candidates) {
  if (candidates.empty()) throw std::invalid_argument("temporal selector: no candidates");
  std::size_t best = 0;
  if (!history_.empty()) {
    float best_cost = std::numeric_limits<float>::max();
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (options_.reject_repeat && candidates[i].frame == history_.front() &&
          candidates.size() > 1)
        continue;
      const float c = cost(candidates[i]);
      if (c < best_cost) best_cost = c, best = i;
    }
  }  // no history yet: the nearest in 2D (the candidates come sorted by distance)
  history_.push_front(candidates[best].frame);
  if (history_.size() > static_cast<std::size_t>(options_.window)) history_.pop_back();
  return best;
}

namespace {

// Cost of going from mocap frame `a` to mocap frame `b` in consecutive output frames.
float transition(const FrameBones& bones, std::uint32_t a, std::uint32_t b, const PathOptions& o) {
  const std::int64_t before_b = bones.earlier(b, 1);
  if (before_b == a) return 0.0f;  // the clip's own next frame: perfectly continuous
  const std::uint32_t from = before_b >= 0 ? static_cast<std::uint32_t>(before_b) : b;
  return bone_distance(bones[from], bones[a]) + o.clip_jump_penalty;
}

}  // namespace

std::vector<std::size_t> best_path(std::span<const std::vector<Candidate>> candidates,
                                   const FrameBones& bones, const PathOptions& options) {
  LaggedPathSelector selector(bones, options, std::numeric_limits<int>::max());
  std::vector<LaggedPathSelector::Decision> decisions;
  for (const auto& c : candidates) {
    auto d = selector.push(c);
    decisions.insert(decisions.end(), d.begin(), d.end());
  }
  auto d = selector.flush();
  decisions.insert(decisions.end(), d.begin(), d.end());
  std::vector<std::size_t> path(candidates.size(), 0);
  for (const auto& [frame, choice] : decisions) {
    if (!choice) continue;
    const auto& c = candidates[frame];
    // A named copy: clang before 16 cannot capture a structured binding.
    const auto projection = choice->projection;
    path[frame] = static_cast<std::size_t>(
        std::find_if(c.begin(), c.end(),
                     [&](const Candidate& x) { return x.projection == projection; }) -
        c.begin());
  }
  return path;
}

LaggedPathSelector::LaggedPathSelector(const FrameBones& bones, const PathOptions& options, int lag)
    : bones_(bones), options_(options), lag_(static_cast<std::size_t>(std::max(0, lag))) {}

// Costs of the newest step from the one before it (or from nothing at the start of a path).
void LaggedPathSelector::extend(Step& step) const {
  const std::size_t n = step.candidates.size();
  step.cost.assign(n, 0.0f);
  step.back.assign(n, 0);
  const Step* prev = pending_.empty() ? nullptr : &pending_.back();
  for (std::size_t b = 0; b < n; ++b) {
    float best = 0.0f;
    if (prev) {
      best = std::numeric_limits<float>::max();
      for (std::size_t a = 0; a < prev->candidates.size(); ++a) {
        const float c = prev->cost[a] + transition(bones_, prev->candidates[a].frame,
                                                   step.candidates[b].frame, options_);
        if (c < best) best = c, step.back[b] = static_cast<std::uint32_t>(a);
      }
    }
    step.cost[b] = best + options_.data_weight * step.candidates[b].distance;
  }
}

// Follows the best path back from the newest step to the oldest and decides the oldest.
void LaggedPathSelector::decide_oldest(std::vector<Decision>& out) {
  const Step& last = pending_.back();
  std::size_t index = static_cast<std::size_t>(
      std::min_element(last.cost.begin(), last.cost.end()) - last.cost.begin());
  for (std::size_t s = pending_.size() - 1; s > 0; --s) index = pending_[s].back[index];
  out.emplace_back(next_frame_++, pending_.front().candidates[index]);
  pending_.pop_front();
}

void LaggedPathSelector::decide_all(std::vector<Decision>& out) {
  if (pending_.empty()) return;
  const Step& last = pending_.back();
  std::vector<std::size_t> path(pending_.size());
  path.back() = static_cast<std::size_t>(std::min_element(last.cost.begin(), last.cost.end()) -
                                         last.cost.begin());
  for (std::size_t s = pending_.size() - 1; s > 0; --s) path[s - 1] = pending_[s].back[path[s]];
  for (std::size_t s = 0; s < pending_.size(); ++s)
    out.emplace_back(next_frame_++, pending_[s].candidates[path[s]]);
  pending_.clear();
}

std::vector<LaggedPathSelector::Decision> LaggedPathSelector::push(
    std::vector<Candidate> candidates) {
  std::vector<Decision> decided;
  if (candidates.empty()) {
    decide_all(decided);  // the path ends here
    decided.emplace_back(next_frame_++, std::nullopt);
    return decided;
  }
  Step step;
  step.candidates = std::move(candidates);
  extend(step);
  pending_.push_back(std::move(step));
  while (pending_.size() > lag_) decide_oldest(decided);
  return decided;
}

std::vector<LaggedPathSelector::Decision> LaggedPathSelector::flush() {
  std::vector<Decision> decided;
  decide_all(decided);
  return decided;
}

}  // namespace mocap::recon
