// `mocap rig info`, `mocap rig convert` and `mocap rig offsets` driven as a user would: the built
// binary in a child process, on Pose2Sim's demo calibration (skips without it) and on a
// single-camera file.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "camera/camera_file.hpp"
#include "camera/rig_file.hpp"
#include "support/mocap_process.hpp"
#include "support/shared_data.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;

// The report after "FILE: ", so that two files of the same rig compare equal.
std::string report_of(const std::string& out) {
  const auto at = out.find(": ");
  return at == std::string::npos ? out : out.substr(at + 2);
}

TEST(RigCommand, InfoAndConvertOnPose2SimsDemo) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/calibration/Calib_qualisys.toml");
  const std::string toml =
      (test::shared_data() / "eval/pose2sim_demo/calibration/Calib_qualisys.toml").string();
  test::TempDir dir;
  test::Mocap info(dir, "info", {"rig", "info", toml});
  ASSERT_EQ(info.wait(60s), 0) << info.err();
  const std::string out = info.out();
  for (const char* text : {"4 cameras", "cam_01", "cam_04", "1088x1920", "k1 -0.000722",
                           "baselines", "angles between optical axes", "floor: not given"})
    EXPECT_NE(out.find(text), std::string::npos) << text << "\n" << out;
  // The numbers are the library's: a baseline and a camera position.
  const camera::Rig rig = camera::read_rig(toml);
  char expected[64];
  std::snprintf(expected, sizeof expected, "%.3f",
                camera::baseline_m(rig.cameras[0], rig.cameras[2]));
  EXPECT_NE(out.find(expected), std::string::npos) << expected << "\n" << out;
  std::snprintf(expected, sizeof expected, "%.3f", rig.cameras[1].centre().x);
  EXPECT_NE(out.find(expected), std::string::npos) << expected << "\n" << out;

  // TOML -> YAML -> TOML: the same rig, the same report.
  test::Mocap to_yaml(dir, "to_yaml", {"rig", "convert", toml, dir.file("demo.yml")});
  ASSERT_EQ(to_yaml.wait(60s), 0) << to_yaml.err();
  EXPECT_NE(to_yaml.out().find("4 camera(s)"), std::string::npos) << to_yaml.out();
  test::Mocap back(dir, "back", {"rig", "convert", dir.file("demo.yml"), dir.file("demo.toml")});
  ASSERT_EQ(back.wait(60s), 0) << back.err();
  EXPECT_TRUE(camera::rigs_match(camera::read_rig(dir.file("demo.toml")), rig, 1e-12));
  test::Mocap yaml_info(dir, "yaml_info", {"rig", "info", dir.file("demo.yml")});
  ASSERT_EQ(yaml_info.wait(60s), 0) << yaml_info.err();
  EXPECT_EQ(report_of(yaml_info.out()), report_of(out));
}

TEST(RigCommand, TheSingleCameraFileWithItsFloor) {
  test::TempDir dir;
  camera::Camera lens = camera::Camera::from_fov(1280, 720, 70.0);
  lens.distortion = {-0.2, 0.05, 0.0, 0.0, 0.0};
  camera::write_camera_file(dir.file("cam.yml"), lens, 0.4, GroundPlane{{0.0, -1.0, 0.0}, 1.6});
  test::Mocap info(dir, "info", {"rig", "info", dir.file("cam.yml")});
  ASSERT_EQ(info.wait(60s), 0) << info.err();
  for (const char* text : {"1 camera,", "cam_01", "1280x720", "k1 -0.200000", "height (m)", "1.600",
                           "floor: dot(normal, x) + offset = 0"})
    EXPECT_NE(info.out().find(text), std::string::npos) << text << "\n" << info.out();
  EXPECT_EQ(info.out().find("baselines"), std::string::npos);  // one camera: no pairs
}

TEST(RigCommand, BadFilesAndNamesAreRefusedNamingThem) {
  test::TempDir dir;
  test::write_file(dir.file("junk.toml"), "[cam_01]\nname = \"a\"\nsize = [640, x]\n");
  test::Mocap junk(dir, "junk", {"rig", "info", dir.file("junk.toml")});
  EXPECT_EQ(junk.wait(60s), 1);
  EXPECT_NE(junk.err().find(dir.file("junk.toml") + ":3: [cam_01] size:"), std::string::npos)
      << junk.err();
  test::Mocap missing(dir, "missing", {"rig", "info", dir.file("none.yml")});
  EXPECT_EQ(missing.wait(60s), 1);
  EXPECT_NE(missing.err().find("none.yml: no such file"), std::string::npos) << missing.err();
  camera::write_camera_file(dir.file("cam.yml"), camera::Camera::from_fov(640, 480, 60.0));
  test::Mocap txt(dir, "txt", {"rig", "convert", dir.file("cam.yml"), dir.file("out.txt")});
  EXPECT_EQ(txt.wait(60s), 1);
  EXPECT_NE(txt.err().find("out.txt: cannot tell the rig format"), std::string::npos) << txt.err();
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.txt")));
  test::Mocap usage(dir, "usage", {"rig", "convert", dir.file("cam.yml")});
  EXPECT_EQ(usage.wait(60s), 2);
}

// Pose2Sim's demo with cam04 as if it started 5 frames late (its first 5 files left out): the
// offset of cam04 comes back as +5; too few views are refused naming the rig and the counts.
TEST(RigCommand, OffsetsFindAViewThatStartedLate) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/S00_P00_T01_BalancingTrial/pose/cam04_json");
  const auto demo = test::shared_data() / "eval" / "pose2sim_demo";
  const std::string toml = (demo / "calibration" / "Calib_qualisys.toml").string();
  test::TempDir dir;
  std::vector<std::string> args = {"rig", "offsets", toml};
  for (int c = 1; c <= 4; ++c) {
    const std::string name = "cam0" + std::to_string(c) + "_json";
    const auto view = std::filesystem::path(dir.file(name));
    std::filesystem::create_directories(view);
    std::vector<std::filesystem::path> files;
    for (const auto& e :
         std::filesystem::directory_iterator(demo / "S00_P00_T01_BalancingTrial" / "pose" / name))
      files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (std::size_t i = c == 4 ? 5 : 0; i < files.size(); ++i)
      std::filesystem::copy_file(files[i], view / files[i].filename());
    args.push_back(view.string());
  }
  args.insert(args.end(), {"--layout", "BODY_25B"});
  test::Mocap run(dir, "offsets", args);
  run.wait(60s);
  const std::string out = run.out();
  const std::string cam04 = "| 4 | cam_04 | 95 | ";
  const auto row = out.find(cam04);
  ASSERT_NE(row, std::string::npos) << out << run.err();
  const double offset = std::stod(out.substr(row + cam04.size()));
  EXPECT_NEAR(offset, 5.0, 0.5) << out;
  args.pop_back();
  args.pop_back();
  args.pop_back();  // three views for four cameras
  test::Mocap few(dir, "few", args);
  EXPECT_EQ(few.wait(60s), 1);
  EXPECT_NE(few.err().find("4 cameras, 3 views given"), std::string::npos) << few.err();
}

}  // namespace
}  // namespace mocap
