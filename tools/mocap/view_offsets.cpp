#include "view_offsets.hpp"

#include <iostream>

namespace mocap::cli {

ViewOffsets estimate_view_offsets(const camera::Rig& rig, const std::vector<std::string>& folders,
                                  const io::OpenPoseOptions& json, std::size_t reference,
                                  const camera::OffsetOptions& options, const std::string& who) {
  std::vector<camera::BodySequence> views;
  for (const std::string& folder : folders) {
    const io::OpenPoseSequence sequence = io::read_openpose_folder(folder, json);
    for (const io::FrameProblem& p : sequence.problems)
      std::cerr << who << ": " << folder << ": " << p.message << "\n";
    views.push_back(camera::body_sequence(sequence.frames));
  }
  ViewOffsets out;
  for (const camera::BodySequence& v : views) out.frames.push_back(v.size());
  out.offsets = camera::estimate_offsets(rig.cameras, views, reference, options);
  return out;
}

}  // namespace mocap::cli
