// A `mocap` command never damages what it did not write, checked through the built binary: an
// output that is one of the inputs is refused naming both (export, db build, retarget,
// reconstruct, eval); numeric options out of range are refused before anything runs; a busy port
// or a node failing before the first frame leaves an existing poses.jsonl untouched; paths with
// bytes that are not UTF-8 work and the JSON written stays valid; an HTTP stream that stops before
// the frames it announced ends the run like a truncated file; an evaluation refuses a database
// built from the motion it evaluates on, or with --allow-leak says so in its report.

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "support/files.hpp"
#include "support/http_file_server.hpp"
#include "support/mocap_process.hpp"
#include "support/models.hpp"
#include "support/network.hpp"
#include "support/shared_data.hpp"

namespace mocap {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kCmu = test::shared_data() / "mocap" / "cmu31";
const fs::path kJson = test::shared_data() / "eval" / "openpose_json" / "json";
const fs::path kVideo = test::shared_data() / "eval" / "opencv_samples" / "vtest_part0.avi";

// A name with bytes that are not UTF-8 (Latin-1 é, and 0xff).
const std::string kNotUtf8 = "caf\xe9-\xff";

class OutputIntegrityTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(kCmu / "08_01.bvh") || !fs::exists(kJson)) return;
    dir_ = std::make_unique<test::TempDir>();
    test::Mocap build(*dir_, "build",
                      {"db", "build", (kCmu / "08_01.bvh").string(), "--clusters", "16", "--out",
                       dir_->file("db.mdb")});
    ASSERT_EQ(build.wait(120s), 0) << build.err();
    // 12 frames of the badminton clip.
    fs::create_directories(dir_->path() / "json");
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(kJson)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (std::size_t i = 0; i < 12; ++i)
      fs::copy_file(files[i], dir_->path() / "json" / files[i].filename());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override {
    if (!dir_) GTEST_SKIP() << "shared data absent (" << kCmu << ", " << kJson << ")";
  }
  static test::Mocap run(const std::string& name, std::vector<std::string> args) {
    return test::Mocap(*dir_, name, std::move(args));
  }
  static inline std::unique_ptr<test::TempDir> dir_;
};

void expect_refused(test::Mocap& run, const std::vector<std::string>& named) {
  ASSERT_EQ(run.wait(60s), 1) << run.err();
  for (const std::string& n : named) EXPECT_NE(run.err().find(n), std::string::npos) << run.err();
  EXPECT_NE(run.err().find("is the input"), std::string::npos) << run.err();
}

TEST(OutputIntegrity, AnOutputThatIsAnInputIsRefusedNamingBoth) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_12.bvh");
  const test::TempDir dir;
  auto run = [&](const std::string& name, std::vector<std::string> args) {
    return test::Mocap(dir, name, std::move(args));
  };
  // A folder of OpenPose JSON, and a file standing for a database (refused before it is read).
  fs::create_directories(dir.path() / "json");
  test::write_file(dir.file("json/a_000000000000_keypoints.json"), "{\"people\": []}");
  test::write_file(dir.file("db.mdb"), "a database");
  const std::string a = dir.file("a.bvh"), rig = dir.file("rig.bvh");
  fs::copy_file(kCmu / "08_01.bvh", a, fs::copy_options::overwrite_existing);
  fs::copy_file(kCmu / "09_12.bvh", rig, fs::copy_options::overwrite_existing);
  fs::create_directories(dir.path() / "sub");
  fs::remove(dir.file("link.glb"));
  fs::create_symlink(a, dir.file("link.glb"));
  const std::string original = test::read_file(a), original_rig = test::read_file(rig);

  auto export_same = run("export_same", {"export", a, "--gltf", a});
  expect_refused(export_same, {"--gltf " + a, "IN.bvh " + a});
  auto export_dots = run("export_dots", {"export", a, "--gltf", dir.file("sub/../a.bvh")});
  expect_refused(export_dots, {"IN.bvh " + a});
  auto export_link = run("export_link", {"export", a, "--gltf", dir.file("link.glb")});
  expect_refused(export_link, {dir.file("link.glb"), "IN.bvh " + a});
  auto db_same = run("db_same", {"db", "build", a, "--out", a});
  expect_refused(db_same, {"--out " + a});
  auto db_folder = run("db_folder", {"db", "build", dir.path().string(), "--out", rig});
  expect_refused(db_folder, {"--out " + rig});
  auto retarget_in = run("retarget_in", {"retarget", a, "--rig", rig, "--out", a});
  expect_refused(retarget_in, {"--out " + a, "IN.bvh " + a});
  auto retarget_rig = run("retarget_rig", {"retarget", a, "--rig", rig, "--out", rig});
  expect_refused(retarget_rig, {"--out " + rig, "--rig " + rig});
  EXPECT_EQ(test::read_file(a), original);
  EXPECT_EQ(test::read_file(rig), original_rig);

  const std::string json = dir.file("json");
  auto reconstruct_in = run("reconstruct_in", {"reconstruct", json, "--db", dir.file("db.mdb"),
                                               "--out", dir.file("sub/../json")});
  expect_refused(reconstruct_in, {"INPUT " + json});
  EXPECT_FALSE(fs::exists(dir.file("json/poses.jsonl")));
  const std::string db_bytes = test::read_file(dir.file("db.mdb"));
  auto eval_json = run(
      "eval_json", {"eval", "virtual", "--db", dir.file("db.mdb"), "--json", dir.file("db.mdb")});
  expect_refused(eval_json, {"--db " + dir.file("db.mdb")});
  EXPECT_EQ(test::read_file(dir.file("db.mdb")), db_bytes);
}

