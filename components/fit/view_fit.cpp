#include "fit/view_fit.hpp"

#include "fit/fit_evaluation.hpp"

namespace mocap::fit {

std::vector<FittedFrame> placed_retrieval(std::span<const FrameInput> inputs,
                                          const camera::Camera& camera) {
  std::vector<FittedFrame> out(inputs.size());
  for (std::size_t t = 0; t < inputs.size(); ++t) {
    if (!inputs[t].retrieved_valid) continue;
    const auto tr = initial_translation(inputs[t].retrieved, inputs[t].keypoints, camera);
    if (!tr) continue;
    out[t].valid = true;
    out[t].observed = true;
    for (int j = 0; j < kBodyJoints; ++j)
      out[t].joints[j] = inputs[t].retrieved[j] + glm::vec3(*tr);
  }
  return out;
}

ViewFits reconstruct_and_fit(recon::Matcher& matcher, const recon::FrameBones& bones,
                             const ContactDetector* contacts, std::span<const recon::BodyXyc> input,
                             const recon::SequenceOptions& retrieval, const FitOptions& options,
                             ViewFitRequest request) {
  ViewFits out;
  out.retrieved = recon::reconstruct_sequence(matcher, bones, input, retrieval);
  const auto inputs = make_inputs(
      input, out.retrieved,
      contacts ? contacts->contacts(out.retrieved) : std::vector<std::array<bool, 2>>{}, {});
  out.placed = placed_retrieval(inputs, options.camera);
  if (request.full) out.full = fit_sequence(inputs, options).frames;
  if (request.live) {
    LiveFitter live(options);
    for (const auto& in : inputs)
      if (auto f = live.push(in)) out.live.push_back(*f);
    for (auto& f : live.finish()) out.live.push_back(f);
  }
  return out;
}

}  // namespace mocap::fit
