#pragma once
// The per-person bookkeeping the two stream fitters share (PeopleFitter, one camera;
// MultiViewPeopleFitter, a rig): frames held until every person in them is decided
// (recon::HeldFrames), each person id a track with its own fitter (Live, fixed lag, or Windowed,
// windows), the frames a track missed pushed as gaps, a track ended once its person has been
// missing for more than `max_missed` frames, and at the end every track finished, within a shared
// budget after a stop. What differs stays with the owner: how a person becomes a fitter's input,
// and what a placed frame also feeds (the single-camera floor estimate).
//
// Options: mode, fit (the fitters' options, read when a track starts), window, max_missed,
// stop_budget (PeopleFitOptions, MultiViewPeopleFitOptions). Live::push returns an optional or a
// vector of FittedFrame; Windowed::push(input, solve) and Windowed::finish(budget) a vector.

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "core/messages.hpp"
#include "fit/frame_times.hpp"
#include "fit/people_fitter.hpp"
#include "fit/skeleton_fit.hpp"
#include "recon/held_frames.hpp"

namespace mocap::fit {

inline void add(FitStats& total, const FitStats& s) {
  total.solves += s.solves;
  total.iterations += s.iterations;
  total.frame_iterations += s.frame_iterations;
  total.initial_cost += s.initial_cost;
  total.final_cost += s.final_cost;
}

template <class Options, class Input, class Live, class Windowed>
class TrackFitters {
 public:
  using Contact = std::array<bool, 2>;
  // Called for each person-frame placed, with the fit and the contact of the input it came from.
  using OnPlaced = std::function<void(const FittedFrame&, const Contact&)>;

  // `options` must outlive this (the owner's, which may change `fit` between tracks); `gap` is
  // the input of a frame where the person is absent.
  TrackFitters(const Options& options, Input gap, OnPlaced on_placed = {})
      : options_(options), gap_(std::move(gap)), on_placed_(std::move(on_placed)) {}

  // Holds a frame until each of `ids` is decided in it; returns its index. The frame's time
  // (frame_times()) runs from here to its end_frame().
  std::int64_t hold(People3D frame, std::vector<int> ids) {
    times_.start();
    return held_.hold(std::move(frame), std::move(ids));
  }
  const People3D& frame(std::int64_t t) { return *held_.find(t); }
  // The input pushed for a person absent from a frame: the owner may set what depends on the
  // frame (its time) before the frame's see() and end_frame().
  Input& gap() { return gap_; }

  // Person `id` seen in held frame `t`: their track (started if new) gets the frames it missed as
  // gaps, then `make_input()`. The id twice in one frame: the first one counts.
  template <class MakeInput>
  void see(int id, std::int64_t t, MakeInput&& make_input) {
    const auto [it, added] = tracks_.try_emplace(id);
    Track& track = it->second;
    if (added) start(track, t);
    if (track.next_frame > t) return;
    while (track.next_frame < t) push(id, track, gap_);  // frames it missed
    const auto& in = make_input();  // after the gaps: the owner may reuse one input
    push(id, track, in);
    track.last_seen = t;
  }

  // After the people of frame `t`: a gap for each track absent from it; a track missing for
  // more than max_missed frames ends (solved now).
  void end_frame(std::int64_t t) {
    for (auto it = tracks_.begin(); it != tracks_.end();) {
      Track& track = it->second;
      if (track.next_frame <= t) push(it->first, track, gap_);  // absent this frame
      if (t - track.last_seen > options_.max_missed) {
        finish(it->first, track, std::nullopt);
        it = tracks_.erase(it);
      } else {
        ++it;
      }
    }
    times_.stop();
  }

  // A stop is under way: windows wait for finish_all(), which then solves them quickly.
  void stop() { stopping_ = true; }
  bool stopping() const { return stopping_; }

  // The end of the stream: every track finished. After a stop, the tracks share the budget's
  // time: each gets an equal part of what is left; once too little is left for a solve, the rest
  // leave unplaced.
  void finish_all() {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    std::size_t left = tracks_.size();
    for (auto& [id, track] : tracks_) {
      std::optional<SolveBudget> budget;
      if (stopping_) {
        const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
        const double share = (options_.stop_budget.seconds - elapsed) / static_cast<double>(left);
        budget = SolveBudget{options_.stop_budget.iterations, share >= 0.005 ? share : 0.0};
      }
      finish(id, track, budget);
      --left;
    }
    tracks_.clear();
  }

