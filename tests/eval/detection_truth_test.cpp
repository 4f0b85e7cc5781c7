// The detection ground truth: its file format (errors name file and key) and the matching rule
// behind recall and precision.

#include <gtest/gtest.h>

#include <filesystem>

#include "core/input_error.hpp"
#include "eval/detection_truth.hpp"

namespace mocap::eval {
namespace {

TEST(DetectionTruth, ReadsFramesPeopleAndIgnoredBoxes) {
  const DetectionTruth t = parse_detection_truth(
      R"({"input": "v.avi", "width": 640, "height": 480, "min_height": 40, "frames": [
          {"frame": 0, "people": [[10, 20, 30, 80]], "ignore": [[100, 100, 110, 120]]},
          {"frame": 9}]})",
      "t.json");
  EXPECT_EQ(t.input, "v.avi");
  EXPECT_EQ(t.width, 640);
  ASSERT_EQ(t.frames.size(), 2u);
  ASSERT_EQ(t.frames[0].people.size(), 1u);
  EXPECT_FLOAT_EQ(t.frames[0].people[0].width, 20);
  EXPECT_FLOAT_EQ(t.frames[0].people[0].height, 60);
  EXPECT_EQ(t.frames[0].ignore.size(), 1u);
  EXPECT_EQ(t.frames[1].frame, 9);
  EXPECT_TRUE(t.frames[1].people.empty());
}

TEST(DetectionTruth, ErrorsNameTheFileAndTheKey) {
  const auto error = [](const char* text) {
    try {
      parse_detection_truth(text, "truth.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("{").find("truth.json: not valid JSON"), std::string::npos);
  EXPECT_NE(error(R"({"input": "v", "width": 1, "height": 1, "min_height": 40})").find("'frames'"),
            std::string::npos);
  EXPECT_NE(error(R"({"input": "v", "width": 1, "height": 1, "min_height": 40,
                      "frames": [{"frame": 0, "people": [[5, 5, 1, 9]]}]})")
                .find("truth.json: frames[0].people[0]"),
            std::string::npos);
  EXPECT_NE(error(R"({"input": "v", "width": 1, "height": 1, "min_height": 40,
                      "frames": [{"frame": 4}, {"frame": 4}]})")
                .find("ascend"),
            std::string::npos);
  EXPECT_THROW(read_detection_truth("/nonexistent/truth.json"), InputError);
}

TEST(DetectionTruth, MatchesBestFirstEachTruthOnceAndIgnoresTheIgnored) {
  TruthFrame f;
  f.people = {{0, 0, 20, 60}, {100, 0, 20, 60}};
  f.ignore = {{300, 0, 8, 20}};
  // A good match, a duplicate of it, a detection on an ignored person, a false one.
  const FrameScore s =
      score_frame(f, {{1, 1, 20, 60}, {0, 2, 20, 58}, {301, 0, 7, 19}, {500, 0, 20, 60}}, 0.5f);
  EXPECT_EQ(s.truths, 2);
  EXPECT_EQ(s.matched, 1);
  EXPECT_EQ(s.detections, 3);  // the ignored one is not counted
  EXPECT_EQ(s.match, (std::vector<int>{0, -1, -2, -1}));
  // Below the IoU the detection does not count as found.
  EXPECT_EQ(score_frame(f, {{10, 30, 20, 60}}, 0.5f).matched, 0);
}

}  // namespace
}  // namespace mocap::eval
