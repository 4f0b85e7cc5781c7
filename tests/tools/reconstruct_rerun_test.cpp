// `mocap reconstruct` into a folder that already holds a run's output, through the built binary:
// without --force it is refused, naming what is there, and every failing rerun (a bad camera
// file, a damaged database, a bad node parameter, a truncated video) leaves the earlier files byte
// for byte; with --force a run that fails before its first frame also leaves them, and a run that
// writes replaces them all, so the folder holds its files only, which its report and summary.json
// list (not the folder's older ones).

#include <gtest/gtest.h>

#include <map>

#include <nlohmann/json.hpp>

#include "motion/bvh.hpp"
#include "support/files.hpp"
#include "support/mocap_process.hpp"
#include "support/models.hpp"
#include "support/shared_data.hpp"

namespace mocap {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kCmu = test::shared_data() / "mocap" / "cmu31";
const fs::path kJson = test::shared_data() / "eval" / "openpose_json" / "json";
const fs::path kVideo = test::shared_data() / "eval" / "opencv_samples" / "vtest_part0.avi";

// Every file under `folder` (hidden ones included), by relative name, with its bytes.
std::map<std::string, std::string> snapshot(const fs::path& folder) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    if (e.is_regular_file())
      files[fs::relative(e.path(), folder).string()] = test::read_file(e.path().string());
  }
  return files;
}

std::vector<std::string> names(const std::map<std::string, std::string>& files) {
  std::vector<std::string> out;
  for (const auto& [name, bytes] : files) out.push_back(name);
  return out;
}

class ReconstructRerunTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(kCmu / "08_01.bvh") || !fs::exists(kJson)) return;
    dir_ = std::make_unique<test::TempDir>();
    // A quarter of the default views: these tests are about the files a run keeps, not the
    // match, and the search is half of a run's time under AddressSanitizer.
    test::Mocap build(
        *dir_, "build",
        {"db", "build", (kCmu / "08_01.bvh").string(), (kCmu / "09_12.bvh").string(), "--clusters",
         "32", "--yaw-steps", "10", "--heights", "1.5,4", "--out", dir_->file("db.mdb")});
    ASSERT_EQ(build.wait(120s), 0) << build.err();
    // A damaged copy: one byte changed in the middle (its checksums no longer match).
    std::string bytes = test::read_file(dir_->file("db.mdb"));
    bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x5a);
    test::write_file(dir_->file("damaged.mdb"), bytes);
    test::write_file(dir_->file("bad_camera.yml"), "not a camera file\n");
    fs::create_directories(dir_->path() / "json");
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(kJson)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (std::size_t i = 0; i < 30; ++i)
      fs::copy_file(files[i], dir_->path() / "json" / files[i].filename());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override {
    if (!dir_) GTEST_SKIP() << "shared data absent (" << kCmu << ", " << kJson << ")";
  }
  // reconstruct on the 30 JSON frames into `out`, fitted (the image size is known; not under
  // AddressSanitizer); `extra` may name another --db.
  static test::Mocap reconstruct(const std::string& name, const std::string& out,
                                 std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {"reconstruct",  dir_->file("json"), "--out", out,
                                     "--image-size", "1920x1080",        "--fps", "25",
                                     "--quiet"};
    if (std::find(extra.begin(), extra.end(), "--db") == extra.end())
      args.insert(args.end(), {"--db", dir_->file("db.mdb")});
#if defined(__SANITIZE_ADDRESS__)
    // The files a run keeps do not depend on the fit, which takes most of a run under
    // AddressSanitizer; the Release build runs the default (full) fit.
    args.insert(args.end(), {"--fit", "off"});
#endif
    args.insert(args.end(), extra.begin(), extra.end());
    return test::Mocap(*dir_, name, args);
  }
  // A folder holding one complete run's output.
  static std::string used_folder(const std::string& name) {
    const std::string out = dir_->file(name);
    auto first = reconstruct(name + "_first", out);
    EXPECT_EQ(first.wait(120s), 0) << first.err();
    return out;
  }
  static inline std::unique_ptr<test::TempDir> dir_;
};

