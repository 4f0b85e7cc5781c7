#pragma once
// Choosing among the matcher's candidates in time. The paper's greedy rule (Lee et al. 2002
// distance over a window of w frames) and, beyond the paper, a dynamic-programming path search
// over all candidates (offline, or with a fixed lag for live use).

#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "posedb/database.hpp"
#include "recon/matcher.hpp"
#include "recon/quaternion_distance.hpp"

namespace mocap::recon {

// Bone rotations of every database frame, computed once (14 quaternions a frame).
class FrameBones {
 public:
  explicit FrameBones(const posedb::Database& db);
  const BoneRotations& operator[](std::uint32_t frame) const { return bones_[frame]; }
  // The frame `lag` frames earlier in the same clip, or -1 when the clip starts later.
  std::int64_t earlier(std::uint32_t frame, int lag) const;
  std::size_t size() const { return bones_.size(); }

 private:
  std::vector<BoneRotations> bones_;
  std::vector<std::uint32_t> clip_frame_;
};

float bone_distance(const BoneRotations& a, const BoneRotations& b);

struct SelectorOptions {
  int window = 4;              // w: previous frames compared
  float lag_decay = 0.8f;      // weight of lag i is lag_decay^(i-1): recent frames count most
  bool reject_repeat = false;  // the paper's option: never pick the previous frame again
  float data_weight = 0.0f;    // weight of the 2D match distance (0 = the paper: time only)
};

// The paper's greedy choice, one person: keeps the last w chosen frames.
class TemporalSelector {
 public:
  TemporalSelector(const FrameBones& bones, const SelectorOptions& options);
  // Returns the index of the chosen candidate (candidates must not be empty).
  std::size_t select(std::span<const Candidate> candidates);
  void reset() { history_.clear(); }

 private:
  float cost(const Candidate& c) const;
  const FrameBones& bones_;
  SelectorOptions options_;
  std::deque<std::uint32_t> history_;  // most recent first
};

struct PathOptions {
  float data_weight = 50.0f;       // weight of the 2D match distance against pose continuity
  float clip_jump_penalty = 0.0f;  // extra cost for leaving a clip's natural order
};

// Viterbi over all candidates of a sequence: the path minimising Σ data + continuity, where the
// continuity of b after a compares b's previous mocap frame with a. Returns one index per frame
// (0 for frames without candidates).
std::vector<std::size_t> best_path(std::span<const std::vector<Candidate>> candidates,
                                   const FrameBones& bones, const PathOptions& options);

// The same, incrementally, with a fixed lag for live use: frame t is decided once frame t + lag
// has arrived, from the best path through everything seen so far (O(K²) work per frame). A frame
// without candidates ends the path: the frames before it are decided at once.
class LaggedPathSelector {
 public:
  LaggedPathSelector(const FrameBones& bones, const PathOptions& options, int lag);
  // (frame index, choice); no choice for a frame that had no candidates.
  using Decision = std::pair<std::size_t, std::optional<Candidate>>;
  // Adds a frame's candidates; returns the decisions that became final, in frame order.
  std::vector<Decision> push(std::vector<Candidate> candidates);
  // Decides the frames still pending (end of stream).
  std::vector<Decision> flush();

 private:
  struct Step {
    std::vector<Candidate> candidates;
    std::vector<float> cost;          // best path cost ending at each candidate
    std::vector<std::uint32_t> back;  // its predecessor in the previous step
  };
  void extend(Step& step) const;
  void decide_oldest(std::vector<Decision>& out);
  void decide_all(std::vector<Decision>& out);
  const FrameBones& bones_;
  PathOptions options_;
  std::size_t lag_;
  std::size_t next_frame_ = 0;  // index of the oldest pending step
  std::deque<Step> pending_;
};

}  // namespace mocap::recon