  // The frames whose people are all decided leave, oldest first (all of them: release_all).
  template <class Release>
  void release_decided(Release&& release) {
    held_.release_decided(std::forward<Release>(release));
  }
  template <class Release>
  void release_all(Release&& release) {
    held_.release_all(std::forward<Release>(release));
  }

  // A new floor for every fitter (fitters of Live/Windowed types that have set_ground).
  template <class Plane>
  void set_ground(const Plane& plane) {
    for (auto& [id, track] : tracks_) {
      if (track.live) track.live->set_ground(plane);
      if (track.windowed) track.windowed->set_ground(plane);
    }
  }

  std::int64_t next_index() const { return held_.next_index(); }
  std::size_t held_frames() const { return held_.size(); }
  std::int64_t placed() const { return placed_; }  // person-frames placed
  std::int64_t tracks_started() const { return started_; }
  const FrameTimes& frame_times() const { return times_; }  // hold() to end_frame(), per frame
  FitStats& stats() { return stats_; }  // of the finished tracks (the owner may add its own)
  const FitStats& stats() const { return stats_; }

 private:
  struct Track {
    std::int64_t next_frame = 0;   // held index of the next frame pushed into the fitter
    std::int64_t next_output = 0;  // held index of the fitter's next output
    std::int64_t last_seen = 0;
    std::optional<Live> live;
    std::optional<Windowed> windowed;
    std::deque<Contact> contacts;  // of the frames pushed and not output yet
  };

  void start(Track& track, std::int64_t t) {
    track.next_frame = track.next_output = track.last_seen = t;
    ++started_;
    if (options_.mode == StreamFitMode::live)
      track.live.emplace(options_.fit);
    else
      track.windowed.emplace(options_.fit, options_.window);
  }

  void push(int id, Track& track, const Input& in) {
    ++track.next_frame;
    track.contacts.push_back(in.contact);
    if (track.live)
      place_all(id, track, track.live->push(in));
    else
      place_all(id, track, track.windowed->push(in, !stopping_));
  }

  void finish(int id, Track& track, std::optional<SolveBudget> budget) {
    if (track.live) {
      place_all(id, track, track.live->finish());
      add(stats_, track.live->stats());
    } else {
      place_all(id, track, track.windowed->finish(budget));
      add(stats_, track.windowed->stats());
    }
  }

  void place_all(int id, Track& track, const std::optional<FittedFrame>& fitted) {
    if (fitted) place(id, track, *fitted);
  }
  void place_all(int id, Track& track, const std::vector<FittedFrame>& fitted) {
    for (const FittedFrame& f : fitted) place(id, track, f);
  }

  // A fitter's output for the track's next output frame: placed into that frame (when the person
  // is in it) and the person decided there. Not valid or not observed: the person is decided and
  // keeps the joints they came with.
  void place(int id, Track& track, const FittedFrame& fitted) {
    const std::int64_t frame = track.next_output++;
    const Contact contact = track.contacts.empty() ? Contact{} : track.contacts.front();
    if (!track.contacts.empty()) track.contacts.pop_front();
    People3D* out = held_.find(frame);
    if (out == nullptr || !held_.decide(frame, id)) return;  // absent from that frame
    if (!fitted.valid || !fitted.observed) return;
    for (Person3D& person : out->people) {
      if (person.id != id) continue;
      const glm::vec3 root = fitted.root();
      for (int j = 0; j < kBodyJoints; ++j) person.positions[j] = fitted.joints[j] - root;
      person.root.translation = root;
      person.placed = true;
      ++placed_;
      if (on_placed_) on_placed_(fitted, contact);
    }
  }

  const Options& options_;
  Input gap_;
  OnPlaced on_placed_;
  std::map<int, Track> tracks_;
  recon::HeldFrames<People3D> held_;
  bool stopping_ = false;
  std::int64_t placed_ = 0, started_ = 0;
  FitStats stats_;
  FrameTimes times_;
};

}  // namespace mocap::fit
