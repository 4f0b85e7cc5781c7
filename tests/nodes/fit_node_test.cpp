// recon.fit in a graph: people placed at the depth their clean projection shows, with constant
// bones, live and full; a person missing from a frame does not break the window; every frame out;
// joints_abs in poses.jsonl; full mode's frames reach the sink while the stream goes on, and a
// stop keeps every frame the node took in; a fit without a camera is refused by name.

#include <chrono>
#include <cmath>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "sink_test_util.hpp"
#include "support/files.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::nodes {
namespace {

using testing::run_graph;
using testing::stats_of;

constexpr double kHfovDeg = 56.14497;  // fx = 600 on 640 pixels: the script source's camera
// How soon after a stop request the graph must have ended: 2 s; a sanitizer build is slower.
#if defined(__SANITIZE_ADDRESS__)
constexpr double kStopBoundS = 6.0;
#else
constexpr double kStopBoundS = 2.0;
#endif

std::string fit_graph(const std::string& db, const std::string& script, const std::string& jsonl,
                      const std::string& fit_params, const std::string& source_params = "") {
  return R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
         db + ", script: \"" + script + R"(", depth_m: 4.0)" + source_params + R"( } }
  fit: { type: recon.fit, params: { db: )" +
         db + ", " + fit_params + R"( } }
  out: { type: sink.jsonl, params: { path: )" +
         jsonl + R"( } }
edges:
  - [src.people3d, fit.in]
  - [fit.out, out.in]
)";
}

// Person 1 in frames 0-15 (consecutive clip frames), person 2 in every frame but 7. They walk in
// place (their roots stay where the script puts them), so the fits run without foot contact.
std::string walking_script() {
  std::string script;
  for (int f = 0; f < 16; ++f) {
    if (f > 0) script += ";";
    script += "1:0:" + std::to_string(f) + ":0";
    if (f != 7) script += ",2:1:" + std::to_string(f) + ":3";
  }
  return script;
}

glm::dvec3 joint(const nlohmann::json& joints, std::string_view name) {
  const auto& v = joints.at(std::string(name));
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

struct Placed {
  std::map<int, std::vector<glm::dvec3>> roots;                              // per person
  std::map<int, std::vector<std::array<double, kBodyJoints>>> bone_lengths;  // per person
  std::size_t lines = 0, people = 0, placed = 0;
  std::size_t with_keypoints = 0;  // people whose 2D input was written (15 x [x, y, confidence])
  std::vector<int> people_in_frame;
};

Placed read_placed(const std::string& jsonl) {
  Placed out;
  for (const std::string& line : test::read_lines(jsonl)) {
    const auto frame = nlohmann::json::parse(line);
    ++out.lines;
    out.people_in_frame.push_back(static_cast<int>(frame.at("people").size()));
    for (const auto& person : frame.at("people")) {
      ++out.people;
      if (person.contains("keypoints") && person.at("keypoints").size() == 3 * kBodyJoints &&
          person.at("keypoints")[3 * index(Joint::root) + 2].get<double>() > 0)
        ++out.with_keypoints;
      if (!person.contains("joints_abs")) continue;
      ++out.placed;
      const int id = person.at("id").get<int>();
      const auto& abs = person.at("joints_abs");
      out.roots[id].push_back(joint(abs, "root"));
      std::array<double, kBodyJoints> lengths{};
      for (int j = 0; j < kBodyJoints; ++j) {
        if (kJointParent[j] < 0) continue;
        lengths[static_cast<std::size_t>(j)] =
            glm::distance(joint(abs, kJointNames[j]), joint(abs, kJointNames[kJointParent[j]]));
      }
      out.bone_lengths[id].push_back(lengths);
    }
  }
  return out;
}

double max_bone_change_m(const std::vector<std::array<double, kBodyJoints>>& frames) {
  double worst = 0;
  for (const auto& f : frames) {
    for (int j = 0; j < kBodyJoints; ++j)
      worst = std::max(worst, std::abs(f[static_cast<std::size_t>(j)] -
                                       frames.front()[static_cast<std::size_t>(j)]));
  }
  return worst;
}

void expect_placed_at_their_depth(const Placed& placed) {
  EXPECT_EQ(placed.lines, 16u);  // one line per input frame
  EXPECT_EQ(placed.people, 31u);
  EXPECT_EQ(placed.placed, 31u);
  EXPECT_EQ(placed.with_keypoints, 31u);    // the 2D input is kept beside the 3D output
  EXPECT_EQ(placed.people_in_frame[7], 1);  // person 2 stays absent where it was absent
  for (const auto& [id, roots] : placed.roots) {
    const double x = id == 1 ? 0.0 : 1.2;
    for (const glm::dvec3& root : roots) {
      EXPECT_NEAR(root.x, x, 0.02) << "person " << id;
      EXPECT_NEAR(root.y, 0.0, 0.02) << "person " << id;
      EXPECT_NEAR(root.z, 4.0, 0.08) << "person " << id;
    }
    // The output is one skeleton per person (joints_abs are rounded to millimetres).
    EXPECT_LT(max_bone_change_m(placed.bone_lengths.at(id)), 0.003) << "person " << id;
  }
}

TEST(FitNode, LivePlacesPeopleAtTheDepthTheirProjectionShowsWithConstantBones) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string jsonl = dir.file("poses.jsonl");
  const auto result = run_graph(fit_graph(
      db, walking_script(), jsonl,
      "mode: live, lag: 3, contact: false, image_width: 640, image_height: 480, hfov_deg: " +
          std::to_string(kHfovDeg)));
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(stats_of(result, "fit").out, 16u);
  expect_placed_at_their_depth(read_placed(jsonl));
}

