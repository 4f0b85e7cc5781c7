// `mocap calibrate rig` driven as a user would: the built binary in a child process, on
// SYNTHETIC renders of a ChArUco board seen by four virtual cameras (support/virtual_rig.hpp),
// the intrinsics given as a rig file, the world from two floor frames. The library's accuracy and
// its bad inputs are in tests/camera/rig_calibration_test.cpp; here: the command's table, the file
// it writes, and its messages for an intrinsics rig without a camera, for an unreadable view and
// for --floor-frame with --floor-frames.

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "camera/rig_file.hpp"
#include "support/files.hpp"
#include "support/mocap_process.hpp"
#include "support/shared_data.hpp"
#include "support/virtual_rig.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;

TEST(CalibrateRigCommand, WritesTheRigOfFourVirtualCameras) {
  test::TempDir dir;
  test::VirtualRoom room;
  room.cameras = 4;
  room.frames = 10;
  room.width = 960;
  room.height = 540;
  room.seed = 5;
  room.floor_frames = 2;  // frame 10: the board on the floor again, elsewhere
  test::VirtualRig truth = test::make_virtual_rig(room);
  const std::vector<std::string> views =
      test::render_virtual_rig(truth, room, dir.path() / "views");
  camera::write_rig(dir.file("lenses.toml"), camera::Rig{truth.cameras, std::nullopt});

  std::vector<std::string> command{"calibrate", "rig"};
  command.insert(command.end(), views.begin(), views.end());
  for (const char* option : {"--board", "charuco", "--squares", "6x4", "--square", "150",
                             "--marker", "110", "--intrinsics"})
    command.emplace_back(option);
  command.push_back(dir.file("lenses.toml"));
  command.emplace_back("--floor-frames");
  command.emplace_back("0,10");
  command.emplace_back("--out");
  command.push_back(dir.file("rig.toml"));
  test::Mocap run(dir, "rig", command);
  ASSERT_EQ(run.wait(120s), 0) << run.err();
  const std::string out = run.out();
  std::cout << out;
  for (const char* text : {"ChArUco 6x4 squares of 150 mm", "the floor from frames 0 (", " 10 (",
                           "| cam_04 |", "RMS reprojection error", "wrote"})
    EXPECT_NE(out.find(text), std::string::npos) << text << "\n" << out;
  const camera::Rig rig = camera::read_rig(dir.file("rig.toml"));
  ASSERT_EQ(rig.cameras.size(), 4u);
  ASSERT_TRUE(rig.floor);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(rig.cameras[k].name, truth.cameras[k].name);
    // Loose: ten frames of small images; the benchmark measures the accuracy.
    EXPECT_LT(glm::length(rig.cameras[k].centre() - truth.cameras[k].centre()), 0.03)
        << rig.cameras[k].name;
  }

  // An intrinsics rig with three cameras for four views names the view without a camera.
  camera::write_rig(
      dir.file("three.toml"),
      camera::Rig{{truth.cameras[0], truth.cameras[1], truth.cameras[2]}, std::nullopt});
  command[command.size() - 5] = dir.file("three.toml");
  test::Mocap missing(dir, "missing", command);
  EXPECT_NE(missing.wait(60s), 0);
  EXPECT_NE(missing.err().find(dir.file("three.toml") + ": has 3 cameras, no camera for view 4 (" +
                               views[3] + ")"),
            std::string::npos)
      << missing.err();

  // A view that is not there is named.
  command[command.size() - 5] = dir.file("lenses.toml");
  command[3] = dir.file("nowhere");
  test::Mocap unreadable(dir, "unreadable", command);
  EXPECT_NE(unreadable.wait(60s), 0);
  EXPECT_NE(unreadable.err().find(dir.file("nowhere") + ": no such file or folder (camera cam_02)"),
            std::string::npos)
      << unreadable.err();

  // One floor frame or several, not both.
  command[3] = views[1];
  command.emplace_back("--floor-frame");
  command.emplace_back("0");
  test::Mocap both(dir, "both", command);
  EXPECT_NE(both.wait(60s), 0);
  EXPECT_NE(both.err().find("--floor-frames: give --floor-frame or --floor-frames, not both"),
            std::string::npos)
      << both.err();
}