TEST(OutputIntegrity, NumericOptionsOutOfRangeAreRefusedBeforeAnythingIsWritten) {
  const test::TempDir dir;
  const std::string bvh = (kCmu / "08_01.bvh").string();  // not read: the options fail first
  for (const char* heights : {"nan", "inf", "-1", "0"}) {
    test::Mocap build(dir, "heights",
                      {"db", "build", bvh, "--heights", heights, "--out", dir.file("bad.mdb")});
    ASSERT_EQ(build.wait(60s), 2) << heights << ": " << build.err();
    EXPECT_NE(build.err().find("--heights: expected comma-separated numbers, each > 0, got '" +
                               std::string(heights) + "'"),
              std::string::npos)
        << build.err();
  }
  for (const char* port : {"99999", "65536"}) {
    test::Mocap view(dir, "port",
                     {"view", "--graph", "graphs/monocular_json.yaml", "--port", port});
    ASSERT_EQ(view.wait(60s), 2) << port << ": " << view.err();
    EXPECT_NE(view.err().find("--port: expected a whole number from 0 to 65535"), std::string::npos)
        << view.err();
  }
  const std::vector<std::vector<std::string>> cases = {
      {"reconstruct", dir.file("json"), "--out", dir.file("r"), "--fps", "nan"},
      {"reconstruct", dir.file("json"), "--out", dir.file("r"), "--image-size", "0x1080"},
      {"export", bvh, "--gltf", dir.file("x.glb"), "--scale", "-1"},
      {"eval", "virtual", "--db", dir.file("db.mdb"), "--threads", "0"},
      {"run", "graphs/monocular_json.yaml", "--drain-timeout", "-5"},
      {"view", dir.file("none.jsonl"), "--fps", "inf"},
  };
  for (const auto& args : cases) {
    test::Mocap bad(dir, "range", args);
    ASSERT_EQ(bad.wait(60s), 2) << args[0] << " " << args.back() << ": " << bad.err();
    EXPECT_NE(bad.err().find("expected"), std::string::npos) << bad.err();
  }
  EXPECT_FALSE(fs::exists(dir.file("bad.mdb")));
  EXPECT_FALSE(fs::exists(dir.file("r")));
  EXPECT_FALSE(fs::exists(dir.file("x.glb")));
}

