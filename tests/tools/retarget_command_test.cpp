// `mocap retarget` driven as a user would: the built binary in a child process.

#include <gtest/gtest.h>

#include "motion/bvh.hpp"
#include "support/files.hpp"
#include "support/mocap_process.hpp"
#include "support/shared_data.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;

TEST(RetargetCommand, PutsACmuClipOnTheDazRigAndSaysWhatItMapped) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  MOCAP_REQUIRE_SHARED("mocap/cmu_daz/05_01.bvh");
  test::TempDir dir;
  const std::string out = dir.file("daz.bvh");
  test::Mocap run(dir, "retarget",
                  {"retarget", (test::shared_data() / "mocap/cmu31/07_01.bvh").string(), "--rig",
                   (test::shared_data() / "mocap/cmu_daz/05_01.bvh").string(), "--out", out});
  ASSERT_EQ(run.wait(60s), 0) << run.err();
  const std::string summary = run.out();
  EXPECT_NE(summary.find("joints mapped: 21 of 43"), std::string::npos) << summary;
  EXPECT_NE(summary.find("lForeArm         <- LeftForeArm"), std::string::npos) << summary;
  EXPECT_NE(summary.find("unmapped (rest rotation): 22"), std::string::npos) << summary;
  EXPECT_NE(summary.find("317 frames"), std::string::npos) << summary;
  EXPECT_NE(summary.find("scale: "), std::string::npos) << summary;
  const motion::Clip clip = motion::read_bvh(out);
  EXPECT_EQ(clip.frame_count, 317);
  EXPECT_EQ(clip.skeleton.channel_count, 132);
}

TEST(RetargetCommand, ErrorsNameTheFile) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  test::TempDir dir;
  test::write_file(dir.file("rig.bvh"), "HIERARCHY\nROOT hip\n{\n  OFFSET 0 0");
  test::Mocap bad_rig(dir, "bad_rig",
                      {"retarget", (test::shared_data() / "mocap/cmu31/07_01.bvh").string(),
                       "--rig", dir.file("rig.bvh"), "--out", dir.file("out.bvh")});
  EXPECT_EQ(bad_rig.wait(60s), 1);
  EXPECT_NE(bad_rig.err().find(dir.file("rig.bvh")), std::string::npos) << bad_rig.err();
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.bvh")));
  test::Mocap no_rig(dir, "no_rig",
                     {"retarget", (test::shared_data() / "mocap/cmu31/07_01.bvh").string(), "--out",
                      dir.file("out.bvh")});
  EXPECT_EQ(no_rig.wait(60s), 1);
  EXPECT_NE(no_rig.err().find("--rig"), std::string::npos) << no_rig.err();
  test::Mocap help(dir, "help", {"retarget", "--help"});
  EXPECT_EQ(help.wait(60s), 0);
  EXPECT_NE(help.out().find("--map FILE"), std::string::npos) << help.out();
}

}  // namespace
}  // namespace mocap
