// Fuzz target: ASF skeletons and AMC motions (motion/asf_amc.hpp). The input is an ASF text,
// optionally followed by a line "@@AMC@@" and an AMC text read against that skeleton.

#include "motion/asf_amc.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  std::string_view asf = fuzz::text(data, size), amc;
  const bool has_amc = fuzz::split(fuzz::text(data, size), "\n@@AMC@@\n", asf, amc);
  motion::AsfSkeleton skeleton;
  try {
    skeleton = motion::parse_asf(asf, "fuzz-input.asf");
  } catch (const InputError& e) {
    fuzz::expect_named(e, "fuzz-input.asf");
    return 0;
  }
  const motion::Skeleton rest = motion::to_skeleton(skeleton);
  if (!has_amc) return 0;
  try {
    const motion::Clip clip = motion::parse_amc(skeleton, amc, "fuzz-input.amc");
    fuzz::check(clip.values.size() ==
                    static_cast<std::size_t>(clip.frame_count) * clip.skeleton.channel_count,
                "clip values do not match frames x channels");
  } catch (const InputError& e) {
    // A skeleton the motion cannot use (no degrees of freedom) is the ASF's fault.
    if (std::string_view(e.what()).find("fuzz-input.asf") == std::string_view::npos)
      fuzz::expect_named(e, "fuzz-input.amc");
  }
  return 0;
}
