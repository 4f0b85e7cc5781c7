// `mocap camera list|grab` driven as a user would, against the fake GigE camera; and the live
// GigE graphs (one camera, several) validated by `mocap graph validate`.

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fake_gv_camera.hpp"
#include "support/mocap_process.hpp"

namespace mocap::test {
namespace {

using namespace std::chrono_literals;

class CameraCommandTest : public FakeCameraFixture {
 protected:
  TempDir dir_;
};

TEST_F(CameraCommandTest, ListShowsTheFakeCamera) {
  FakeGvCamera fake(*program_, unique_serial("CLI"));
  Mocap list(dir_, "list", {"camera", "list"});
  ASSERT_EQ(list.wait(30s), 0) << list.err();
  const std::string out = list.out();
  EXPECT_NE(out.find(fake.serial()), std::string::npos) << out;
  EXPECT_NE(out.find("127.0.0.1"), std::string::npos) << out;
  EXPECT_NE(out.find("Aravis"), std::string::npos) << out;
}

TEST_F(CameraCommandTest, GrabSavesPngFramesByDefault) {
  FakeGvCamera fake(*program_, unique_serial("CLI"));
  const auto out_dir = dir_.path() / "png";
  Mocap grab(dir_, "grab",
             {"camera", "grab", "--id", fake.serial(), "--frames", "3", "--out", out_dir.string(),
              "--width", "64", "--height", "48", "--fps", "50", "--pixel-format", "Mono16"});
  ASSERT_EQ(grab.wait(60s), 0) << grab.err();
  EXPECT_NE(grab.out().find("grabbed 3 frames"), std::string::npos) << grab.out();
  for (int i = 0; i < 3; ++i) {
    const auto file = out_dir / ("frame_00000" + std::to_string(i) + ".png");
    const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << file << " is not a PNG OpenCV reads";
    EXPECT_EQ(image.cols, 64);
    EXPECT_EQ(image.rows, 48);
    EXPECT_EQ(image.type(), CV_8UC1) << "Mono16 is saved as its top 8 bits";
  }
  Mocap colour(dir_, "colour",
               {"camera", "grab", "--id", fake.serial(), "--frames", "1", "--out",
                (dir_.path() / "rgb").string(), "--width", "64", "--height", "48", "--pixel-format",
                "BayerRG8"});
  ASSERT_EQ(colour.wait(60s), 0) << colour.err();
  const cv::Mat rgb = cv::imread((dir_.path() / "rgb" / "frame_000000.png").string());
  ASSERT_FALSE(rgb.empty());
  EXPECT_EQ(rgb.type(), CV_8UC3);
}

TEST_F(CameraCommandTest, GrabSavesPnmFramesAndPrintsTheRate) {
  FakeGvCamera fake(*program_, unique_serial("CLI"));
  const auto out_dir = dir_.path() / "frames";
  Mocap grab(dir_, "grab",
             {"camera", "grab", "--id", fake.serial(), "--frames", "5", "--out", out_dir.string(),
              "--width", "64", "--height", "48", "--fps", "50", "--pixel-format", "Mono8",
              "--format", "pnm"});
  ASSERT_EQ(grab.wait(60s), 0) << grab.err();
  EXPECT_NE(grab.out().find("grabbed 5 frames"), std::string::npos) << grab.out();
  EXPECT_NE(grab.out().find("drops: "), std::string::npos) << grab.out();
  for (int i = 0; i < 5; ++i) {
    const auto file = out_dir / ("frame_00000" + std::to_string(i) + ".pgm");
    ASSERT_TRUE(std::filesystem::exists(file)) << file;
    const std::string header = "P5\n64 48\n255\n";
    EXPECT_EQ(std::filesystem::file_size(file), header.size() + 64u * 48u);
    EXPECT_EQ(read_file(file.string()).substr(0, header.size()), header);
  }
}

TEST_F(CameraCommandTest, GrabFromAnUnknownCameraNamesIt) {
  Mocap grab(dir_, "grab",
             {"camera", "grab", "--id", "no-such-camera-4711", "--out", dir_.file("x")});
  const auto code = grab.wait(30s);
  ASSERT_TRUE(code.has_value());
  EXPECT_NE(*code, 0);
  EXPECT_NE(grab.err().find("no-such-camera-4711"), std::string::npos) << grab.err();
}

TEST(LiveGigeGraph, Validates) {
  TempDir dir;
  Mocap validate(dir, "validate", {"graph", "validate", "graphs/live_gige.yaml"});
  ASSERT_EQ(validate.wait(30s), 0) << validate.err() << validate.out();
}

// The live multi-view graphs (several cameras joined by capture time) as shipped.
TEST(LiveMultiviewGraphs, Validate) {
  TempDir dir;
  for (const char* graph :
       {"graphs/live_multiview_gige.yaml", "graphs/live_multiview_webcam.yaml"}) {
    Mocap validate(dir, "validate", {"graph", "validate", graph});
    ASSERT_EQ(validate.wait(30s), 0) << graph << "\n" << validate.err() << validate.out();
  }
}

}  // namespace
}  // namespace mocap::test
