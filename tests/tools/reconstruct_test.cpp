// `mocap reconstruct` end to end, through the built binary: real OpenPose JSON of several people,
// with a malformed file and a missing frame: the run reports both, goes on, and writes one line
// per input frame, a BVH per person and a summary.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "camera/camera_file.hpp"
#include "core/body15.hpp"
#include "motion/bvh.hpp"
#include "support/mocap_process.hpp"
#include "support/shared_data.hpp"

namespace mocap {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class ReconstructTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path mocap = test::shared_data() / "mocap" / "cmu31";
    const fs::path json = test::shared_data() / "eval" / "openpose_json" / "json";
    if (!fs::exists(mocap / "08_01.bvh") || !fs::exists(json)) return;
    dir_ = std::make_unique<test::TempDir>();
    test::Mocap build(
        *dir_, "build",
        {"db", "build", (mocap / "08_01.bvh").string(), (mocap / "09_12.bvh").string(),
         "--clusters", "32", "--out", dir_->file("db.mdb")});
    ASSERT_EQ(build.wait(120s), 0) << build.err();
    // The first 40 frames of the badminton clip; frame 7 truncated, frame 12 missing.
    fs::create_directories(dir_->path() / "input");
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(json)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (std::size_t i = 0; i < 40; ++i) {
      const fs::path target = dir_->path() / "input" / files[i].filename();
      if (i == 12) continue;
      if (i == 7) {
        const std::string text = test::read_file(files[i].string());
        test::write_file(target.string(), text.substr(0, text.size() / 2));
      } else {
        fs::copy_file(files[i], target);
      }
    }
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override {
    if (!dir_)
      GTEST_SKIP()
          << "shared data absent (../shared/data/mocap/cmu31, ../shared/data/eval/openpose_json)";
  }
  static inline std::unique_ptr<test::TempDir> dir_;
};

TEST_F(ReconstructTest, DamagedInputIsReportedAndEveryFrameIsWritten) {
  const std::string out = dir_->file("out");
  test::Mocap run(*dir_, "reconstruct",
                  {"reconstruct", (dir_->path() / "input").string(), "--db", dir_->file("db.mdb"),
                   "--out", out});
  ASSERT_EQ(run.wait(300s), 0) << run.err();
  const std::string err = run.err();
  EXPECT_NE(err.find("000000000007_keypoints.json"), std::string::npos)
      << err;                                           // the truncated file
  EXPECT_NE(err.find("12"), std::string::npos) << err;  // the missing frame

  const auto lines = test::read_lines(out + "/poses.jsonl");
  ASSERT_EQ(lines.size(), 40u);
  int people_frames = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const auto j = nlohmann::json::parse(lines[i]);
    EXPECT_EQ(j.at("frame").get<std::size_t>(), i);
    EXPECT_NEAR(j.at("time").get<double>(), static_cast<double>(i) / 30.0, 1e-6);
    for (const auto& p : j.at("people")) {
      ++people_frames;
      ASSERT_EQ(p.at("joints").size(), static_cast<std::size_t>(kBodyJoints));
      const auto root = p.at("joints").at("root");
      EXPECT_EQ(root[0].get<double>(), 0.0);  // root-relative
      const auto head = p.at("joints").at("head");
      EXPECT_LT(head[1].get<double>(),
                -0.15);  // the head is above the root (y down), seated people too
    }
    if (i == 7 || i == 12) {
      EXPECT_TRUE(j.at("people").empty()) << "frame " << i;
    }
  }
  EXPECT_GT(people_frames, 38 * 6);  // 7-12 people in every good frame

  const auto summary = nlohmann::json::parse(test::read_file(out + "/summary.json"));
  EXPECT_EQ(summary.at("frames"), 40);
  EXPECT_GE(summary.at("people").get<int>(), 7);
  EXPECT_TRUE(summary.at("completed").get<bool>());
  EXPECT_TRUE(summary.at("nodes").contains("match"));

  int bvh_files = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    if (e.path().extension() != ".bvh") continue;
    ++bvh_files;
    const motion::Clip clip = motion::read_bvh(e.path().string());
    EXPECT_GT(clip.frame_count, 0) << e.path();
    EXPECT_EQ(clip.skeleton.joint_count(), 38) << e.path();  // the cgspeed skeleton with End Sites
  }
  EXPECT_GE(bvh_files, 7);
}

