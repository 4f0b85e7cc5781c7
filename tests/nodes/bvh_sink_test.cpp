// sink.bvh in a graph: one file per person, held frames over gaps, files valid after the run is
// killed with SIGKILL, and a real client (Blender's BVH importer) reading what it wrote.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <nlohmann/json.hpp>

#include "motion/bvh.hpp"
#include "sink_test_util.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::nodes {
namespace {

using testing::run_graph;
using testing::stats_of;

std::string bvh_graph(const std::string& db, const std::string& dir, const std::string& script,
                      const std::string& extra_source_params = "", int min_frames = 1) {
  return R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
         db + ", script: \"" + script + "\"" + extra_source_params + R"( } }
  bvh: { type: sink.bvh, params: { db: )" +
         db + ", dir: " + dir + ", min_frames: " + std::to_string(min_frames) + R"(, fps: 24 } }
edges:
  - [src.people3d, bvh.in]
)";
}

// Person 3 in every frame, person 5 in frames 0-1 and 4-5 (held in 2-3), person 8 with a Bandai
// pose first (its own skeleton) and CMU poses after (held: skeleton_mismatch).
constexpr const char* kScript =
    "3:0:0:0,5:1:0:2,8:2:0:0;"
    "3:0:1:0,5:1:1:2,8:0:0:0;"
    "3:0:2:0;"
    "3:0:3:0,8:2:3:0;"
    "3:0:4:0,5:1:4:2;"
    "3:0:5:0,5:1:5:2";

TEST(BvhSink, OneFilePerPersonOnTheClipSkeletonWithGapsHeld) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string out = (dir.path() / "bvh").string();
  const graph::RunResult result = run_graph(bvh_graph(db, out, kScript));
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(stats_of(result, "bvh").in, 6u);
  const motion::Clip three = motion::read_bvh(out + "/person_3.bvh");
  const motion::Clip five = motion::read_bvh(out + "/person_5.bvh");
  const motion::Clip eight = motion::read_bvh(out + "/person_8.bvh");
  EXPECT_EQ(three.frame_count, 6);
  EXPECT_EQ(five.frame_count, 6);   // frames 2 and 3 repeat frame 1's pose
  EXPECT_EQ(eight.frame_count, 4);  // frames 0-3, none after its last appearance
  EXPECT_NEAR(three.fps(), 24.0, 1e-3);
  auto row = [](const motion::Clip& c, int f) {
    return std::vector<float>(c.frame(f), c.frame(f) + c.skeleton.channel_count);
  };
  EXPECT_EQ(row(five, 2), row(five, 1));
  EXPECT_EQ(row(five, 3), row(five, 1));
  EXPECT_NE(row(five, 4), row(five, 1));
  EXPECT_EQ(three.skeleton.joint_count(), 38);             // cgspeed CMU: 31 joints and 7 End Sites
  EXPECT_EQ(eight.skeleton.joints[0].name, "joint_Root");  // Bandai
  EXPECT_EQ(row(eight, 1), row(eight, 0));  // a CMU pose cannot be written on it: held
  EXPECT_NE(row(eight, 3), row(eight, 0));  // Bandai again
}

// A tracker's short-lived ids leave no file: person 8 (4 frames) stays under min_frames 5, while
// person 5 reaches it only through its held gap frames and is written whole from its first frame.
TEST(BvhSink, ShortTracksLeaveNoFile) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string out = (dir.path() / "bvh").string();
  const graph::RunResult result = run_graph(bvh_graph(db, out, kScript, "", 5));
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(motion::read_bvh(out + "/person_3.bvh").frame_count, 6);
  EXPECT_EQ(motion::read_bvh(out + "/person_5.bvh").frame_count, 6);
  EXPECT_FALSE(std::filesystem::exists(out + "/person_8.bvh"));
}

TEST(BvhSink, MissingDatabaseFailsTheGraphNamingTheFile) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string missing = dir.file("none.mdb");
  const graph::RunResult result = run_graph(R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
                                            db + R"(, script: "0:0:0:0" } }
  bvh: { type: sink.bvh, params: { db: )" + missing +
                                            ", dir: " + dir.file("out") + R"( } }
edges:
  - [src.people3d, bvh.in]
)");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find(missing), std::string::npos) << result.error;
}