// From people: Pose2Sim's static trial (one person standing still, 12 frames) is refused with the
// reason; the intrinsics must come from somewhere.
TEST(CalibrateRigCommand, FromPeopleRefusesOnePersonStandingStill) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/S00_P00_T00_StaticTrial/pose/cam01_json");
  const auto demo = test::shared_data() / "eval" / "pose2sim_demo";
  test::TempDir dir;
  std::vector<std::string> command{"calibrate", "rig", "--from-people", "--intrinsics",
                                   (demo / "calibration" / "Calib_qualisys.toml").string()};
  for (int k = 1; k <= 4; ++k)
    command.push_back(
        (demo / "S00_P00_T00_StaticTrial" / "pose" / ("cam0" + std::to_string(k) + "_json"))
            .string());
  command.emplace_back("--out");
  command.push_back(dir.file("rig.toml"));
  test::Mocap still(dir, "still", command);
  EXPECT_NE(still.wait(60s), 0);
  EXPECT_NE(still.err().find("the person hardly moves"), std::string::npos) << still.err();
  EXPECT_FALSE(std::filesystem::exists(dir.file("rig.toml")));

  // cam04's keypoints as from a video at half size (OpenPose run on 544x960): the solve could
  // not tell (it puts the camera twice as far), so the view's extent is noted as it is read.
  const std::string half = dir.file("cam04_half");
  std::filesystem::create_directories(half);
  for (const auto& e : std::filesystem::directory_iterator(command[8])) {
    nlohmann::json frame = nlohmann::json::parse(test::read_file(e.path().string()));
    for (auto& person : frame["people"])
      for (std::size_t i = 0; i + 2 < person["pose_keypoints_2d"].size(); i += 3) {
        person["pose_keypoints_2d"][i] = person["pose_keypoints_2d"][i].get<double>() / 2;
        person["pose_keypoints_2d"][i + 1] = person["pose_keypoints_2d"][i + 1].get<double>() / 2;
      }
    test::write_file(half + "/" + e.path().filename().string(), frame.dump());
  }
  std::vector<std::string> halved = command;
  halved[8] = half;
  test::Mocap small(dir, "small", halved);
  EXPECT_NE(small.wait(60s), 0);
  EXPECT_NE(small.err().find("note: the keypoints of " + half + " (camera 'cam_04', 1088x1920)"),
            std::string::npos)
      << small.err();
  EXPECT_EQ(still.err().find("top-left quarter"), std::string::npos) << still.err();

  command.erase(command.begin() + 3, command.begin() + 5);  // no --intrinsics, no --hfov
  test::Mocap bare(dir, "bare", command);
  EXPECT_NE(bare.wait(60s), 0);
  EXPECT_NE(bare.err().find("give one of --intrinsics and --hfov"), std::string::npos)
      << bare.err();
}

// From people, OpenPose JSON views (no image size of their own) against the cameras' sizes:
// Pose2Sim's balancing trial (portrait 1088x1920 cameras) with the intrinsics' width and height
// swapped, or --size given landscape, is refused naming the camera and a file. At the right size
// the check passes: FromPeopleRefusesOnePersonStandingStill gets past it to its own refusal.
TEST(CalibrateRigCommand, FromPeopleRefusesKeypointsOutsideTheCamerasImage) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/S00_P00_T01_BalancingTrial/pose/cam01_json");
  const auto demo = test::shared_data() / "eval" / "pose2sim_demo";
  test::TempDir dir;
  camera::Rig swapped = camera::read_rig(demo / "calibration" / "Calib_qualisys.toml");
  for (camera::Camera& c : swapped.cameras) {
    std::swap(c.width, c.height);
    std::swap(c.cx, c.cy);
    std::swap(c.fx, c.fy);
  }
  camera::write_rig(dir.file("landscape.toml"), swapped);
  std::vector<std::string> views;
  for (int k = 1; k <= 4; ++k)
    views.push_back(
        (demo / "S00_P00_T01_BalancingTrial" / "pose" / ("cam0" + std::to_string(k) + "_json"))
            .string());
  const auto command = [&](std::vector<std::string> head) {
    head.insert(head.end(), views.begin(), views.end());
    head.emplace_back("--out");
    head.push_back(dir.file("rig.toml"));
    return head;
  };
  test::Mocap wrong(
      dir, "wrong",
      command({"calibrate", "rig", "--from-people", "--intrinsics", dir.file("landscape.toml")}));
  EXPECT_NE(wrong.wait(60s), 0);
  EXPECT_NE(wrong.err().find("camera 'cam_01' is 1920x1088 but"), std::string::npos) << wrong.err();
  EXPECT_NE(wrong.err().find("cam01_json/cam01.00"), std::string::npos) << wrong.err();
  EXPECT_NE(wrong.err().find("give the views in the cameras' order"), std::string::npos)
      << wrong.err();
  EXPECT_FALSE(std::filesystem::exists(dir.file("rig.toml")));

  test::Mocap size(
      dir, "size",
      command({"calibrate", "rig", "--from-people", "--hfov", "50", "--size", "1920x1088"}));
  EXPECT_NE(size.wait(60s), 0);
  EXPECT_NE(size.err().find("camera 'cam_01' is 1920x1088"), std::string::npos) << size.err();
}

}  // namespace
}  // namespace mocap
