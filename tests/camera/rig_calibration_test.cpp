// Calibrating a rig from a board (camera/rig_calibration.hpp) on SYNTHETIC renders: four virtual
// cameras around a 4 m room, a ChArUco board in a few places (support/virtual_rig.hpp), the truth
// known. Small images and few frames, so it takes seconds; tools/bench/rig_board_bench.cpp has the
// full 4- and 8-camera tables. The world from several floor frames. Then the bad inputs: a board
// never found, a camera that shares no frame, views of different lengths, unreadable views, an
// intrinsics rig without a camera, floor frames without the board, listed twice or in the air.

#include "camera/rig_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_access.hpp>

#include "core/input_error.hpp"
#include "support/files.hpp"
#include "support/virtual_rig.hpp"

namespace mocap::camera {
namespace {

namespace fs = std::filesystem;

double rotation_error_deg(const glm::dmat3& a, const glm::dmat3& b) {
  const glm::dmat3 d = a * glm::transpose(b);
  const double trace = d[0][0] + d[1][1] + d[2][2];
  return std::acos(std::clamp((trace - 1) / 2, -1.0, 1.0)) * 180.0 / std::acos(-1.0);
}

std::vector<std::string> names_of(const std::vector<Camera>& cameras) {
  std::vector<std::string> names;
  for (const Camera& c : cameras) names.push_back(c.name);
  return names;
}

// Four cameras, 16 frames and two more of the board on the floor, rendered once for every test
// here.
class RigCalibration : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    room_.cameras = 4;
    room_.frames = 16;
    room_.floor_frames = 3;
    room_.seed = 3;
    room_.width = 960;
    room_.height = 540;
    frames_ = room_.frames + room_.floor_frames - 1;
    truth_ = test::make_virtual_rig(room_);
    folders_ = test::render_virtual_rig(truth_, room_, dir_->path());
    options_.board = room_.board;
    Rig intrinsics;
    intrinsics.cameras = truth_.cameras;
    options_.intrinsics = intrinsics;
    views_ = find_rig_board(folders_, names_of(truth_.cameras), options_);
  }
  static void TearDownTestSuite() { dir_.reset(); }

  static inline std::unique_ptr<test::TempDir> dir_;
  static inline test::VirtualRoom room_;
  static inline int frames_ = 0;  // every frame rendered
  static inline test::VirtualRig truth_;
  static inline std::vector<std::string> folders_;
  static inline RigBoardOptions options_;
  static inline std::vector<CameraBoardViews> views_;
};

TEST_F(RigCalibration, RecoversFourCamerasAndTheFloor) {
  for (std::size_t k = 0; k < views_.size(); ++k) {
    int found = 0, shown = 0;
    for (std::size_t f = 0; f < views_[k].boards.size(); ++f) {
      found += views_[k].boards[f].has_value();
      shown += truth_.seen[k][f];
    }
    EXPECT_EQ(views_[k].frames, frames_);
    // The detector may miss an oblique board, never invent one.
    EXPECT_LE(found, shown) << views_[k].name;
    EXPECT_GE(found, 2) << views_[k].name;
  }
  const camera::RigCalibration result = calibrate_rig(views_, options_);
  ASSERT_EQ(result.rig.cameras.size(), 4u);
  EXPECT_EQ(result.floor_frame, 0);
  ASSERT_TRUE(result.rig.floor);
  EXPECT_EQ(result.rig.floor->normal, glm::dvec3(0, 0, 1));
  for (std::size_t k = 0; k < 4; ++k) {
    const Camera& got = result.rig.cameras[k];
    const Camera& want = truth_.cameras[k];
    const double mm = 1000.0 * glm::length(got.centre() - want.centre());
    const double deg = rotation_error_deg(got.rotation, want.rotation);
    std::cout << got.name << ": position error " << mm << " mm, angle " << deg << " deg, RMS "
              << result.cameras[k].rms_px << " px, " << result.cameras[k].dropped
              << " corners dropped\n";
    EXPECT_EQ(got.name, want.name);
    EXPECT_LT(mm, 10.0) << got.name;
    EXPECT_LT(deg, 0.3) << got.name;
    EXPECT_LT(result.cameras[k].rms_px, 0.5) << got.name;
    EXPECT_GT(result.cameras[k].observations, 0);
  }
  EXPECT_TRUE(result.notes.empty());
}

