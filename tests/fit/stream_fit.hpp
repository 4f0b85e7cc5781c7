#pragma once
// The stream's multi-view fitter driven over a reconstructed scene, as multiview.reconstruct
// drives it: shared by the fit tests.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fit/multiview_people_fitter.hpp"

namespace mocap::test {

// Pushes the frames `frames` (indices into `input` and `results`, the scene's observations and
// reconstruction) through `fitter`, frame i numbered `numbers[i]`, then finishes it: every set it
// emitted, in order. Each set holds the ids the reconstruction tracked.
inline std::vector<People3D> fit_stream(fit::MultiViewPeopleFitter& fitter,
                                        std::span<const multiview::FrameObservations> input,
                                        std::span<const multiview::FrameResult> results,
                                        const std::vector<std::size_t>& frames,
                                        const std::vector<std::int64_t>& numbers) {
  std::vector<People3D> out;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::size_t f = frames[i];
    People3D frame;
    frame.header.frame = numbers[i];
    frame.header.seq = i;
    for (const auto& person : results[f].people)
      if (person.id >= 0) frame.people.emplace_back().id = person.id;
    for (People3D& done :
         fitter.push(input[f], results[f], multiview::KeypointSet::body15(), std::move(frame)))
      out.push_back(std::move(done));
  }
  for (People3D& done : fitter.finish()) out.push_back(std::move(done));
  return out;
}

// Every frame, in order, numbered from 0.
inline std::vector<People3D> fit_stream(fit::MultiViewPeopleFitter& fitter,
                                        std::span<const multiview::FrameObservations> input,
                                        std::span<const multiview::FrameResult> results) {
  std::vector<std::size_t> frames(results.size());
  std::vector<std::int64_t> numbers(results.size());
  for (std::size_t f = 0; f < results.size(); ++f) {
    frames[f] = f;
    numbers[f] = static_cast<std::int64_t>(f);
  }
  return fit_stream(fitter, input, results, frames, numbers);
}

}  // namespace mocap::test