// The failing reruns of the issue that need no detector.
std::vector<std::pair<std::string, std::vector<std::string>>> failing_reruns(
    const test::TempDir& dir) {
  return {{"bad camera file", {"--camera", dir.file("bad_camera.yml")}},
          {"damaged database", {"--db", dir.file("damaged.mdb")}},
          {"bad node parameter", {"--set", "select.mode=bogus"}}};
}

TEST_F(ReconstructRerunTest, AUsedFolderIsRefusedWithoutForceAndStaysByteIdentical) {
  const std::string out = used_folder("used");
  const auto before = snapshot(out);
  ASSERT_TRUE(before.count("poses.jsonl"));
  ASSERT_TRUE(before.count("summary.json"));
  auto again = reconstruct("again", out);
  ASSERT_EQ(again.wait(60s), 1) << again.err();
  EXPECT_NE(again.err().find(out + ": holds the output of an earlier run"), std::string::npos)
      << again.err();
  EXPECT_NE(again.err().find("poses.jsonl"), std::string::npos) << again.err();
  EXPECT_NE(again.err().find("--force"), std::string::npos) << again.err();
  EXPECT_EQ(snapshot(out), before);
  for (const auto& [what, extra] : failing_reruns(*dir_)) {
    auto rerun = reconstruct("refused", out, extra);
    ASSERT_EQ(rerun.wait(60s), 1) << what << ": " << rerun.err();
    EXPECT_EQ(snapshot(out), before) << what;
  }
}

TEST_F(ReconstructRerunTest, WithForceAFailureBeforeTheFirstFrameLeavesTheEarlierOutput) {
  const std::string out = used_folder("forced_failure");
  const auto before = snapshot(out);
  for (const auto& [what, extra] : failing_reruns(*dir_)) {
    std::vector<std::string> args = extra;
    args.push_back("--force");
    auto rerun = reconstruct("forced", out, args);
    ASSERT_EQ(rerun.wait(60s), 1) << what << ": " << rerun.err();
    EXPECT_EQ(names(snapshot(out)), names(before)) << what << ": " << rerun.err();
    EXPECT_EQ(snapshot(out), before) << what;
  }
  // A fresh folder and a failure before the first frame: nothing is written, not even a summary.
  const std::string fresh = dir_->file("fresh");
  auto failing = reconstruct("fresh", fresh, {"--set", "select.mode=bogus"});
  ASSERT_EQ(failing.wait(60s), 1) << failing.err();
  EXPECT_NE(failing.err().find("nothing was written"), std::string::npos) << failing.err();
  EXPECT_TRUE(!fs::exists(fresh) || fs::is_empty(fresh));
}

TEST_F(ReconstructRerunTest, WithForceTheFolderHoldsThisRunsFilesOnlyAndTheReportListsThem) {
  const std::string out = used_folder("forced");
  // Sixteen older BVH files, as a run with more people would have left.
  std::string some_bvh;
  for (const auto& e : fs::directory_iterator(out))
    if (e.path().extension() == ".bvh") some_bvh = e.path().string();
  ASSERT_FALSE(some_bvh.empty());
  for (int id = 100; id < 116; ++id)
    fs::copy_file(some_bvh, out + "/person_" + std::to_string(id) + ".bvh");
  test::write_file(out + "/notes.txt", "mine");
  // This run keeps only people seen for 25 of the 30 frames: fewer files.
  auto rerun = reconstruct("rerun", out, {"--force", "--set", "bvh.min_frames=25"});
  ASSERT_EQ(rerun.wait(120s), 0) << rerun.err();
  EXPECT_NE(rerun.err().find("--force: replaced"), std::string::npos) << rerun.err();

  std::vector<std::string> bvh;
  for (const auto& e : fs::directory_iterator(out))
    if (e.path().extension() == ".bvh") bvh.push_back(e.path().filename().string());
  for (const std::string& name : bvh) EXPECT_LT(std::stoi(name.substr(7)), 100) << name;
  EXPECT_FALSE(fs::exists(out + "/person_100.bvh"));
  EXPECT_FALSE(fs::exists(out + "/.mocap-replaced"));
  EXPECT_EQ(test::read_file(out + "/notes.txt"), "mine");  // not an output: left alone

  // The report names every file of this run, and no other.
  const std::string report = rerun.out();
  std::size_t reported_bvh = 0;
  for (std::size_t at = report.find(".bvh"); at != std::string::npos;
       at = report.find(".bvh", at + 1))
    ++reported_bvh;
  if (bvh.size() > 8) {
    EXPECT_NE(report.find("wrote " + std::to_string(bvh.size()) + " BVH files"), std::string::npos)
        << report;
  } else {
    EXPECT_EQ(reported_bvh, bvh.size()) << report;
    for (const std::string& name : bvh)
      EXPECT_NE(report.find(out + "/" + name), std::string::npos) << report;
  }
  const auto summary = nlohmann::json::parse(test::read_file(out + "/summary.json"));
  std::vector<std::string> listed;
  for (const auto& f : summary.at("files")) {
    listed.push_back(fs::path(f.at("path").get<std::string>()).filename().string());
    EXPECT_EQ(f.at("bytes").get<std::uintmax_t>(), fs::file_size(f.at("path").get<std::string>()));
  }
  std::vector<std::string> present;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (name != "summary.json" && name != "notes.txt") present.push_back(name);
  }
  std::sort(listed.begin(), listed.end());
  std::sort(present.begin(), present.end());
  EXPECT_EQ(listed, present);
  EXPECT_TRUE(summary.at("completed").get<bool>());
}

