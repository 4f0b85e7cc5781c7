// Our GLB files in other programs' hands: the Khronos glTF validator finds no error, and Blender
// imports the BVH and the GLB made from it with the same bones and frames.

#include <algorithm>
#include <fstream>
#include <iostream>

#include <gtest/gtest.h>

#include "export/gltf_writer.hpp"
#include "gltf_tools.hpp"
#include "motion/bvh.hpp"
#include "support/files.hpp"
#include "support/shared_data.hpp"

namespace mocap::exporting {
namespace {

// A CMU cgspeed clip (31 joints, 120 fps) and a Bandai one (22 joints, 30 fps, cm).
const char* const kClips[] = {"mocap/cmu31/09_03.bvh",
                              "mocap/bandai/dataset-1/dataset-1_run_normal_001.bvh"};

std::string shared(const char* relative) { return (test::shared_data() / relative).string(); }

int bones_of(const motion::Skeleton& s) {
  return static_cast<int>(
      std::count_if(s.joints.begin(), s.joints.end(), [](const auto& j) { return !j.end_site; }));
}

TEST(GltfReaders, KhronosValidatorFindsNoErrors) {
  if (const std::string missing = test::validator_missing(); !missing.empty())
    GTEST_SKIP() << missing;
  test::TempDir dir;
  int files = 0;
  for (const char* relative : kClips) {
    if (!std::filesystem::exists(shared(relative))) continue;
    const motion::Clip clip = motion::read_bvh(shared(relative));
    for (bool mesh : {true, false}) {
      const std::string path = dir.file(std::string(mesh ? "mesh_" : "bare_") +
                                        std::filesystem::path(relative).stem().string() + ".glb");
      const GltfFigure figure{"figure", &clip, 0.0f};
      write_glb({&figure, 1}, path, {mesh});
      std::string log;
      const nlohmann::json report = test::validate_gltf(path, log);
      ASSERT_TRUE(report.is_object()) << "the validator printed no report:\n" << log;
      std::cout << "[ note ] validator on " << std::filesystem::path(path).filename().string()
                << " (" << std::filesystem::file_size(path) << " bytes): " << report["errors"]
                << " errors, " << report["warnings"] << " warnings, " << report["infos"]
                << " infos, " << report["hints"] << " hints " << report["messages"].dump() << "\n";
      EXPECT_EQ(report["errors"], 0) << report.dump(1);
      EXPECT_EQ(report["warnings"], 0) << report.dump(1);
      ++files;
    }
  }
  // The validator must also see errors: a GLB with its binary chunk cut off.
  const motion::Clip clip = motion::parse_bvh(
      "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n End Site\n "
      "{\n  OFFSET 0 10 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n10 20 30\n0 0 0\n",
      "tiny.bvh");
  const GltfFigure figure{"tiny", &clip, 0.01f};
  std::vector<std::uint8_t> bytes = make_glb({&figure, 1});
  bytes.resize(bytes.size() - 40);
  const std::string broken = dir.file("broken.glb");
  {
    std::ofstream out(broken, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  }
  std::string log;
  const nlohmann::json report = test::validate_gltf(broken, log);
  ASSERT_TRUE(report.is_object()) << log;
  EXPECT_GT(report["errors"].get<int>(), 0) << report.dump(1);
  if (files == 0) GTEST_SKIP() << "shared data absent: " << shared(kClips[0]);
}

TEST(GltfReaders, BlenderImportsBvhAndGlbWithTheSameBonesAndFrames) {
  if (!test::on_path("blender"))
    GTEST_SKIP() << "blender is not on PATH (Debian: apt-get install blender)";
  MOCAP_REQUIRE_SHARED(kClips[0]);
  test::TempDir dir;
  for (const char* relative : kClips) {
    if (!std::filesystem::exists(shared(relative))) continue;
    const motion::Clip clip = motion::read_bvh(shared(relative));
    const std::string glb = dir.file(std::filesystem::path(relative).stem().string() + ".glb");
    const GltfFigure figure{"figure", &clip, 0.0f};
    write_glb({&figure, 1}, glb);
    std::string log;
    const nlohmann::json report = test::blender_import_both(shared(relative), glb, log);
    ASSERT_TRUE(report.is_object()) << "Blender printed no report:\n" << log;
    std::cout << "[ note ] Blender on " << relative << " and its GLB: " << report.dump() << "\n";
    for (const char* kind : {"bvh", "glb"}) {
      const nlohmann::json& r = report[kind];
      EXPECT_EQ(r["result"], nlohmann::json::array({"FINISHED"})) << kind;
      EXPECT_EQ(r["armatures"], 1) << kind;
      EXPECT_EQ(r["bones"], bones_of(clip.skeleton)) << kind;
      EXPECT_EQ(r["keyed_frames"], clip.frame_count) << kind;
    }
    EXPECT_EQ(report["glb"]["meshes"], 1);
    EXPECT_EQ(report["glb"]["first_bones"], report["bvh"]["first_bones"]);
  }
}

}  // namespace
}  // namespace mocap::exporting
