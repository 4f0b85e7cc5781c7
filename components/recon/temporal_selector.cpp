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

// Viterbi over `frames`; when `anchor` is given the path starts after it.
std::vector<std::size_t> viterbi(const std::vector<const std::vector<Candidate>*>& frames,
                                 const FrameBones& bones, const PathOptions& o,
                                 const Candidate* anchor) {
  const std::size_t n = frames.size();
  std::vector<std::size_t> path(n, 0);
  if (n == 0) return path;
  std::vector<std::vector<float>> cost(n);
  std::vector<std::vector<std::uint32_t>> back(n);
  for (std::size_t t = 0; t < n; ++t) {
    const auto& cands = *frames[t];
    cost[t].assign(cands.size(), 0.0f);
    back[t].assign(cands.size(), 0);
    for (std::size_t b = 0; b < cands.size(); ++b) {
      float best = 0.0f;
      if (t == 0) {
        best = anchor ? transition(bones, anchor->frame, cands[b].frame, o) : 0.0f;
      } else {
        best = std::numeric_limits<float>::max();
        const auto& prev = *frames[t - 1];
        for (std::size_t a = 0; a < prev.size(); ++a) {
          const float c = cost[t - 1][a] + transition(bones, prev[a].frame, cands[b].frame, o);
          if (c < best) best = c, back[t][b] = static_cast<std::uint32_t>(a);
        }
        if (prev.empty()) best = 0.0f;
      }
      cost[t][b] = best + o.data_weight * cands[b].distance;
    }
  }
  // Frames without candidates break the chain: each stretch is traced back on its own.
  std::size_t t = n;
  while (t-- > 0) {
    if (frames[t]->empty()) continue;
    const bool chain_end = t + 1 == n || frames[t + 1]->empty();
    if (chain_end) {
      path[t] = static_cast<std::size_t>(std::min_element(cost[t].begin(), cost[t].end()) -
                                         cost[t].begin());
    } else {
      path[t] = back[t + 1][path[t + 1]];
    }
  }
  return path;
}

}  // namespace

std::vector<std::size_t> best_path(std::span<const std::vector<Candidate>> candidates,
                                   const FrameBones& bones, const PathOptions& options) {
  std::vector<const std::vector<Candidate>*> frames;
  for (const auto& c : candidates) frames.push_back(&c);
  return viterbi(frames, bones, options, nullptr);
}

LaggedPathSelector::LaggedPathSelector(const FrameBones& bones, const PathOptions& options, int lag)
    : bones_(bones), options_(options), lag_(std::max(0, lag)) {}

std::vector<LaggedPathSelector::Decision> LaggedPathSelector::push(
    std::vector<Candidate> candidates) {
  pending_.push_back(std::move(candidates));
  return decide(false);
}

std::vector<LaggedPathSelector::Decision> LaggedPathSelector::flush() { return decide(true); }

std::vector<LaggedPathSelector::Decision> LaggedPathSelector::decide(bool all) {
  std::vector<Decision> decided;
  while (!pending_.empty() && (all || pending_.size() > static_cast<std::size_t>(lag_))) {
    std::vector<const std::vector<Candidate>*> frames;
    for (const auto& p : pending_) frames.push_back(&p);
    const auto path = viterbi(frames, bones_, options_, has_anchor_ ? &anchor_ : nullptr);
    const auto& first = pending_.front();
    if (first.empty()) {
      has_anchor_ = false;  // a gap: the next stretch starts afresh
      decided.emplace_back(first_pending_, std::nullopt);
    } else {
      anchor_ = first[path[0]];
      has_anchor_ = true;
      decided.emplace_back(first_pending_, anchor_);
    }
    pending_.pop_front();
    ++first_pending_;
    if (!all) break;
  }
  return decided;
}

}  // namespace mocap::recon