TEST_F(ReconstructRerunTest, ATruncatedVideoRerunIsRefusedOrWithForceKeepsOnlyWhatItWrote) {
  if (!fs::exists(kVideo)) GTEST_SKIP() << "shared video absent: " << kVideo;
  MOCAP_REQUIRE_MOVENET();
  const std::string cut = dir_->file("cut.avi");
  const std::string bytes = test::read_file(kVideo.string());
  test::write_file(cut, bytes.substr(0, bytes.size() / 10));
  const std::string out = dir_->file("video");
  auto video = [&](const std::string& name, const std::string& input,
                   std::vector<std::string> extra) {
    std::vector<std::string> args = {"reconstruct", input, "--db",  dir_->file("db.mdb"),
                                     "--out",       out,   "--fit", "off",
                                     "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    return test::Mocap(*dir_, name, args);
  };
  auto first = video("video_first", kVideo.string(), {"--set", "src.count=30"});
  ASSERT_EQ(first.wait(300s), 0) << first.err();
  const auto before = snapshot(out);

  auto refused = video("video_refused", cut, {});
  ASSERT_EQ(refused.wait(60s), 1) << refused.err();
  EXPECT_EQ(snapshot(out), before);

  auto forced = video("video_forced", cut, {"--force"});
  ASSERT_EQ(forced.wait(300s), 1) << forced.err();
  EXPECT_NE(forced.err().find("truncated"), std::string::npos) << forced.err();
  EXPECT_NE(forced.err().find("kept what it wrote"), std::string::npos) << forced.err();
  const auto summary = nlohmann::json::parse(test::read_file(out + "/summary.json"));
  EXPECT_FALSE(summary.at("completed").get<bool>());
  EXPECT_NE(summary.at("error").get<std::string>().find(cut), std::string::npos);
  EXPECT_EQ(summary.at("input"), cut);
  const auto lines = test::read_lines(out + "/poses.jsonl");
  EXPECT_EQ(summary.at("frames").get<std::size_t>(), lines.size());
  EXPECT_LT(lines.size(), 30u);  // this run's frames, not the earlier 30
  for (const auto& line : lines)
    EXPECT_FALSE(nlohmann::json::parse(line, nullptr, false).is_discarded()) << line;
  std::size_t listed = summary.at("files").size();
  std::size_t present = 0;
  for (const auto& e : fs::directory_iterator(out))
    present += e.path().filename() != "summary.json" ? 1 : 0;
  EXPECT_EQ(listed, present);
  for (const auto& e : fs::directory_iterator(out)) {
    if (e.path().extension() != ".bvh") continue;
    const motion::Clip clip = motion::read_bvh(e.path().string());
    EXPECT_LE(clip.frame_count, static_cast<std::int64_t>(lines.size())) << e.path();
  }
}

}  // namespace
}  // namespace mocap