// Intrinsics from each camera's own frames, refined in the bundle: p1 p2 stay at zero unless
// asked for (fitted, they trade against the principal point and so the camera's angle), one
// focal length (square pixels). The
// bounds are loose: 4-8 views of a distant board per camera determine its intrinsics poorly
// (measured 10-22 mm, 0.27-0.68 degrees either way); mocap-bench-rig-board measures the
// 60-frame 1280x720 rigs.
TEST_F(RigCalibration, OwnIntrinsicsAreRefinedWithoutTangentialDistortion) {
  RigBoardOptions options = options_;
  options.intrinsics.reset();
  options.refine_intrinsics = true;
  const camera::RigCalibration held = calibrate_rig(views_, options);
  options.tangential_distortion = true;
  const camera::RigCalibration fitted = calibrate_rig(views_, options);
  ASSERT_EQ(held.rig.cameras.size(), 4u);
  ASSERT_EQ(fitted.rig.cameras.size(), 4u);
  bool any_fitted = false;
  for (std::size_t k = 0; k < 4; ++k) {
    const Camera& got = held.rig.cameras[k];
    const Camera& want = truth_.cameras[k];
    ASSERT_GE(got.distortion.size(), 4u);
    EXPECT_EQ(got.distortion[2], 0.0) << got.name;
    EXPECT_EQ(got.distortion[3], 0.0) << got.name;
    EXPECT_EQ(got.fx, got.fy) << got.name;  // square pixels by default
    const auto& other = fitted.rig.cameras[k].distortion;
    any_fitted = any_fitted || other.at(2) != 0.0 || other.at(3) != 0.0;
    const double mm = 1000.0 * glm::length(got.centre() - want.centre());
    const double deg = rotation_error_deg(got.rotation, want.rotation);
    std::cout << got.name << ": own intrinsics, p1 p2 held: " << mm << " mm, " << deg
              << " deg (p1 p2 fitted: "
              << 1000.0 * glm::length(fitted.rig.cameras[k].centre() - want.centre()) << " mm, "
              << rotation_error_deg(fitted.rig.cameras[k].rotation, want.rotation) << " deg)\n";
    EXPECT_LT(mm, 40.0) << got.name;
    EXPECT_LT(deg, 1.2) << got.name;
  }
  EXPECT_TRUE(any_fitted);
}

TEST_F(RigCalibration, ACameraThatSharesNoFrameIsNamedOrLeftOut) {
  std::vector<CameraBoardViews> views = views_;
  // cam_04 keeps none of the frames it shares, and sees the board alone in one more frame.
  for (std::size_t f = 0; f < views[3].boards.size(); ++f)
    if (views[0].boards[f] || views[1].boards[f] || views[2].boards[f]) views[3].boards[f].reset();
  for (auto& v : views) v.boards.emplace_back();
  ASSERT_TRUE(views_[3].boards[0]) << "cam_04 does not see the floor board";
  views[3].boards.back() = views_[3].boards[0];
  try {
    calibrate_rig(views, options_);
    FAIL() << "a camera sharing no frame was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cam_04"), std::string::npos) << what;
    EXPECT_NE(what.find("never see the board"), std::string::npos) << what;
    EXPECT_EQ(what.find("cam_01 ("), std::string::npos) << what;
  }
  RigBoardOptions drop = options_;
  drop.drop_unconnected = true;
  const camera::RigCalibration result = calibrate_rig(views, drop);
  EXPECT_EQ(names_of(result.rig.cameras), (std::vector<std::string>{"cam_01", "cam_02", "cam_03"}));
  ASSERT_EQ(result.notes.size(), 1u);
  EXPECT_NE(result.notes[0].find("cam_04"), std::string::npos);
}

