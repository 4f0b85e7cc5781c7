#include "fit/multiview_people_fitter.hpp"

#include <algorithm>
#include <map>
#include <optional>

#include "fit/multiview_input.hpp"
#include "fit/track_fitters.hpp"

namespace mocap::fit {

struct MultiViewPeopleFitter::State {
  MultiViewPeopleFitOptions options;
  TrackFitters<MultiViewPeopleFitOptions, MultiViewFrameInput, MultiViewLiveFitter,
               MultiViewWindowedFitter>
      tracks{options, MultiViewFrameInput{}};
  MultiViewFrameInput input;  // reused
  std::int64_t people = 0;
  // The monocular prior, and per track id its bones' runs of frames lacking views and the held
  // frame it was last seen in (a gap longer than max_missed starts a new track: runs from 0).
  std::optional<MonocularPrior> prior;
  struct PriorRuns {
    MonocularPrior::Runs runs{};
    std::int64_t last = 0;
  };
  std::map<int, PriorRuns> prior_runs;
  std::int64_t prior_frames = 0;

  explicit State(MultiViewPeopleFitOptions o) : options(std::move(o)) {
    if (options.prior_db) prior.emplace(*options.prior_db, options.prior);
  }

  // The monocular prior of person `p` of `result` into `input` (a track's frames come in order).
  void add_prior(int id, std::int64_t t, const multiview::FrameResult& result, std::size_t p) {
    const bool found = prior->add(input, result.body_of(p), options.fit.cameras);
    prior_frames += found ? 1 : 0;
    auto [it, fresh] = prior_runs.try_emplace(id);
    PriorRuns& track = it->second;
    if (!fresh && t - track.last > options.max_missed) {
      track.runs = {};
    } else if (!fresh) {
      for (std::int64_t gap = track.last + 1; gap < t; ++gap)
        prior->settle_newest(nullptr, track.runs);  // frames the person was missed in
    }
    track.last = t;
    prior->settle_newest(found ? &input.prior : nullptr, track.runs);
  }

  void process(const multiview::FrameObservations* observations,
               const multiview::FrameResult* result, const multiview::KeypointSet* set,
               People3D frame, std::vector<People3D>& out) {
    std::vector<int> ids;
    for (const Person3D& person : frame.people)
      if (person.id >= 0) ids.push_back(person.id);
    std::sort(ids.begin(), ids.end());
    people += static_cast<std::int64_t>(ids.size());
    // The set's number is its time: the limiter's gaps (dropped sets) are steps of the fit.
    const auto time = static_cast<double>(frame.header.frame);
    tracks.gap().time = time;
    const std::int64_t t = tracks.hold(std::move(frame), ids);
    if (result) {
      for (std::size_t p = 0; p < result->people.size(); ++p) {
        const int id = result->people[p].id;
        if (id < 0 || !std::binary_search(ids.begin(), ids.end(), id)) continue;
        tracks.see(id, t, [&]() -> const MultiViewFrameInput& {
          multiview_input(*observations, *result, p, *set, input);
          input.time = time;
          if (prior) add_prior(id, t, *result, p);
          return input;
        });
      }
    }
    tracks.end_frame(t);
    // A track missed longer than max_missed starts again from no runs when seen (above): forget
    // it, so that a long live run keeps only the tracks that can still come back.
    std::erase_if(prior_runs,
                  [&](const auto& entry) { return t - entry.second.last > options.max_missed; });
    tracks.release_decided([&](People3D&& f) { out.push_back(std::move(f)); });
  }
};

MultiViewPeopleFitter::MultiViewPeopleFitter(MultiViewPeopleFitOptions options)
    : state_(std::make_unique<State>(std::move(options))) {}
MultiViewPeopleFitter::~MultiViewPeopleFitter() = default;
MultiViewPeopleFitter::MultiViewPeopleFitter(MultiViewPeopleFitter&&) noexcept = default;
MultiViewPeopleFitter& MultiViewPeopleFitter::operator=(MultiViewPeopleFitter&&) noexcept = default;

std::vector<People3D> MultiViewPeopleFitter::push(const multiview::FrameObservations& observations,
                                                  const multiview::FrameResult& result,
                                                  const multiview::KeypointSet& set,
                                                  People3D frame) {
  std::vector<People3D> out;
  state_->process(&observations, &result, &set, std::move(frame), out);
  return out;
}

std::vector<People3D> MultiViewPeopleFitter::push(People3D frame) {
  std::vector<People3D> out;
  state_->process(nullptr, nullptr, nullptr, std::move(frame), out);
  return out;
}

void MultiViewPeopleFitter::stop() { state_->tracks.stop(); }

// After a stop, frames beyond the budget leave with their triangulated joints.
std::vector<People3D> MultiViewPeopleFitter::finish() {
  State& s = *state_;
  std::vector<People3D> out;
  s.tracks.finish_all();
  s.tracks.release_all([&](People3D&& frame) { out.push_back(std::move(frame)); });
  return out;
}

std::int64_t MultiViewPeopleFitter::placed() const { return state_->tracks.placed(); }
std::int64_t MultiViewPeopleFitter::prior_frames() const { return state_->prior_frames; }
std::size_t MultiViewPeopleFitter::held_frames() const { return state_->tracks.held_frames(); }
const FitStats& MultiViewPeopleFitter::stats() const { return state_->tracks.stats(); }

const FrameTimes& MultiViewPeopleFitter::frame_times() const {
  return state_->tracks.frame_times();
}

std::string MultiViewPeopleFitter::summary() const {
  const State& s = *state_;
  return std::string(s.options.mode == StreamFitMode::live ? "live" : "full") +
         " fit: " + std::to_string(s.tracks.placed()) + " of " + std::to_string(s.people) +
         " person-frames fitted, " + std::to_string(s.tracks.tracks_started()) + " tracks" +
         (s.prior ? ", monocular prior in " + std::to_string(s.prior_frames) : std::string()) +
         (s.tracks.frame_times().count() ? ", " + s.tracks.frame_times().describe("frame set")
                                         : std::string());
}

}  // namespace mocap::fit