TEST_F(OutputIntegrityTest, ABusyPortOrAFailureBeforeTheFirstFrameLeavesAnEarlierFileUntouched) {
  const fs::path out = dir_->path() / "busy";
  fs::create_directories(out);
  const std::string poses = (out / "poses.jsonl").string();
  const std::string earlier = "{\"frame\": 0, \"time\": 0.0, \"people\": []}\n";
  test::write_file(poses, earlier);
  const auto written = fs::last_write_time(poses);
  std::vector<std::string> graph = {"--set", "src.path=" + dir_->file("json"),
                                    "--set", "jsonl.path=" + poses,
                                    "--set", "bvh.dir=" + out.string(),
                                    "--set", "overlay.video=" + (out / "overlay.mp4").string(),
                                    "--set", "overlay.png_dir=" + out.string()};
  for (const char* node : {"scale", "match", "select", "fit", "bvh"})
    graph.insert(graph.end(), {"--set", std::string(node) + ".db=" + dir_->file("db.mdb")});

  // A port something listens on.
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(listen(fd, 1), 0);
  socklen_t size = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  const std::string port = std::to_string(ntohs(address.sin_port));
  std::vector<std::string> view = {"view", "--graph", "graphs/monocular_json.yaml", "--port", port};
  view.insert(view.end(), graph.begin(), graph.end());
  auto busy = run("busy", view);
  EXPECT_EQ(busy.wait(60s), 1) << busy.err();
  close(fd);
  EXPECT_NE(busy.err().find("127.0.0.1:" + port), std::string::npos) << busy.err();
  EXPECT_EQ(test::read_file(poses), earlier);
  EXPECT_EQ(fs::last_write_time(poses), written);

  // A node that fails when it opens, after the sinks have opened.
  std::vector<std::string> bogus = {"run", "graphs/monocular_json.yaml", "--set",
                                    "select.mode=bogus"};
  bogus.insert(bogus.end(), graph.begin(), graph.end());
  auto failing = run("bogus", bogus);
  EXPECT_EQ(failing.wait(60s), 1) << failing.err();
  EXPECT_NE(failing.err().find("bogus"), std::string::npos) << failing.err();
  EXPECT_EQ(test::read_file(poses), earlier);
  EXPECT_EQ(fs::last_write_time(poses), written);
  EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator()), 1);
}

TEST_F(OutputIntegrityTest, PathsWithBytesThatAreNotUtf8WorkAndTheJsonStaysValid) {
  const fs::path odd = dir_->path() / kNotUtf8;
  fs::create_directories(odd / ("json" + kNotUtf8));
  for (const auto& e : fs::directory_iterator(dir_->path() / "json"))
    fs::copy_file(e.path(), odd / ("json" + kNotUtf8) / e.path().filename());
  const std::string db = (odd / ("db" + kNotUtf8 + ".mdb")).string();
  auto build = run("odd_build",
                   {"db", "build", (kCmu / "08_01.bvh").string(), "--clusters", "8", "--out", db});
  ASSERT_EQ(build.wait(120s), 0) << build.err();
  auto info = run("odd_info", {"db", "info", db, "--json"});
  ASSERT_EQ(info.wait(60s), 0) << info.err();
  EXPECT_FALSE(nlohmann::json::parse(info.out(), nullptr, false).is_discarded()) << info.out();

  const std::string out = (odd / ("out" + kNotUtf8)).string();
  auto reconstruct = run("odd_reconstruct", {"reconstruct", (odd / ("json" + kNotUtf8)).string(),
                                             "--db", db, "--out", out, "--quiet"});
  ASSERT_EQ(reconstruct.wait(120s), 0) << reconstruct.err();
  const auto summary = nlohmann::json::parse(test::read_file(out + "/summary.json"));
  EXPECT_TRUE(summary.at("completed").get<bool>());
  EXPECT_EQ(summary.at("frames"), 12);
  EXPECT_FALSE(summary.at("files").empty());
  EXPECT_EQ(test::read_lines(out + "/poses.jsonl").size(), 12u);
  EXPECT_NE(reconstruct.out().find(out + "/poses.jsonl"), std::string::npos) << reconstruct.out();
}

TEST_F(OutputIntegrityTest, OptionsThatContradictTheInputAreRefusedBeforeAnythingIsWritten) {
  // --fps against a video's own rate (vtest_part0 is 10 fps): BVH and overlay would disagree
  // with poses.jsonl's times.
  if (fs::exists(kVideo)) {
    auto fps = run("fps", {"reconstruct", kVideo.string(), "--db", dir_->file("db.mdb"), "--out",
                           dir_->file("fps"), "--fps", "25"});
    ASSERT_EQ(fps.wait(60s), 1) << fps.err();
    EXPECT_NE(fps.err().find("runs at 10 frames/s"), std::string::npos) << fps.err();
    EXPECT_FALSE(fs::exists(dir_->file("fps")));
  }
  // An image size smaller than where the keypoints are (the badminton clip's are 1920x1080).
  auto size = run("size", {"reconstruct", dir_->file("json"), "--db", dir_->file("db.mdb"), "--out",
                           dir_->file("size"), "--image-size", "1280x720"});
  ASSERT_EQ(size.wait(60s), 1) << size.err();
  EXPECT_NE(size.err().find("--image-size: 1280x720 is smaller than the keypoints"),
            std::string::npos)
      << size.err();
  EXPECT_NE(size.err().find("_keypoints.json"), std::string::npos) << size.err();
  EXPECT_FALSE(fs::exists(dir_->file("size")));
}