TEST_F(RigCalibration, ABoardNeverFoundNamesTheCameraAndTheFramesTried) {
  // A fifth camera whose folder shows an empty room.
  const fs::path empty = dir_->path() / "empty";
  fs::create_directories(empty);
  for (int f = 0; f < frames_; ++f)
    cv::imwrite((empty / ("frame_" + std::to_string(100 + f) + ".png")).string(),
                cv::Mat(room_.height, room_.width, CV_8U, cv::Scalar(110)));
  // Two views are enough to say it (and quicker to read).
  const std::vector<std::string> folders{folders_[0], empty.string()};
  const std::vector<std::string> names{"cam_01", "cam_05"};
  Rig intrinsics = *options_.intrinsics;
  intrinsics.cameras.push_back(truth_.cameras[0]);
  intrinsics.cameras.back().name = "cam_05";
  RigBoardOptions options = options_;
  options.intrinsics = intrinsics;
  try {
    calibrate_rig_from_board(folders, names, options);
    FAIL() << "a camera without the board was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cam_05"), std::string::npos) << what;
    EXPECT_NE(what.find(empty.string()), std::string::npos) << what;
    EXPECT_NE(what.find("not found in any of the " + std::to_string(frames_) + " frames tried"),
              std::string::npos)
        << what;
  }
}

TEST_F(RigCalibration, ViewsOfDifferentLengthsAreRefusedWithTheirCounts) {
  const fs::path shorter = dir_->path() / "shorter";
  fs::create_directories(shorter);
  for (int f = 0; f + 1 < frames_; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%03d.png", f);
    fs::copy_file(fs::path(folders_[1]) / name, shorter / name,
                  fs::copy_options::overwrite_existing);
  }
  const std::vector<std::string> folders{folders_[0], shorter.string()};
  try {
    find_rig_board(folders, {"cam_01", "cam_02"}, options_);
    FAIL() << "views of different lengths were accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("different frame counts"), std::string::npos) << what;
    EXPECT_NE(what.find("cam_02 (" + shorter.string() + ") " + std::to_string(frames_ - 1)),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("cam_01 (" + folders_[0] + ") " + std::to_string(frames_)),
              std::string::npos)
        << what;
  }
}

// Without the rendered room: the bad view is read first and refused before the other.
TEST(RigCalibrationViews, UnreadableViewsAreNamed) {
  test::TempDir dir;
  RigBoardOptions options;
  options.board = test::VirtualRoom{}.board;
  const std::string missing = dir.file("no-such-view");
  const std::string not_video = dir.file("garbage.mp4");
  test::write_file(not_video, "this is not a video");
  const fs::path folder_with_garbage = dir.path() / "garbage-images";
  fs::create_directories(folder_with_garbage);
  test::write_file((folder_with_garbage / "frame_000.png").string(), "not a png");
  const fs::path no_images = dir.path() / "no-images";
  fs::create_directories(no_images);
  for (const std::string& bad :
       {missing, not_video, (folder_with_garbage / "frame_000.png").string(), no_images.string()}) {
    // The bad view first: the good ones after it are not read.
    const std::vector<std::string> folders{bad == (folder_with_garbage / "frame_000.png").string()
                                               ? folder_with_garbage.string()
                                               : bad,
                                           dir.file("never-read")};
    try {
      find_rig_board(folders, {"cam_03", "cam_01"}, options);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(bad + ": ", 0), 0u) << what;
      EXPECT_NE(what.find("cam_03"), std::string::npos) << what;
    }
  }
}

TEST_F(RigCalibration, AnIntrinsicsRigWithoutACameraNamesIt) {
  RigBoardOptions options = options_;
  options.intrinsics->cameras.erase(options.intrinsics->cameras.begin() + 2);
  options.intrinsics_source = "given.toml";
  try {
    calibrate_rig(views_, options);
    FAIL() << "a missing camera was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("given.toml: has no camera 'cam_03'", 0), 0u) << what;
    EXPECT_NE(what.find("it has cam_01, cam_02, cam_04"), std::string::npos) << what;
  }
}