TEST_F(ReconstructTest, MissingDatabaseOrInputGivesAClearError) {
  test::Mocap no_db(*dir_, "no_db",
                    {"reconstruct", (dir_->path() / "input").string(), "--db",
                     dir_->file("absent.mdb"), "--out", dir_->file("x")});
  EXPECT_EQ(no_db.wait(30s), 1);
  EXPECT_NE(no_db.err().find("mocap db build"), std::string::npos) << no_db.err();
  test::Mocap no_input(*dir_, "no_input",
                       {"reconstruct", dir_->file("nowhere"), "--db", dir_->file("db.mdb"), "--out",
                        dir_->file("y")});
  EXPECT_EQ(no_input.wait(30s), 1);
  EXPECT_NE(no_input.err().find("nowhere"), std::string::npos) << no_input.err();
}

// --layout-offsets auto re-scores the candidates in BODY_25's own joint definition: a real
// change of the output, every frame still written; a damaged offsets file stops the run by name.
TEST_F(ReconstructTest, LayoutOffsetsChangeTheMatchAndABadFileIsNamed) {
  const auto run = [&](const std::string& name, const std::string& setting) {
    test::Mocap r(*dir_, name,
                  {"reconstruct", (dir_->path() / "input").string(), "--db", dir_->file("db.mdb"),
                   "--out", dir_->file(name), "--layout-offsets", setting});
    const auto code = r.wait(120s);  // before reading stderr: argument order is unspecified
    return std::make_pair(code, r.err());
  };
  const auto [off_code, off_err] = run("off", "off");
  ASSERT_EQ(off_code, 0) << off_err;
  const auto [auto_code, auto_err] = run("auto", "auto");
  ASSERT_EQ(auto_code, 0) << auto_err;
  const auto off = test::read_lines(dir_->file("off") + "/poses.jsonl");
  const auto with = test::read_lines(dir_->file("auto") + "/poses.jsonl");
  EXPECT_EQ(off.size(), with.size());
  EXPECT_NE(off, with);
  test::write_file(dir_->file("bad.yaml"), "format: mocap-layout-offsets/1\nlayout: BODY_25\n");
  const auto [bad_code, bad_err] = run("bad", dir_->file("bad.yaml"));
  EXPECT_NE(bad_code, 0);
  EXPECT_NE(bad_err.find("bad.yaml"), std::string::npos) << bad_err;
}

// A camera file holding exactly what --image-size and --hfov assume gives the same output; a
// truncated camera file stops the run naming it.
TEST_F(ReconstructTest, ACameraFileReplacesImageSizeAndFieldOfView) {
  const auto run = [&](const std::string& name, std::vector<std::string> extra) {
    // The fit off: the camera is the match's ray whatever follows (three full fits took 95 s
    // under AddressSanitizer).
    std::vector<std::string> argv{"reconstruct", (dir_->path() / "input").string(),
                                  "--db",        dir_->file("db.mdb"),
                                  "--out",       dir_->file(name),
                                  "--fit",       "off"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    test::Mocap r(*dir_, name, argv);
    const auto code = r.wait(120s);  // before reading stderr: argument order is unspecified
    return std::make_pair(code, r.err());
  };
  // What --image-size assumes: the principal point at w/2, h/2.
  const camera::Camera same = camera::Camera::from_fov(1920, 1080, 50.0);
  camera::write_camera_file(dir_->file("cam.yml"), same);
  const auto [fov_code, fov_err] = run("fov", {"--image-size", "1920x1080", "--hfov", "50"});
  ASSERT_EQ(fov_code, 0) << fov_err;
  const auto [cam_code, cam_err] = run("cam", {"--camera", dir_->file("cam.yml")});
  ASSERT_EQ(cam_code, 0) << cam_err;
  const auto [none_code, none_err] = run("none", {});
  ASSERT_EQ(none_code, 0) << none_err;
  const auto fov = test::read_lines(dir_->file("fov") + "/poses.jsonl");
  EXPECT_EQ(fov, test::read_lines(dir_->file("cam") + "/poses.jsonl"));
  EXPECT_NE(fov, test::read_lines(dir_->file("none") + "/poses.jsonl"));  // the ray matters
  const std::string text = test::read_file(dir_->file("cam.yml"));
  test::write_file(dir_->file("cut.yml"), text.substr(0, text.size() / 3));
  const auto [cut_code, cut_err] = run("cut", {"--camera", dir_->file("cut.yml")});
  EXPECT_NE(cut_code, 0);
  EXPECT_NE(cut_err.find("cut.yml"), std::string::npos) << cut_err;
}

}  // namespace
}  // namespace mocap
