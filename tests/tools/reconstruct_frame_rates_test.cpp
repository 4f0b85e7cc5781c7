// `mocap reconstruct --calibration` with videos of different frame rates (issue 20's bad input):
// the views are joined frame by frame, so it is refused before anything is written, naming both
// views and their rates. Small videos written here, at the sizes of a rig written here.

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "support/files.hpp"
#include "support/mocap_process.hpp"
#include "support/shared_data.hpp"

namespace mocap::test {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 64, kHeight = 48;

void write_video(const std::string& path, double fps) {
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                         cv::Size(kWidth, kHeight));
  ASSERT_TRUE(writer.isOpened()) << path;
  for (int i = 0; i < 10; ++i) writer.write(cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar(i * 20)));
}

TEST(ReconstructMultiViewRates, VideosOfDifferentFrameRatesAreRefusedNamingBoth) {
  const std::string demo_rig = "eval/pose2sim_demo/calibration/Calib_qualisys.toml";
  MOCAP_REQUIRE_SHARED(demo_rig);
  TempDir dir;
  // Pose2Sim's rig with every camera's images 64x48.
  std::string rig = read_file((shared_data() / demo_rig).string());
  for (std::size_t at; (at = rig.find("size = [ 1088.0, 1920.0]")) != std::string::npos;)
    rig.replace(at, 24, "size = [ 64.0, 48.0]");
  write_file(dir.file("rig.toml"), rig);
  const double rates[] = {30, 30, 25, 30};
  std::vector<std::string> a = {"reconstruct", "--calibration", dir.file("rig.toml")};
  for (int c = 0; c < 4; ++c) {
    a.push_back(dir.file("cam" + std::to_string(c + 1) + ".avi"));
    write_video(a.back(), rates[c]);
  }
  a.insert(a.end(), {"--out", dir.file("out"), "--quiet"});
  Mocap run(dir, "rates", a);
  const auto code = run.wait(std::chrono::seconds(60));
  ASSERT_TRUE(code.has_value());
  EXPECT_NE(*code, 0);
  const std::string err = run.err();
  EXPECT_NE(err.find("cam3.avi is 25 fps"), std::string::npos) << err;
  EXPECT_NE(err.find("cam1.avi (camera 'cam_01') is 30 fps"), std::string::npos) << err;
  EXPECT_NE(err.find("cam_03"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir.file("out")));
}

}  // namespace
}  // namespace mocap::test