TEST_F(RigCalibration, AFloorFrameWithoutTheBoardIsNamed) {
  RigBoardOptions options = options_;
  options.floor_frame = 99;
  try {
    calibrate_rig(views_, options);
    FAIL() << "floor frame 99 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("floor frame 99: the views have " +
                                         std::to_string(frames_) + " frames"),
              std::string::npos)
        << e.what();
  }
}

// The world from every floor frame: the plane through all their corners. Each board lies within a
// few millimetres of it, the cameras' heights above the floor and their poses come out as with the
// one floor frame or better, and origin and x are the first frame's.
TEST_F(RigCalibration, SeveralFloorFramesSetTheFloorTogether) {
  std::vector<int> floors;
  for (int f : test::floor_frame_indices(room_))
    if (std::any_of(views_.begin(), views_.end(), [&](const auto& v) {
          return v.boards[static_cast<std::size_t>(f)].has_value();
        }))
      floors.push_back(f);
  ASSERT_GE(floors.size(), 2u) << "the board on the floor is seen in fewer than 2 frames";
  RigBoardOptions options = options_;
  options.floor_frames = floors;
  const camera::RigCalibration several = calibrate_rig(views_, options);
  const camera::RigCalibration one = calibrate_rig(views_, options_);
  EXPECT_EQ(several.floor_frame, 0);
  ASSERT_EQ(several.floor_frames.size(), floors.size());
  ASSERT_EQ(one.floor_frames.size(), 1u);
  EXPECT_NEAR(one.floor_frames[0].max_off_mm, 0.0, 1e-6);  // one board: the plane is its own
  for (std::size_t i = 0; i < floors.size(); ++i) {
    const FloorFrameReport& f = several.floor_frames[i];
    std::cout << "floor frame " << f.frame << ": " << f.corners << " corners, " << f.max_off_mm
              << " mm off the plane, tilted " << f.tilt_deg << " deg\n";
    EXPECT_EQ(f.frame, floors[i]);
    EXPECT_GE(f.corners, options.min_corners);
    EXPECT_LT(f.max_off_mm, kFloorToleranceMm);
    EXPECT_LT(f.tilt_deg, 0.5);
  }
  EXPECT_TRUE(several.notes.empty());
  double worst_height_one = 0, worst_height_several = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    const Camera& want = truth_.cameras[k];
    const Camera& got = several.rig.cameras[k];
    const double height_mm = 1000 * std::abs(got.centre().z - want.centre().z);
    worst_height_several = std::max(worst_height_several, height_mm);
    worst_height_one = std::max(worst_height_one,
                                1000 * std::abs(one.rig.cameras[k].centre().z - want.centre().z));
    const double mm = 1000.0 * glm::length(got.centre() - want.centre());
    std::cout << got.name << ": " << floors.size() << " floor frames: " << mm << " mm ("
              << height_mm << " in height), " << rotation_error_deg(got.rotation, want.rotation)
              << " deg; floor frame 0 alone: "
              << 1000.0 * glm::length(one.rig.cameras[k].centre() - want.centre()) << " mm\n";
    EXPECT_LT(mm, 10.0) << got.name;
    EXPECT_LT(rotation_error_deg(got.rotation, want.rotation), 0.3) << got.name;
  }
  EXPECT_LT(worst_height_several, 5.0);
  EXPECT_LT(worst_height_several, worst_height_one + 1.0);
}

