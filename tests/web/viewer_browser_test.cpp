// The viewer in a real browser: Debian's chromium, headless, driven by tests/web/viewer_test.mjs
// (playwright-core from the npm cache of tools/setup.sh). Two ways in: `mocap view poses.jsonl`
// (the built binary, a recording with its timeline) and a graph with sink.web fed by a synthetic
// source. The page must load, receive frames, show the right people count and draw pixels; the
// screenshots are kept in the build folder (test-artefacts/). Skips without chromium, node or
// the npm cache.

#include <gtest/gtest.h>

#include <filesystem>
#include <thread>

#include <nlohmann/json.hpp>

#include "camera/rig_file.hpp"
#include "graph/graph_spec.hpp"
#include "graph/runtime.hpp"
#include "graph/validation.hpp"
#include "support/files.hpp"
#include "support/mocap_process.hpp"
#include "support/network.hpp"
#include "web/web_server.hpp"

namespace mocap::test {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

std::string find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  for (std::size_t start = 0; start <= dirs.size();) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const fs::path candidate = fs::path(dirs.substr(start, end - start)) / program;
    if (!candidate.parent_path().empty() && access(candidate.c_str(), X_OK) == 0)
      return candidate.string();
    start = end + 1;
  }
  return "";
}

struct Browser {
  std::string node, playwright, chromium = "/usr/bin/chromium";
  std::string missing;  // why the test cannot run
};

Browser find_browser() {
  Browser b;
  b.node = find_on_path("node");
  b.playwright = (web::default_three_dir().parent_path() / "playwright-core").string();
  if (access(b.chromium.c_str(), X_OK) != 0)
    b.missing = "no chromium at /usr/bin/chromium (tools/setup.sh installs it)";
  else if (b.node.empty())
    b.missing = "no node on PATH (tools/setup.sh installs npm and node)";
  else if (!fs::exists(fs::path(b.playwright) / "index.mjs"))
    b.missing = "no playwright-core in the npm cache " + b.playwright + " (run tools/setup.sh)";
  else if (!fs::exists(web::default_three_dir() / "build" / "three.module.js"))
    b.missing = "no three.js in the npm cache (run tools/setup.sh)";
  return b;
}

#define MOCAP_REQUIRE_BROWSER(b)    \
  const Browser b = find_browser(); \
  if (!b.missing.empty()) GTEST_SKIP() << b.missing

fs::path artefact(const std::string& name) {
  const fs::path dir = MOCAP_ARTEFACT_DIR;
  fs::create_directories(dir);
  return dir / name;
}

// Runs viewer_test.mjs against `url`; returns its JSON result (after checking its exit code).
Json drive_page(const Browser& b, const TempDir& dir, const std::string& url,
                std::vector<std::string> extra) {
  std::vector<std::string> args = {MOCAP_VIEWER_SCRIPT, "--url",      url,       "--playwright",
                                   b.playwright,        "--chromium", b.chromium};
  args.insert(args.end(), extra.begin(), extra.end());
  ChildProcess script(b.node, args, dir.file("node.out"), dir.file("node.err"), environment());
  const auto code = script.wait(std::chrono::seconds(120));
  const std::string out = script.out();
  EXPECT_TRUE(code.has_value()) << "viewer_test.mjs did not finish in 120 s";
  EXPECT_EQ(code.value_or(-1), 0) << out << "\n" << script.err();
  // The result is the last line of its output.
  std::string line = out.substr(0, out.find_last_not_of('\n') + 1);
  line = line.substr(line.rfind('\n') == std::string::npos ? 0 : line.rfind('\n') + 1);
  Json result = Json::parse(line, nullptr, false);
  if (!result.is_object()) {
    ADD_FAILURE() << "no result from viewer_test.mjs: " << out << script.err();
    return Json::object();
  }
  return result;
}

// Height of a joint over the root of an upright person (metres, up positive).
double height_of_joint(const std::string& name) {
  return name == "head"                               ? 0.7
         : name == "neck"                             ? 0.5
         : name.find("shoulder") != std::string::npos ? 0.45
         : name.find("elbow") != std::string::npos    ? 0.2
         : name.find("wrist") != std::string::npos    ? -0.05
         : name.find("knee") != std::string::npos     ? -0.45
         : name.find("ankle") != std::string::npos    ? -0.9
                                                      : 0.0;
}

