// sink.gltf in a graph beside sink.bvh: the GLB of each person carries the BVH's joints and
// frames (keys equal to the BVH's rotations), all_in_one puts everybody in one file, the Khronos
// validator finds no error and Blender imports the BVH and the GLB alike.

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <iostream>

#include <glm/gtc/quaternion.hpp>

#include "export/gltf_tools.hpp"
#include "export/tiny_gltf_config.hpp"
#include "motion/bvh.hpp"
#include "motion/pose_sequence.hpp"
#include "sink_test_util.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::nodes {
namespace {

using testing::run_graph;
using testing::stats_of;

std::string graph(const std::string& db, const std::string& dir, const std::string& script,
                  const std::string& gltf_params) {
  return R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
         db + ", script: \"" + script + R"(" } }
  bvh: { type: sink.bvh, params: { db: )" +
         db + ", dir: " + dir + R"(, min_frames: 1, fps: 24 } }
  gltf: { type: sink.gltf, params: { db: )" +
         db + ", min_frames: 1, fps: 24, " + gltf_params + R"( } }
edges:
  - [src.people3d, bvh.in]
  - [src.people3d, gltf.in]
)";
}

// Person 3 (CMU) in frames 0-39 through view 4, person 8 (Bandai) in frames 10-39, person 5
// (CMU) in frames 0-9 and 20-39 (held in 10-19).
std::string script() {
  std::string s;
  for (int f = 0; f < 40; ++f) {
    if (f) s += ';';
    s += "3:0:" + std::to_string(f) + ":4";
    if (f >= 10) s += ",8:2:" + std::to_string(f) + ":0";
    if (f < 10 || f >= 20) s += ",5:1:" + std::to_string(f) + ":2";
  }
  return s;
}

tinygltf::Model load(const std::string& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &error, &warning, path)) << path << ": " << error;
  return model;
}

std::vector<float> element(const tinygltf::Model& model, int accessor_id, std::size_t i,
                           std::size_t n) {
  const tinygltf::Accessor& accessor = model.accessors.at(accessor_id);
  const tinygltf::BufferView& view = model.bufferViews.at(accessor.bufferView);
  std::vector<float> out(n);
  std::memcpy(out.data(),
              model.buffers.at(0).data.data() + view.byteOffset + accessor.byteOffset + i * n * 4,
              n * 4);
  return out;
}

int bones_of(const motion::Skeleton& s) {
  return static_cast<int>(
      std::count_if(s.joints.begin(), s.joints.end(), [](const auto& j) { return !j.end_site; }));
}

// The GLB's keys at the first and last frame equal the BVH's rotations (as quaternions).
void expect_same_motion(const tinygltf::Model& model, const motion::Clip& bvh) {
  const int joints = bones_of(bvh.skeleton);
  ASSERT_EQ(model.skins.size(), 1u);
  ASSERT_EQ(static_cast<int>(model.skins[0].joints.size()), joints);
  ASSERT_EQ(model.animations.size(), 1u);
  const tinygltf::Animation& animation = model.animations[0];
  int rotating = 0, moving = 0;
  for (const auto& j : bvh.skeleton.joints) {
    bool r = false, m = false;
    for (motion::Channel c : j.channels) (motion::is_rotation(c) ? r : m) = true;
    rotating += r, moving += m;
  }
  EXPECT_EQ(static_cast<int>(animation.samplers.size()), rotating + moving);
  EXPECT_EQ(static_cast<int>(model.accessors[animation.samplers[0].input].count), bvh.frame_count);
  std::vector<int> joint_of_node(model.nodes.size(), -1);
  for (int j = 0, k = 0; j < bvh.skeleton.joint_count(); ++j)
    if (!bvh.skeleton.joints[j].end_site) joint_of_node[model.skins[0].joints[k++]] = j;
  const motion::PoseSequence poses = motion::to_poses(bvh);
  for (const tinygltf::AnimationChannel& channel : animation.channels) {
    if (channel.target_path != "rotation") continue;
    const int j = joint_of_node.at(channel.target_node);
    ASSERT_GE(j, 0);
    for (int f : {0, bvh.frame_count - 1}) {
      const std::vector<float> k = element(model, animation.samplers[channel.sampler].output, f, 4);
      const glm::quat q = glm::normalize(poses.rotation[poses.at(f, j)]);
      const float sign = (k[0] * q.x + k[1] * q.y + k[2] * q.z + k[3] * q.w) < 0 ? -1.0f : 1.0f;
      EXPECT_NEAR(k[0], sign * q.x, 1e-5) << bvh.skeleton.joints[j].name << " frame " << f;
      EXPECT_NEAR(k[1], sign * q.y, 1e-5);
      EXPECT_NEAR(k[2], sign * q.z, 1e-5);
      EXPECT_NEAR(k[3], sign * q.w, 1e-5);
    }
  }
}