TEST_F(RigCalibration, FloorFramesInTheAirOrListedTwiceAreNamed) {
  // Frame 1: the board held up in the room, not on the floor.
  std::size_t air = 1;
  while (air < static_cast<std::size_t>(room_.frames) &&
         !std::any_of(views_.begin(), views_.end(),
                      [&](const auto& v) { return v.boards[air].has_value(); }))
    ++air;
  ASSERT_LT(air, static_cast<std::size_t>(room_.frames)) << "the board is never seen in the air";
  RigBoardOptions options = options_;
  options.floor_frames = {0, static_cast<int>(air)};
  const camera::RigCalibration result = calibrate_rig(views_, options);
  // Two boards, one plane through both: each is off it, the one in the air is named.
  for (const std::string& n : result.notes) std::cout << "note: " << n << "\n";
  const std::string note = "floor frame " + std::to_string(air) + ": its board lies";
  EXPECT_TRUE(std::any_of(result.notes.begin(), result.notes.end(), [&](const std::string& n) {
    return n.rfind(note, 0) == 0;
  })) << (result.notes.empty() ? "no note" : result.notes[0]);
  EXPECT_GT(result.floor_frames.at(1).max_off_mm, kFloorToleranceMm);

  for (const std::vector<int>& bad : {std::vector<int>{0, 0}, std::vector<int>{0, 99}}) {
    options.floor_frames = bad;
    try {
      calibrate_rig(views_, options);
      ADD_FAILURE() << "floor frames " << bad[0] << "," << bad[1] << " were accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("floor frame " + std::to_string(bad[1]) + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(bad[1] == 0 ? "listed twice" : "the views have"), std::string::npos)
          << what;
    }
  }
}

// The plane alone, on exact board poses: three boards flat on a floor seen from a turned and
// shifted frame, then boards whose corners lie on one line.
TEST(RigFloorFit, ThePlaneThroughEveryBoardWithTheFirstBoardsOriginAndAxis) {
  using namespace rig_calibration_detail;
  const cv::Matx33d face_up(1, 0, 0, 0, -1, 0, 0, 0, -1);  // board -> world, lying face up
  const auto turn = [](double yaw) {
    return cv::Matx33d(std::cos(yaw), -std::sin(yaw), 0, std::sin(yaw), std::cos(yaw), 0, 0, 0, 1);
  };
  // bundle <- world: any rigid motion.
  cv::Matx33d bundle_R;
  cv::Rodrigues(cv::Vec3d(0.4, -1.1, 0.7), bundle_R);
  const cv::Vec3d bundle_t(0.3, -2.0, 4.5);
  const std::vector<std::pair<double, cv::Vec3d>> boards_in_world{
      {0.0, {0, 0, 0}}, {1.3, {1.2, -0.4, 0}}, {-2.0, {-0.7, 0.9, 0}}};
  std::vector<Pose> boards;
  std::vector<std::vector<std::array<double, 3>>> corners;
  for (const auto& [yaw, origin] : boards_in_world) {
    const cv::Matx33d R = bundle_R * turn(yaw) * face_up;
    cv::Vec3d r;
    cv::Rodrigues(R, r);
    const cv::Vec3d t = bundle_R * origin + bundle_t;
    boards.push_back({{r[0], r[1], r[2]}, {t[0], t[1], t[2]}});
    corners.push_back({{0.1, 0.1, 0}, {0.5, 0.1, 0}, {0.1, 0.3, 0}, {0.5, 0.3, 0}});
  }
  const FloorFit fit = fit_floor(boards, corners);
  cv::Matx33d R;
  cv::Rodrigues(cv::Vec3d(fit.world_from_bundle.rotation[0], fit.world_from_bundle.rotation[1],
                          fit.world_from_bundle.rotation[2]),
                R);
  const cv::Vec3d t(fit.world_from_bundle.translation[0], fit.world_from_bundle.translation[1],
                    fit.world_from_bundle.translation[2]);
  // world <- bundle <- world: the identity.
  const cv::Matx33d round = R * bundle_R;
  const cv::Vec3d shift = R * bundle_t + t;
  for (int r = 0; r < 3; ++r) {
    EXPECT_NEAR(shift[r], 0.0, 1e-9);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(round(r, c), r == c ? 1.0 : 0.0, 1e-9);
  }
  for (std::size_t b = 0; b < boards.size(); ++b) {
    EXPECT_NEAR(fit.max_off_m[b], 0.0, 1e-9);
    EXPECT_NEAR(fit.tilt_deg[b], 0.0, 1e-6);
  }

  // One board, its corners on a line: no plane.
  corners = {{{0.1, 0.1, 0}, {0.3, 0.1, 0}, {0.5, 0.1, 0}}};
  EXPECT_THROW(fit_floor({boards[0]}, corners), std::invalid_argument);
}

}  // namespace
}  // namespace mocap::camera
