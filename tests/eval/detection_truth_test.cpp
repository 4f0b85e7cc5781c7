// The detection ground truth: its file format (errors name file and key) and the matching rule
// behind recall and precision.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

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

// The hand-checked files themselves (tests/data/detection/README.md): every box lies in the frame,
// every counted person is at least min_height tall unless the frame's border cuts them, and
// vtest_part0.json (the first 200 frames of vtest.avi) holds exactly the truth of vtest.json there.
TEST(DetectionTruth, CommittedFilesAreConsistent) {
  const std::filesystem::path dir = "tests/data/detection";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << dir << " is absent";
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json" || entry.path().filename() == "tfjs_reference.json")
      continue;
    ++files;
    const DetectionTruth t = read_detection_truth(entry.path());
    for (const TruthFrame& f : t.frames) {
      const std::string where =
          entry.path().filename().string() + " frame " + std::to_string(f.frame);
      for (const auto* boxes : {&f.people, &f.ignore}) {
        for (const Box2D& b : *boxes) {
          EXPECT_TRUE(b.x >= 0 && b.y >= 0 && b.x + b.width <= t.width &&
                      b.y + b.height <= t.height)
              << where << ": a box leaves the " << t.width << "x" << t.height << " frame";
        }
      }
      for (const Box2D& b : f.people) {
        const bool cut =
            b.x <= 0 || b.y <= 0 || b.x + b.width >= t.width || b.y + b.height >= t.height;
        EXPECT_TRUE(cut || b.height >= t.min_height)
            << where << ": a person " << b.height << " px tall belongs in 'ignore'";
      }
    }
  }
  EXPECT_GE(files, 1);

  if (!std::filesystem::exists(dir / "vtest.json") ||
      !std::filesystem::exists(dir / "vtest_part0.json"))
    return;
  const DetectionTruth whole = read_detection_truth(dir / "vtest.json");
  const DetectionTruth part = read_detection_truth(dir / "vtest_part0.json");
  std::vector<const TruthFrame*> early;
  for (const TruthFrame& f : whole.frames)
    if (f.frame < 200) early.push_back(&f);
  ASSERT_EQ(part.frames.size(), early.size());
  const auto same = [](const std::vector<Box2D>& a, const std::vector<Box2D>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const Box2D& p, const Box2D& q) {
      return p.x == q.x && p.y == q.y && p.width == q.width && p.height == q.height;
    });
  };
  for (std::size_t i = 0; i < early.size(); ++i) {
    EXPECT_EQ(part.frames[i].frame, early[i]->frame);
    EXPECT_TRUE(same(part.frames[i].people, early[i]->people)) << "frame " << early[i]->frame;
    EXPECT_TRUE(same(part.frames[i].ignore, early[i]->ignore)) << "frame " << early[i]->frame;
  }
}

}  // namespace
}  // namespace mocap::eval
