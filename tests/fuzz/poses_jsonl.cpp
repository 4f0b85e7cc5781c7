// Fuzz target: a poses.jsonl recording as `mocap view` plays it (web/recording.hpp
// parse_poses_jsonl): frames and times in step, times from 0 and never going back.

#include <sstream>

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "web/recording.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.jsonl";
  std::istringstream in{std::string(fuzz::text(data, size))};
  try {
    const web::Recording r = web::parse_poses_jsonl(in, name, 30.0);
    fuzz::check(!r.frames.empty() && r.frames.size() == r.times.size(), "frames and times differ");
    fuzz::check(r.times.front() == 0.0, "times do not start at 0");
    for (std::size_t i = 1; i < r.times.size(); ++i)
      fuzz::check(r.times[i] >= r.times[i - 1], "times go back");
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
