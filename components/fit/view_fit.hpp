#pragma once
// One person seen by one static, calibrated camera, through retrieval and then the skeleton
// fitting (library mocap_fit_eval), as the evaluations with real cameras (HumanEva-I, Pose2Sim)
// run it: the retrieval's poses placed by the closed-form translation (what the fit starts
// from), the full-sequence fit and the fixed-lag live fit.

#include <span>
#include <vector>

#include "fit/foot_contact.hpp"
#include "fit/skeleton_fit.hpp"
#include "recon/sequence_reconstruction.hpp"

namespace mocap::fit {

// The retrieval's poses placed by the closed-form translation (initial_translation): frames
// without a retrieved pose or a translation are invalid.
std::vector<FittedFrame> placed_retrieval(std::span<const FrameInput> inputs,
                                          const camera::Camera& camera);

struct ViewFitRequest {
  bool full = true;  // fit_sequence
  bool live = true;  // LiveFitter with FitOptions::lag
};

struct ViewFits {
  std::vector<recon::Pose3D> retrieved;  // root-relative, camera frame
  std::vector<FittedFrame> placed;       // retrieved + closed-form translation
  std::vector<FittedFrame> full, live;   // empty when not requested
};

// Reconstructs `input` (one person's keypoints per frame) with `retrieval` (its camera should be
// `options.camera` for the ray alignment) and fits it with `options.camera` (static, placed in
// the world of `options.ground`). Contacts come from `contacts` when given.
ViewFits reconstruct_and_fit(recon::Matcher& matcher, const recon::FrameBones& bones,
                             const ContactDetector* contacts, std::span<const recon::BodyXyc> input,
                             const recon::SequenceOptions& retrieval, const FitOptions& options,
                             ViewFitRequest request = {});

}  // namespace mocap::fit
