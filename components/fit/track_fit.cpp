#include "fit/track_fit.hpp"

#include <map>
#include <utility>

#include "fit/multiview_input.hpp"

namespace mocap::fit {

TrackFits fit_tracks(std::span<const multiview::FrameObservations> input,
                     std::vector<multiview::FrameResult>& results,
                     const MultiViewFitOptions& options, bool live,
                     const multiview::KeypointSet& set, MonocularPrior* prior) {
  // Each track's (frame, person) in frame order.
  std::map<int, std::vector<std::pair<std::size_t, std::size_t>>> tracks;
  for (std::size_t f = 0; f < results.size() && f < input.size(); ++f)
    for (std::size_t p = 0; p < results[f].people.size(); ++p)
      if (results[f].people[p].id >= 0) tracks[results[f].people[p].id].emplace_back(f, p);
  TrackFits out;
  for (const auto& [id, seen] : tracks) {
    const std::size_t first = seen.front().first, last = seen.back().first;
    std::vector<MultiViewFrameInput> frames(last + 1 - first);
    for (const auto& [f, p] : seen) {
      MultiViewFrameInput& frame = frames[f - first];
      multiview_input(input[f], results[f], p, set, frame);
      if (prior && prior->add(frame, results[f].body_of(p), options.cameras)) ++out.prior_frames;
    }
    if (prior) prior->settle_runs(frames, live);
    std::vector<FittedFrame> fitted;
    if (live) {
      MultiViewLiveFitter fitter(options);
      for (const auto& frame : frames)
        for (auto& r : fitter.push(frame)) fitted.push_back(r);
      for (auto& r : fitter.finish()) fitted.push_back(r);
      const FitStats& s = fitter.stats();
      out.stats.solves += s.solves, out.stats.iterations += s.iterations;
    } else {
      FitResult r = fit_multiview_sequence(frames, options);
      out.stats.solves += r.stats.solves, out.stats.iterations += r.stats.iterations;
      fitted = std::move(r.frames);
    }
    ++out.tracks;
    for (const auto& [f, p] : seen) {
      const FittedFrame& body = fitted[f - first];
      if (!body.valid) continue;
      multiview::FrameResult& result = results[f];
      const std::uint64_t views = result.people[p].views != 0 ? result.people[p].views : 1;
      for (int j = 0; j < kBodyJoints; ++j) {
        multiview::TriangulatedPoint& point =
            result.body_points[p * static_cast<std::size_t>(kBodyJoints) + j];
        point.position = body.joints[j];
        if (!point.valid()) point.views = views;
      }
      ++out.person_frames;
    }
  }
  return out;
}

}  // namespace mocap::fit
