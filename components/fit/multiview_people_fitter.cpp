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

  explicit State(MultiViewPeopleFitOptions o) : options(std::move(o)) {}

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
          return input;
        });
      }
    }
    tracks.end_frame(t);
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
std::size_t MultiViewPeopleFitter::held_frames() const { return state_->tracks.held_frames(); }
const FitStats& MultiViewPeopleFitter::stats() const { return state_->tracks.stats(); }

std::string MultiViewPeopleFitter::summary() const {
  const State& s = *state_;
  return std::string(s.options.mode == StreamFitMode::live ? "live" : "full") +
         " fit: " + std::to_string(s.tracks.placed()) + " of " + std::to_string(s.people) +
         " person-frames fitted, " + std::to_string(s.tracks.tracks_started()) + " tracks";
}

}  // namespace mocap::fit
