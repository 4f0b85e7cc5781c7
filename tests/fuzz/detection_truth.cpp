// Fuzz target: a detection ground-truth file (eval/detection_truth.hpp); what parses is scored
// against a fixed detection.

#include "eval/detection_truth.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  try {
    const eval::DetectionTruth truth =
        eval::parse_detection_truth(fuzz::text(data, size), "fuzz-truth.json");
    for (const eval::TruthFrame& f : truth.frames) {
      const auto s = eval::score_frame(f, {Box2D{10, 10, 20, 40}}, 0.5f);
      fuzz::check(s.matched <= s.truths && s.matched <= s.detections, "more matches than boxes");
    }
  } catch (const InputError& e) {
    fuzz::expect_named(e, "fuzz-truth.json");
  }
  return 0;
}