TEST(GltfSink, OneGlbPerPersonWithTheBvhFramesAndRotations) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string out = (dir.path() / "out").string();
  const graph::RunResult result =
      run_graph(graph(db, out, script(), "path: \"" + out + "/person_{id}.glb\""));
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(stats_of(result, "gltf").in, 40u);
  for (int id : {3, 5, 8}) {
    const std::string base = out + "/person_" + std::to_string(id);
    const motion::Clip bvh = motion::read_bvh(base + ".bvh");
    ASSERT_TRUE(std::filesystem::exists(base + ".glb")) << base;
    std::cout << "[ note ] person_" << id << ".glb: " << std::filesystem::file_size(base + ".glb")
              << " bytes, " << bvh.frame_count << " frames, " << bones_of(bvh.skeleton)
              << " joints\n";
    expect_same_motion(load(base + ".glb"), bvh);
  }
  EXPECT_EQ(motion::read_bvh(out + "/person_8.bvh").frame_count, 30);
  EXPECT_EQ(motion::read_bvh(out + "/person_5.bvh").frame_count, 40);  // 10 held frames
}

TEST(GltfSink, AllInOneFileStartsEachPersonAtTheirFirstFrame) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const std::string out = (dir.path() / "out").string();
  const std::string glb = dir.file("all.glb");
  const graph::RunResult result =
      run_graph(graph(db, out, script(), "path: " + glb + ", all_in_one: true"));
  ASSERT_TRUE(result.ok) << result.error;
  const tinygltf::Model model = load(glb);
  ASSERT_EQ(model.skins.size(), 3u);
  EXPECT_EQ(model.animations.size(), 1u);
  // Person 8 comes in at frame 10: its keys start at 10 / 24 s.
  bool found = false;
  for (const tinygltf::AnimationChannel& channel : model.animations[0].channels) {
    if (model.nodes[channel.target_node].name.rfind("person_8:", 0) != 0) continue;
    const auto& times = model.accessors[model.animations[0].samplers[channel.sampler].input];
    EXPECT_NEAR(times.minValues.at(0), 10.0 / 24.0, 1e-6);
    EXPECT_EQ(times.count, 30u);
    found = true;
  }
  EXPECT_TRUE(found);
  if (const std::string missing = test::validator_missing(); missing.empty()) {
    std::string log;
    const nlohmann::json report = test::validate_gltf(glb, log);
    ASSERT_TRUE(report.is_object()) << log;
    std::cout << "[ note ] validator on the all-in-one GLB (" << std::filesystem::file_size(glb)
              << " bytes): " << report["errors"] << " errors, " << report["warnings"]
              << " warnings, " << report["infos"] << " infos " << report["messages"].dump() << "\n";
    EXPECT_EQ(report["errors"], 0);
  }
}

TEST(GltfSink, PathWithoutIdIsRefusedNamingTheNode) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  test::TempDir dir;
  const graph::RunResult result =
      run_graph(graph(db, dir.file("out"), "1:0:0:0", "path: " + dir.file("one.glb")));
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("{id}"), std::string::npos) << result.error;
}

TEST(GltfSink, ValidatorAndBlenderReadTheSinkFiles) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  const std::string validator = test::validator_missing();
  const bool blender = test::on_path("blender");
  if (!validator.empty() && !blender)
    GTEST_SKIP() << validator << "; blender is not on PATH either";
  test::TempDir dir;
  const std::string out = (dir.path() / "out").string();
  const graph::RunResult result =
      run_graph(graph(db, out, script(), "path: \"" + out + "/person_{id}.glb\""));
  ASSERT_TRUE(result.ok) << result.error;
  for (int id : {3, 8}) {
    const std::string base = out + "/person_" + std::to_string(id);
    const motion::Clip bvh = motion::read_bvh(base + ".bvh");
    if (validator.empty()) {
      std::string log;
      const nlohmann::json report = test::validate_gltf(base + ".glb", log);
      ASSERT_TRUE(report.is_object()) << log;
      std::cout << "[ note ] validator on person_" << id << ".glb: " << report["errors"]
                << " errors, " << report["warnings"] << " warnings, " << report["infos"]
                << " infos, " << report["hints"] << " hints\n";
      EXPECT_EQ(report["errors"], 0) << report.dump(1);
      EXPECT_EQ(report["warnings"], 0) << report.dump(1);
    }
    if (blender) {
      std::string log;
      const nlohmann::json report = test::blender_import_both(base + ".bvh", base + ".glb", log);
      ASSERT_TRUE(report.is_object()) << "Blender printed no report:\n" << log;
      std::cout << "[ note ] Blender on person_" << id << ": bvh " << report["bvh"]["bones"]
                << " bones / " << report["bvh"]["keyed_frames"] << " frames, glb "
                << report["glb"]["bones"] << " bones / " << report["glb"]["keyed_frames"]
                << " frames\n";
      for (const char* kind : {"bvh", "glb"}) {
        EXPECT_EQ(report[kind]["bones"], bones_of(bvh.skeleton)) << kind;
        EXPECT_EQ(report[kind]["keyed_frames"], bvh.frame_count) << kind;
      }
    }
  }
}

}  // namespace
}  // namespace mocap::nodes