TEST_F(OutputIntegrityTest, AStreamThatStopsEarlyEndsTheRunLikeATruncatedFile) {
  if (!fs::exists(kVideo)) GTEST_SKIP() << "shared video absent: " << kVideo;
  MOCAP_REQUIRE_MOVENET();
  const std::string bytes = test::read_file(kVideo.string());
  const test::HttpFileServer server(bytes, bytes.size() / 4);  // the connection lost at a quarter
  const std::string url = server.url("vtest_part0.avi");
  const std::string out = dir_->file("stream");
  auto stream =
      run("stream", {"reconstruct", url, "--db", dir_->file("db.mdb"), "--out", out, "--quiet"});
  ASSERT_EQ(stream.wait(300s), 1) << stream.err();
  EXPECT_NE(stream.err().find(url), std::string::npos) << stream.err();
  EXPECT_NE(stream.err().find("stopped early"), std::string::npos) << stream.err();
  const auto summary = nlohmann::json::parse(test::read_file(out + "/summary.json"));
  EXPECT_FALSE(summary.at("completed").get<bool>());
  const auto lines = test::read_lines(out + "/poses.jsonl");
  EXPECT_GT(lines.size(), 10u);  // the frames before the cut are kept
  EXPECT_LT(lines.size(), 200u);
  for (const auto& line : lines)
    EXPECT_FALSE(nlohmann::json::parse(line, nullptr, false).is_discarded()) << line;
}

TEST_F(OutputIntegrityTest, AnEvaluationRefusesADatabaseOfItsHeldOutMotionUnlessAllowed) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/02_01.bvh");
  const std::string leak = dir_->file("leak.mdb");
  auto build =
      run("leak_build", {"db", "build", (kCmu / "08_01.bvh").string(),
                         (kCmu / "02_01.bvh").string(), "--clusters", "16", "--out", leak});
  ASSERT_EQ(build.wait(120s), 0) << build.err();
  const std::vector<std::string> eval = {"eval",       "virtual",   "--db",        leak,
                                         "--paper-db", leak,        "--quick",     "--clips",
                                         "1",          "--configs", "per-frame NN"};
  std::vector<std::string> refused_args = eval;
  refused_args.insert(refused_args.end(), {"--json", dir_->file("refused.json")});
  auto refused = run("leak_refused", refused_args);
  ASSERT_EQ(refused.wait(120s), 1) << refused.err();
  EXPECT_NE(refused.err().find("02_01.bvh (cmu31)"), std::string::npos) << refused.err();
  EXPECT_NE(refused.err().find("--allow-leak"), std::string::npos) << refused.err();
  EXPECT_FALSE(fs::exists(dir_->file("refused.json")));

  std::vector<std::string> allowed_args = eval;
  allowed_args.insert(allowed_args.end(), {"--json", dir_->file("allowed.json"), "--allow-leak"});
  auto allowed = run("leak_allowed", allowed_args);
  ASSERT_EQ(allowed.wait(300s), 0) << allowed.err();
  EXPECT_NE(allowed.err().find("WARNING"), std::string::npos) << allowed.err();
  EXPECT_NE(allowed.out().find("WARNING (--allow-leak)"), std::string::npos) << allowed.out();
  const auto results = nlohmann::json::parse(test::read_file(dir_->file("allowed.json")));
  ASSERT_TRUE(results.at("leak").is_object()) << results.dump(2);
  EXPECT_TRUE(results.at("leak").at("allowed").get<bool>());
  EXPECT_EQ(results.at("leak").at("databases").at(leak).at(0), "02_01.bvh (cmu31)");

  // A database of the train split only is not a leak.
  std::vector<std::string> clean = {"eval",
                                    "virtual",
                                    "--db",
                                    dir_->file("db.mdb"),
                                    "--paper-db",
                                    dir_->file("db.mdb"),
                                    "--quick",
                                    "--clips",
                                    "1",
                                    "--configs",
                                    "per-frame NN",
                                    "--json",
                                    dir_->file("clean.json")};
  auto ok = run("leak_clean", clean);
  ASSERT_EQ(ok.wait(300s), 0) << ok.err();
  EXPECT_TRUE(
      nlohmann::json::parse(test::read_file(dir_->file("clean.json"))).at("leak").is_null());
}

}  // namespace
}  // namespace mocap
