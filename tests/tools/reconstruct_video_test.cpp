// `mocap reconstruct VIDEO` end to end, through the built binary: the first frames of the shared
// vtest video become poses.jsonl (one line per frame, its time in the video), BVH files, an
// overlay video (a picture per frame) and a summary; a missing model, a truncated or unreadable
// video and an absent camera each end the run with exit code 1 and a message naming the problem.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "detect/singlepose.hpp"
#include "support/mocap_process.hpp"
#include "support/models.hpp"
#include "support/shared_data.hpp"
#include "video/video_source.hpp"

namespace mocap {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kVideo = test::shared_data() / "eval" / "opencv_samples" / "vtest_part0.avi";

class ReconstructVideoTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path mocap = test::shared_data() / "mocap" / "cmu31";
    if (!fs::exists(mocap / "08_01.bvh") || !fs::exists(kVideo)) return;
    dir_ = std::make_unique<test::TempDir>();
    test::Mocap build(
        *dir_, "build",
        {"db", "build", (mocap / "08_01.bvh").string(), (mocap / "09_12.bvh").string(),
         "--clusters", "32", "--out", dir_->file("db.mdb")});
    ASSERT_EQ(build.wait(120s), 0) << build.err();
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override {
    if (!dir_) GTEST_SKIP() << "shared data absent (../shared/data/mocap/cmu31, " << kVideo << ")";
  }
  static test::Mocap reconstruct(const std::string& name, const std::string& input,
                                 std::vector<std::string> extra = {},
                                 std::vector<std::string> env = {}) {
    std::vector<std::string> args = {"reconstruct",        input,   "--db",
                                     dir_->file("db.mdb"), "--out", dir_->file(name)};
    args.insert(args.end(), extra.begin(), extra.end());
    return test::Mocap(*dir_, name, args, std::move(env));
  }
  static inline std::unique_ptr<test::TempDir> dir_;
};

TEST_F(ReconstructVideoTest, AVideoBecomesPosesBvhAndAnOverlayVideo) {
  MOCAP_REQUIRE_MOVENET();
  auto run =
      reconstruct("out", kVideo.string(),
                  {"--detector", "multipose", "--detector-size", "384", "--set", "src.count=30"});
  ASSERT_EQ(run.wait(300s), 0) << run.err();
  const std::string out = dir_->file("out");
  const auto lines = test::read_lines(out + "/poses.jsonl");
  ASSERT_EQ(lines.size(), 30u);
  std::size_t people = 0, placed = 0, grounded = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const auto j = nlohmann::json::parse(lines[i]);
    EXPECT_EQ(j.at("frame").get<std::size_t>(), i);
    EXPECT_NEAR(j.at("time").get<double>(), 0.1 * static_cast<double>(i), 0.011);  // 10 fps
    people += j.at("people").size();
    for (const auto& person : j.at("people")) {
      if (!person.contains("joints_abs")) continue;
      ++placed;
      const auto& root = person.at("joints_abs").at("root");
      EXPECT_GT(root[2].get<double>(), 1.0);  // in front of the camera, in the mall
      EXPECT_LT(root[2].get<double>(), 60.0);
      if (!j.contains("ground")) continue;
      // The fitted hips stand at hip height over the floor estimated from the feet.
      const auto& n = j.at("ground").at("normal");
      double height = j.at("ground").at("offset").get<double>();
      for (int k = 0; k < 3; ++k) height += n[k].get<double>() * root[k].get<double>();
      EXPECT_GT(height, 0.5);
      EXPECT_LT(height, 1.3);
      ++grounded;
    }
  }
  EXPECT_GT(people, 30u);              // pedestrians are found: more than one per frame on average
  EXPECT_GE(placed, people * 9 / 10);  // the fit (full, by default for a file) placed them
  EXPECT_GT(grounded, 0u);
  // The overlay has a picture per frame, each drawn over its video frame read again from the file
  // (sink.overlay's video_path, set by reconstruct for files).
  video::VideoSource overlay(out + "/overlay.mp4");
  int pictures = 0;
  while (overlay.read()) ++pictures;
  EXPECT_EQ(pictures, 30);
  EXPECT_EQ(overlay.width(), 1280);  // two 640 x 480 panels for the 768 x 576 video
  EXPECT_NE(run.err().find("30 video frames read again"), std::string::npos) << run.err();
  bool bvh = false;
  for (const auto& e : fs::directory_iterator(out)) bvh = bvh || e.path().extension() == ".bvh";
  EXPECT_TRUE(bvh);
  const auto summary = nlohmann::json::parse(test::read_file(out + "/summary.json"));
  EXPECT_EQ(summary.at("video").at("width"), 768);
  EXPECT_EQ(summary.at("video").at("height"), 576);
  EXPECT_EQ(summary.at("detector").at("type"), "detect.movenet");
  EXPECT_EQ(summary.at("detector").at("params").at("input_size"), "384");
  EXPECT_EQ(summary.at("frames"), 30);
  EXPECT_EQ(summary.at("fit"), "full");
  EXPECT_NE(run.out().find(out + "/overlay.mp4"), std::string::npos) << run.out();
}