// A child process runs the graph with a source that never ends; SIGKILL lands mid-write. Every
// file must read back with the frames it declares.
TEST(BvhSink, FilesOfAKilledRunReadBack) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  for (int round = 0; round < 4; ++round) {
    const std::string out = (dir.path() / ("killed" + std::to_string(round))).string();
    const std::string graph =
        bvh_graph(db, out, "1:0:0:0,2:1:0:5,4:0:9:7;1:0:1:0,4:0:10:7", ", repeat: true");
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      run_graph(graph);  // runs until killed
      _exit(2);
    }
    // Wait until the files are there and growing, then kill at a slightly different moment.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!std::filesystem::exists(out + "/person_4.bvh") &&
           std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::this_thread::sleep_for(std::chrono::milliseconds(100 + 37 * round));
    ASSERT_EQ(kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status));
    for (int id : {1, 2, 4}) {
      const std::string path = out + "/person_" + std::to_string(id) + ".bvh";
      ASSERT_TRUE(std::filesystem::exists(path)) << path;
      const motion::Clip clip = motion::read_bvh(path);  // throws if it were broken
      EXPECT_GT(clip.frame_count, 0) << path;
      std::cout << "[ note ] round " << round << ": " << path.substr(out.size() + 1) << " "
                << clip.frame_count << " frames at the kill\n";
    }
  }
}

// --- Blender

bool blender_available() { return std::system("command -v blender > /dev/null 2>&1") == 0; }

// Runs Blender headless on the import script; returns its JSON report (or null with the output
// in `log` when there is none).
nlohmann::json blender_import(const std::string& bvh, std::string& log) {
  const std::string command = "timeout 300 blender --background --factory-startup --python " +
                              std::string(MOCAP_BLENDER_SCRIPT) + " -- " + bvh + " 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return nullptr;
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe.get())) log += buffer.data();
  const auto at = log.find("MOCAP_BLENDER ");
  if (at == std::string::npos) return nullptr;
  return nlohmann::json::parse(log.substr(at + 14, log.find('\n', at) - at - 14));
}

void expect_blender_reads(const std::string& path, int frames, int bones) {
  std::string log;
  const nlohmann::json report = blender_import(path, log);
  ASSERT_FALSE(report.is_null()) << "Blender printed no report:\n" << log;
  std::cout << "[ note ] Blender on " << std::filesystem::path(path).filename().string() << ": "
            << report.dump() << "\n";
  EXPECT_EQ(report["result"], nlohmann::json::array({"FINISHED"}));
  EXPECT_EQ(report["armatures"], 1);
  EXPECT_EQ(report["bones"], bones);
  EXPECT_EQ(report["keyed_frames"], frames);
  // Blender extends the scene (never shortens it from its 250 frames) to the count it read from
  // "Frames: 0000000300": the zero-padded count is read as a number.
  if (frames > 250) {
    EXPECT_EQ(report["frame_end"].get<int>() - report["frame_start"].get<int>(), frames);
  }
}

TEST(BvhSink, BlenderImportsTheFilesWithEveryFrameAndBone) {
  if (!blender_available())
    GTEST_SKIP() << "blender is not on PATH (Debian: apt-get install blender)";
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string out = (dir.path() / "bvh").string();
  // 300 frames of person 3 (CMU, a clip played through view 4) and person 8 (Bandai).
  std::string script;
  for (int f = 0; f < 300; ++f) {
    char frame[64];
    std::snprintf(frame, sizeof frame, "%s3:0:%d:4,8:2:%d:0", f ? ";" : "", f, f);
    script += frame;
  }
  const graph::RunResult result = run_graph(bvh_graph(db, out, script));
  ASSERT_TRUE(result.ok) << result.error;
  for (const std::string name : {"person_3.bvh", "person_8.bvh"}) {
    const motion::Clip ours = motion::read_bvh(out + "/" + name);
    int joints = 0;  // Blender makes a bone of every joint but the End Sites
    for (const auto& j : ours.skeleton.joints) joints += j.end_site ? 0 : 1;
    expect_blender_reads(out + "/" + name, ours.frame_count, joints);
  }
}

// What a kill leaves (the counted frames, perhaps one more whole line) imports too.
TEST(BvhSink, BlenderImportsTheFileOfAKilledRun) {
  if (!blender_available())
    GTEST_SKIP() << "blender is not on PATH (Debian: apt-get install blender)";
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string out = (dir.path() / "killed").string();
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    run_graph(bvh_graph(db, out, "6:0:0:3", ", repeat: true"));
    _exit(2);
  }
  const std::string path = out + "/person_6.bvh";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!std::filesystem::exists(path) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  const motion::Clip ours = motion::read_bvh(path);
  std::string log;
  const nlohmann::json report = blender_import(path, log);
  ASSERT_FALSE(report.is_null()) << "Blender printed no report:\n" << log;
  std::cout << "[ note ] Blender on the killed file (" << ours.frame_count
            << " frames counted): keyed_frames " << report["keyed_frames"] << "\n";
  EXPECT_EQ(report["result"], nlohmann::json::array({"FINISHED"}));
  // Blender reads every line after the header: the frame written before its count, if any.
  const int keyed = report["keyed_frames"].get<int>();
  EXPECT_TRUE(keyed == ours.frame_count || keyed == ours.frame_count + 1) << keyed;
}

}  // namespace
}  // namespace mocap::nodes