// A multi-view reconstruction's recording: 2 people in a z-up world (as Pose2Sim's), 60 frames, and
// its rig of 4 level cameras on a 4 m ring at 1.6 m, facing the centre.
void write_world_recording(const std::string& poses, const std::string& rig_file) {
  camera::Rig rig;
  for (int k = 0; k < 4; ++k) {
    camera::Camera c = camera::Camera::from_fov(1280, 720, 60.0, "cam0" + std::to_string(k + 1));
    const double angle = 0.4 + k * std::acos(-1.0) / 2.0;
    const glm::dvec3 centre(4.0 * std::cos(angle), 4.0 * std::sin(angle), 1.6);
    const glm::dvec3 forward = glm::normalize(glm::dvec3(0.0, 0.0, 1.6) - centre);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0.0, 0.0, 1.0)));
    c.set_pose_from_centre(glm::dmat3(right, glm::cross(forward, right), forward), centre);
    rig.cameras.push_back(c);
  }
  rig.floor = GroundPlane{{0.0, 0.0, 1.0}, 0.0};
  write_file(rig_file, camera::format_rig_toml(rig));
  std::string text;
  for (int f = 0; f < 60; ++f) {
    Json people = Json::array();
    for (int id : {3, 8}) {
      const double a = 0.05 * f + id, swing = 0.25 * std::sin(0.3 * f + id);
      const glm::dvec3 root(1.2 * std::cos(a), 1.2 * std::sin(a), 0.95);
      Json joints = Json::object(), world = Json::object();
      for (int j = 0; j < kBodyJoints; ++j) {
        const std::string name(kJointNames[static_cast<std::size_t>(j)]);
        const double side = name.rfind("left", 0) == 0    ? 0.15
                            : name.rfind("right", 0) == 0 ? -0.15
                                                          : 0.0;
        const double ahead =
            name.find("wrist") != std::string::npos || name.find("ankle") != std::string::npos
                ? (side > 0 ? swing : -swing)
                : 0.0;
        const glm::dvec3 p(side, ahead, height_of_joint(name));
        joints[name] = {p.x, p.y, p.z};
        world[name] = {p.x + root.x, p.y + root.y, p.z + root.z};
      }
      people.push_back({{"id", id}, {"joints", joints}, {"joints_world", world}});
    }
    text += Json{{"frame", f}, {"time", f / 25.0}, {"people", people}}.dump() + "\n";
  }
  write_file(poses, text);
}

// A recording of 3 people, one of them placed, with a tilted floor: 120 frames at 25 fps.
void write_recording(const std::string& path) {
  std::string text;
  for (int f = 0; f < 120; ++f) {
    Json people = Json::array();
    for (int id : {2, 5, 9}) {
      Json joints = Json::object(), absolute = Json::object();
      const double swing = 0.25 * std::sin(0.2 * f + id);
      for (int j = 0; j < kBodyJoints; ++j) {
        const std::string name(kJointNames[static_cast<std::size_t>(j)]);
        const double side = name.rfind("left", 0) == 0    ? 0.15
                            : name.rfind("right", 0) == 0 ? -0.15
                                                          : 0.0;
        const double y = name == "head"                               ? -0.7
                         : name == "neck"                             ? -0.5
                         : name.find("shoulder") != std::string::npos ? -0.45
                         : name.find("elbow") != std::string::npos    ? -0.2
                         : name.find("wrist") != std::string::npos    ? 0.05
                         : name.find("knee") != std::string::npos     ? 0.45
                         : name.find("ankle") != std::string::npos    ? 0.9
                                                                      : 0.0;
        const double z =
            name.find("wrist") != std::string::npos || name.find("ankle") != std::string::npos
                ? (side > 0 ? swing : -swing)
                : 0.0;
        joints[name] = {side, y, z};
        absolute[name] = {side - 1.0, y + 0.4, z + 4.0};
      }
      Json person = {{"id", id}, {"joints", joints}};
      if (id == 9) person["joints_abs"] = absolute;
      people.push_back(person);
    }
    const Json line = {{"frame", f},
                       {"time", f / 25.0},
                       {"people", people},
                       {"ground", {{"normal", {0.0, -0.98, 0.199}}, {"offset", 1.35}}}};
    text += line.dump() + "\n";
  }
  write_file(path, text);
}

