// `mocap export --gltf` driven as a user would: the built binary in a child process.

#include <gtest/gtest.h>

#include "support/files.hpp"
#include "support/mocap_process.hpp"
#include "support/shared_data.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;

TEST(ExportCommand, WritesOneGlbForSeveralBvhFiles) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_03.bvh");
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_08.bvh");
  test::TempDir dir;
  const std::string out = dir.file("two.glb");
  test::Mocap run(dir, "export",
                  {"export", (test::shared_data() / "mocap/cmu31/09_03.bvh").string(),
                   (test::shared_data() / "mocap/cmu31/09_08.bvh").string(), "--gltf", out});
  ASSERT_EQ(run.wait(60s), 0) << run.err();
  const std::string summary = run.out();
  EXPECT_NE(summary.find("2 figure(s), 62 joint nodes, 64 animation channels, 129 keys"),
            std::string::npos)
      << summary;
  ASSERT_TRUE(std::filesystem::exists(out));
  const std::string bytes = test::read_file(out);
  ASSERT_GT(bytes.size(), 12u);
  EXPECT_EQ(bytes.substr(0, 4), "glTF");  // the GLB magic
  EXPECT_FALSE(std::filesystem::exists(out + ".part"));
}

TEST(ExportCommand, ErrorsNameTheFileAndTheMissingOption) {
  test::TempDir dir;
  test::write_file(dir.file("cut.bvh"), "HIERARCHY\nROOT hip\n{\n  OFFSET 0 0");
  test::Mocap bad(dir, "bad", {"export", dir.file("cut.bvh"), "--gltf", dir.file("out.glb")});
  EXPECT_EQ(bad.wait(60s), 1);
  EXPECT_NE(bad.err().find(dir.file("cut.bvh")), std::string::npos) << bad.err();
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.glb")));
  test::Mocap no_out(dir, "no_out", {"export", dir.file("cut.bvh")});
  EXPECT_EQ(no_out.wait(60s), 1);
  EXPECT_NE(no_out.err().find("--gltf"), std::string::npos) << no_out.err();
  test::Mocap help(dir, "help", {"export", "--help"});
  EXPECT_EQ(help.wait(60s), 0);
  EXPECT_NE(help.out().find("--no-mesh"), std::string::npos) << help.out();
}

}  // namespace
}  // namespace mocap
