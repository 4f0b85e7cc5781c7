// `mocap calibrate intrinsics` driven as a user would: the built binary in a child process on
// Debian's opencv-doc chessboard images (skips without them).

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "camera/camera_file.hpp"
#include "support/mocap_process.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;
const std::string kDataDir = "/usr/share/doc/opencv-doc/examples/data";

TEST(CalibrateIntrinsics, WritesACameraFileAndPrintsTheError) {
  std::vector<std::string> args = {"calibrate", "intrinsics"};
  for (int i = 1; i <= 14; ++i) {
    const std::string name = kDataDir + "/left" + (i < 10 ? "0" : "") + std::to_string(i) + ".jpg";
    if (std::filesystem::exists(name)) args.push_back(name);
  }
  if (args.size() != 15) GTEST_SKIP() << "needs " << kDataDir << "/left01..14.jpg (opencv-doc)";
  test::TempDir dir;
  args.insert(args.end(),
              {"--board", "9x6", "--square", "25", "--out", dir.file("cams/left.yml"), "x.png"});
  // x.png does not exist: a clear error naming it, nothing written.
  test::Mocap missing(dir, "missing", args);
  EXPECT_EQ(missing.wait(60s), 1);
  EXPECT_NE(missing.err().find("x.png: no such file"), std::string::npos) << missing.err();
  EXPECT_FALSE(std::filesystem::exists(dir.file("cams/left.yml")));

  args.pop_back();
  test::Mocap run(dir, "run", args);
  ASSERT_EQ(run.wait(120s), 0) << run.err();
  EXPECT_NE(run.out().find("used 13 views"), std::string::npos) << run.out();
  EXPECT_NE(run.out().find("skipped 0 views"), std::string::npos) << run.out();
  EXPECT_NE(run.out().find("RMS reprojection error 0."), std::string::npos) << run.out();
  const camera::Camera c = camera::read_camera_file(dir.file("cams/left.yml"));
  EXPECT_EQ(c.width, 640);
  EXPECT_NEAR(c.fx, 536.0, 30.0);

  test::Mocap bad_board(dir, "bad", {"calibrate", "intrinsics", args[2], "--board", "9by6"});
  EXPECT_EQ(bad_board.wait(60s), 1);
  EXPECT_NE(bad_board.err().find("--board: '9by6'"), std::string::npos) << bad_board.err();
}

}  // namespace
}  // namespace mocap