TEST(FitNode, FullSequencePlacesPeopleAtTheirDepthWithConstantBones) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string jsonl = dir.file("poses.jsonl");
  const auto result = run_graph(
      fit_graph(db, walking_script(), jsonl,
                "mode: full, contact: false, image_width: 640, image_height: 480, hfov_deg: " +
                    std::to_string(kHfovDeg)));
  ASSERT_TRUE(result.ok) << result.error;
  expect_placed_at_their_depth(read_placed(jsonl));
}

TEST(FitNode, FullModeFramesReachTheSinkWhileTheStreamGoesOnAndAStopKeepsThemAll) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string jsonl = dir.file("poses.jsonl");
  // The script again and again until the stop: the stream has no end of its own.
  graph::Runtime runtime(graph::resolve(graph::parse_graph_text(
      fit_graph(db, walking_script(), jsonl,
                "mode: full, window: 16, overlap: 4, contact: false, ground: off, image_width: "
                "640, image_height: 480, hfov_deg: " +
                    std::to_string(kHfovDeg),
                ", repeat: true, interval_ms: 2"),
      "test.yaml")));
  graph::RunResult result;
  std::thread run([&] { result = runtime.run(); });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (test::read_lines(jsonl).size() < 40 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::size_t seen = test::read_lines(jsonl).size();
  const auto stop = std::chrono::steady_clock::now();
  runtime.request_stop();
  run.join();
  const double stop_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - stop).count();
  EXPECT_GE(seen, 40u) << "full mode sent nothing while the stream went on";
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_LT(stop_s, kStopBoundS);
  // Every frame the fit took in went out, and reached the file as a whole line.
  const auto& fit = stats_of(result, "fit");
  EXPECT_EQ(fit.out, fit.in);
  const auto lines = test::read_lines(jsonl);
  EXPECT_EQ(lines.size(), fit.out);
  for (const auto& line : lines) EXPECT_TRUE(nlohmann::json::accept(line)) << line;
}

TEST(FitNode, WithoutACameraTheGraphIsRefusedNamingWhatIsMissing) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const auto result = run_graph(fit_graph(db, "1:0:0:0", dir.file("poses.jsonl"), "lag: 1"));
  ASSERT_FALSE(result.ok);
  EXPECT_NE(result.error.find("image_width"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("fit"), std::string::npos) << result.error;
}

}  // namespace
}  // namespace mocap::nodes