TEST(ViewerBrowser, MocapViewPlaysARecordingInChromium) {
  MOCAP_REQUIRE_BROWSER(browser);
  TempDir dir;
  write_recording(dir.file("poses.jsonl"));
  const int port = free_tcp_port();
  std::vector<std::string> env;  // Mocap drops MOCAP_* variables; the npm cache's stays
  if (const char* npm = std::getenv("MOCAP_NPM_DIR"))
    env.push_back(std::string("MOCAP_NPM_DIR=") + npm);
  Mocap view(
      dir, "view",
      {"view", dir.file("poses.jsonl"), "--port", std::to_string(port), "--image-size", "640x480"},
      env);
  const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (view.out().find(url) == std::string::npos && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_NE(view.out().find("120 frames"), std::string::npos) << view.out() << view.err();
  const Json result = drive_page(browser, dir, url + "?aa=0",
                                 {"--frames", "30", "--people", "3", "--timeline", "--screenshot",
                                  artefact("viewer_recording.png").string()});
  EXPECT_GE(result.value("frames_received", 0), 30);
  EXPECT_EQ(result.value("people_shown", -1), 3);
  EXPECT_TRUE(fs::exists(artefact("viewer_recording.png")));
  std::cerr << "viewer_test.mjs: " << result.dump() << "\n";
}

// `mocap view --rig`: people in the rig's world, every camera of the rig drawn where it stands.
TEST(ViewerBrowser, MocapViewShowsAWorldRecordingWithItsRigsCameras) {
  MOCAP_REQUIRE_BROWSER(browser);
  TempDir dir;
  write_world_recording(dir.file("poses.jsonl"), dir.file("rig.toml"));
  const int port = free_tcp_port();
  std::vector<std::string> env;
  if (const char* npm = std::getenv("MOCAP_NPM_DIR"))
    env.push_back(std::string("MOCAP_NPM_DIR=") + npm);
  Mocap view(dir, "view",
             {"view", dir.file("poses.jsonl"), "--port", std::to_string(port), "--rig",
              dir.file("rig.toml")},
             env);
  const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (view.out().find(url) == std::string::npos && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_NE(view.out().find("60 frames"), std::string::npos) << view.out() << view.err();
  const Json result = drive_page(browser, dir, url + "?aa=0",
                                 {"--frames", "20", "--people", "2", "--cameras", "4",
                                  "--screenshot", artefact("viewer_world.png").string()});
  EXPECT_EQ(result.value("cameras_shown", -1), 4);
  EXPECT_EQ(result.value("people_shown", -1), 2);
  std::cerr << "viewer_test.mjs: " << result.dump() << "\n";
}

// A camera's recording is not drawn with a rig, nor a world recording with one camera.
TEST(ViewerBrowser, MocapViewRefusesARigForACameraRecordingAndACameraForAWorldOne) {
  TempDir dir;
  write_world_recording(dir.file("world.jsonl"), dir.file("rig.toml"));
  write_recording(dir.file("camera.jsonl"));
  Mocap with_rig(dir, "rig",
                 {"view", dir.file("camera.jsonl"), "--port", "0", "--rig", dir.file("rig.toml")});
  EXPECT_EQ(with_rig.wait(30s), std::optional<int>(1));
  EXPECT_NE(with_rig.err().find("not --rig"), std::string::npos) << with_rig.err();
  Mocap with_camera(dir, "camera",
                    {"view", dir.file("world.jsonl"), "--port", "0", "--image-size", "1280x720"});
  EXPECT_EQ(with_camera.wait(30s), std::optional<int>(1));
  EXPECT_NE(with_camera.err().find("give the rig with --rig"), std::string::npos)
      << with_camera.err();
}

TEST(ViewerBrowser, SinkWebInAGraphStreamsLivePeopleToChromium) {
  MOCAP_REQUIRE_BROWSER(browser);
  TempDir dir;
  const int port = free_tcp_port();
  const std::string text =
      "graph: viewer_test\nnodes:\n"
      "  src: { type: unit.walking_people, params: { count: 4, fps: 30 } }\n"
      "  web: { type: sink.web, params: { port: " +
      std::to_string(port) +
      ", image_width: 640, image_height: 480, title: live } }\n"
      "edges:\n  - [src.out, web.in, { policy: latest }]\n";
  const graph::ResolvedGraph resolved = graph::resolve(graph::parse_graph_text(text, "test"));
  graph::Runtime runtime(resolved);
  graph::RunResult run;
  std::thread runner([&] { run = runtime.run(); });
  const Json result = drive_page(
      browser, dir, "http://127.0.0.1:" + std::to_string(port) + "/",
      {"--frames", "60", "--people", "4", "--screenshot", artefact("viewer.png").string()});
  runtime.request_stop();
  runner.join();
  EXPECT_TRUE(run.ok) << run.error;
  EXPECT_GE(result.value("frames_received", 0), 60);
  EXPECT_EQ(result.value("people_shown", -1), 4);
  EXPECT_EQ(result.value("people_in_stream", -1), 4);
  std::cerr << "viewer_test.mjs: " << result.dump() << "\n";
}

}  // namespace
}  // namespace mocap::test