// The BlazePose preset puts BlazePose full in the top-down node and finds the pedestrians.
TEST_F(ReconstructVideoTest, TheBlazePosePresetFindsThePedestrians) {
  try {
    detect::cached_model_json(detect::model_name(detect::SinglePoseModel::blazepose_full));
  } catch (const detect::ModelMissing&) {
    GTEST_SKIP() << "BlazePose full absent: tools/setup.sh --models-only";
  }
  auto run = reconstruct("blaze", kVideo.string(),
                         {"--detector", "topdown-blaze", "--fit", "off", "--set", "src.count=5"});
  ASSERT_EQ(run.wait(300s), 0) << run.err();
  const auto summary =
      nlohmann::json::parse(test::read_file(dir_->file("blaze") + "/summary.json"));
  EXPECT_EQ(summary.at("detector").at("type"), "detect.topdown");
  EXPECT_EQ(summary.at("detector").at("params").at("pose_model"), "blazepose-full");
  std::size_t people = 0;
  for (const auto& line : test::read_lines(dir_->file("blaze") + "/poses.jsonl"))
    people += nlohmann::json::parse(line).at("people").size();
  EXPECT_GE(people, 5u * 3);  // 4-6 walkers in view on these frames
}

TEST_F(ReconstructVideoTest, AMissingModelNamesTheSetupCommand) {
  auto run = reconstruct("nomodel", kVideo.string(), {}, {"MOCAP_MODEL_DIR=/nonexistent"});
  ASSERT_EQ(run.wait(60s), 1) << run.err();
  EXPECT_NE(run.err().find("tools/setup.sh --models-only"), std::string::npos) << run.err();
}

TEST_F(ReconstructVideoTest, ATruncatedVideoEndsWithAnErrorNamingIt) {
  MOCAP_REQUIRE_MOVENET();
  const std::string cut = dir_->file("cut.avi");
  const std::string bytes = test::read_file(kVideo.string());
  test::write_file(cut, bytes.substr(0, bytes.size() / 10));
  auto run = reconstruct("cut", cut);
  ASSERT_EQ(run.wait(300s), 1) << run.err();
  EXPECT_NE(run.err().find(cut), std::string::npos) << run.err();
  EXPECT_NE(run.err().find("truncated"), std::string::npos) << run.err();
  // The frames before the cut are written, and the files are complete.
  const auto lines = test::read_lines(dir_->file("cut") + "/poses.jsonl");
  EXPECT_GT(lines.size(), 5u);
  for (const auto& line : lines)
    EXPECT_FALSE(nlohmann::json::parse(line, nullptr, false).is_discarded()) << line;
}

TEST_F(ReconstructVideoTest, UnreadableInputsAndAnAbsentCameraAreRefusedByName) {
  const std::string noise = dir_->file("noise.avi");
  std::string bytes(100000, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 7919) % 251);
  test::write_file(noise, bytes);
  auto garbage = reconstruct("noise", noise);
  ASSERT_EQ(garbage.wait(60s), 1) << garbage.err();
  EXPECT_NE(garbage.err().find(noise), std::string::npos) << garbage.err();

  if (!fs::exists("/dev/video9")) {
    auto camera = reconstruct("camera", "/dev/video9");
    ASSERT_EQ(camera.wait(60s), 1) << camera.err();
    EXPECT_NE(camera.err().find("/dev/video9: no such camera device"), std::string::npos)
        << camera.err();
  }
  auto missing = reconstruct("missing", dir_->file("nothing.mp4"));
  ASSERT_EQ(missing.wait(60s), 1) << missing.err();
  EXPECT_NE(missing.err().find("no such file"), std::string::npos) << missing.err();
}

}  // namespace
}  // namespace mocap
