// Fuzz target: one OpenPose *_keypoints.json file (io/openpose_json.hpp), as BODY_25 and as
// BODY_25B.

#include "io/openpose_json.hpp"
#include "core/input_error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  for (const io::Body25Choice choice :
       {io::Body25Choice::body25, io::Body25Choice::body25b, io::Body25Choice::detect}) {
    io::OpenPoseOptions options;
    options.body25 = choice;
    try {
      const People2D people =
          io::parse_openpose_json(fuzz::text(data, size), "fuzz-input.json", options);
      for (const Person2D& p : people.people)
        fuzz::check(p.joints.size() == people.people.front().joints.size(),
                    "people with different joint counts");
    } catch (const InputError& e) {
      fuzz::expect_named(e, "fuzz-input.json");
    }
  }
  return 0;
}
