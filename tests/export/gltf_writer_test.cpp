// The glTF writer on real CMU motion, read back with tinygltf: the joint nodes and hierarchy, the
// skin, one sampler per animated channel, keys equal to the clip's rotations and root translation.

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <iostream>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

#include "core/input_error.hpp"
#include "export/gltf_writer.hpp"
#include "export/tiny_gltf_config.hpp"
#include "motion/bvh.hpp"
#include "motion/pose_sequence.hpp"
#include "support/shared_data.hpp"

namespace mocap::exporting {
namespace {

tinygltf::Model parse_glb(const std::vector<std::uint8_t>& bytes) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  const bool ok = loader.LoadBinaryFromMemory(&model, &error, &warning, bytes.data(),
                                              static_cast<unsigned int>(bytes.size()));
  EXPECT_TRUE(ok) << error;
  EXPECT_TRUE(error.empty()) << error;
  return model;
}

// Element `i` of a float accessor as `n` floats.
std::vector<float> element(const tinygltf::Model& model, int accessor_id, std::size_t i,
                           std::size_t n) {
  const tinygltf::Accessor& accessor = model.accessors.at(accessor_id);
  const tinygltf::BufferView& view = model.bufferViews.at(accessor.bufferView);
  const std::vector<unsigned char>& data = model.buffers.at(view.buffer).data;
  EXPECT_EQ(accessor.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  EXPECT_LT(i, accessor.count);
  std::vector<float> out(n);
  std::memcpy(out.data(), data.data() + view.byteOffset + accessor.byteOffset + i * n * 4, n * 4);
  return out;
}

int non_end_site_joints(const motion::Skeleton& s) {
  return static_cast<int>(
      std::count_if(s.joints.begin(), s.joints.end(), [](const auto& j) { return !j.end_site; }));
}

TEST(GltfWriter, CmuClipReadsBackWithEveryJointAndKey) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_03.bvh");
  const motion::Clip clip =
      motion::read_bvh((test::shared_data() / "mocap/cmu31/09_03.bvh").string());
  const GltfFigure figure{"09_03", &clip, 0.0f};
  GltfSummary summary;
  const std::vector<std::uint8_t> bytes = make_glb({&figure, 1}, {}, &summary);
  const tinygltf::Model model = parse_glb(bytes);

  const int joints = non_end_site_joints(clip.skeleton);
  EXPECT_EQ(joints, 31);
  EXPECT_EQ(summary.joint_nodes, joints);
  ASSERT_EQ(model.skins.size(), 1u);
  ASSERT_EQ(static_cast<int>(model.skins[0].joints.size()), joints);
  EXPECT_EQ(model.nodes.size(), static_cast<std::size_t>(joints) + 1);  // + the mesh node
  // Node names and parents as in the BVH.
  std::vector<int> node_of(clip.skeleton.joints.size(), -1);
  for (int j = 0, k = 0; j < clip.skeleton.joint_count(); ++j) {
    if (clip.skeleton.joints[j].end_site) continue;
    node_of[j] = model.skins[0].joints[k++];
    EXPECT_EQ(model.nodes[node_of[j]].name, clip.skeleton.joints[j].name);
    const int parent = clip.skeleton.joints[j].parent;
    if (parent >= 0) {
      const auto& children = model.nodes[node_of[parent]].children;
      EXPECT_NE(std::find(children.begin(), children.end(), node_of[j]), children.end());
    }
  }
  // cgspeed CMU: rest translation = OFFSET x 0.056444 m.
  const float scale = metres_per_unit_of(clip.skeleton, clip.source);
  EXPECT_NEAR(scale, 0.056444, 1e-5);
  const glm::vec3 offset = clip.skeleton.joints[2].offset;  // LeftUpLeg;
  const auto& t = model.nodes[node_of[2]].translation;
  ASSERT_EQ(t.size(), 3u);
  EXPECT_NEAR(t[0], offset.x * scale, 1e-6);
  EXPECT_NEAR(t[1], offset.y * scale, 1e-6);

  // One animation: a rotation sampler per joint (all 31 rotate) and the root's translation.
  ASSERT_EQ(model.animations.size(), 1u);
  const tinygltf::Animation& animation = model.animations[0];
  EXPECT_EQ(animation.samplers.size(), static_cast<std::size_t>(joints) + 1);
  EXPECT_EQ(summary.samplers, joints + 1);
  const tinygltf::Accessor& times = model.accessors[animation.samplers[0].input];
  EXPECT_EQ(static_cast<int>(times.count), clip.frame_count);
  ASSERT_EQ(times.maxValues.size(), 1u);
  EXPECT_NEAR(times.maxValues[0], (clip.frame_count - 1) * clip.frame_time, 1e-5);

  const motion::PoseSequence poses = motion::to_poses(clip);
  int rotation_channels = 0;
  for (const tinygltf::AnimationChannel& channel : animation.channels) {
    const auto at = std::find(node_of.begin(), node_of.end(), channel.target_node);
    ASSERT_NE(at, node_of.end());
    const int j = static_cast<int>(at - node_of.begin());
    const tinygltf::AnimationSampler& sampler = animation.samplers[channel.sampler];
    EXPECT_EQ(sampler.interpolation, "LINEAR");
    for (int f : {0, clip.frame_count - 1}) {
      if (channel.target_path == "rotation") {
        const std::vector<float> k = element(model, sampler.output, f, 4);
        const glm::quat q = glm::normalize(poses.rotation[poses.at(f, j)]);
        // The same rotation: q or -q (keys are kept in one hemisphere along the clip).
        const float sign = (k[0] * q.x + k[1] * q.y + k[2] * q.z + k[3] * q.w) < 0 ? -1.0f : 1.0f;
        EXPECT_NEAR(k[0], sign * q.x, 1e-5) << clip.skeleton.joints[j].name << " frame " << f;
        EXPECT_NEAR(k[1], sign * q.y, 1e-5);
        EXPECT_NEAR(k[2], sign * q.z, 1e-5);
        EXPECT_NEAR(k[3], sign * q.w, 1e-5);
      } else {
        ASSERT_EQ(channel.target_path, "translation");
        EXPECT_EQ(j, 0);
        const std::vector<float> k = element(model, sampler.output, f, 3);
        const glm::vec3 p = poses.translation[poses.at(f, j)] * scale;
        EXPECT_NEAR(k[0], p.x, 1e-5);
        EXPECT_NEAR(k[1], p.y, 1e-5);
        EXPECT_NEAR(k[2], p.z, 1e-5);
      }
    }
    rotation_channels += channel.target_path == "rotation" ? 1 : 0;
  }
  EXPECT_EQ(rotation_channels, joints);
  // The hips stand about a metre high (CMU 09_03 is a run): metres, +Y up.
  const auto translation =
      std::find_if(animation.channels.begin(), animation.channels.end(),
                   [](const auto& c) { return c.target_path == "translation"; });
  ASSERT_NE(translation, animation.channels.end());
  const std::vector<float> root =
      element(model, animation.samplers[translation->sampler].output, 0, 3);
  EXPECT_GT(root[1], 0.7f);
  EXPECT_LT(root[1], 1.2f);
  std::cout << "[ note ] 09_03: " << clip.frame_count << " frames, " << joints << " joints, "
            << bytes.size() << " bytes of GLB\n";
}

TEST(GltfWriter, SeveralFiguresShareOneFileWithPrefixedNames) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_03.bvh");
  MOCAP_REQUIRE_SHARED("mocap/cmu_daz/07_01.bvh");
  const motion::Clip a = motion::read_bvh((test::shared_data() / "mocap/cmu31/09_03.bvh").string());
  const motion::Clip b =
      motion::read_bvh((test::shared_data() / "mocap/cmu_daz/07_01.bvh").string());
  const std::vector<GltfFigure> figures{{"a", &a, 0.0f}, {"b", &b, 0.0f}};
  GltfSummary summary;
  const tinygltf::Model model = parse_glb(make_glb(figures, {}, &summary));
  const int joints = non_end_site_joints(a.skeleton) + non_end_site_joints(b.skeleton);
  EXPECT_EQ(summary.joint_nodes, joints);
  EXPECT_EQ(model.skins.size(), 2u);
  EXPECT_EQ(model.meshes.size(), 2u);
  EXPECT_EQ(model.animations.size(), 1u);
  EXPECT_EQ(model.nodes[model.skins[0].joints[0]].name, "a:" + a.skeleton.joints[0].name);
  EXPECT_EQ(model.nodes[model.skins[1].joints[0]].name, "b:" + b.skeleton.joints[0].name);
  EXPECT_EQ(summary.frames, std::max(a.frame_count, b.frame_count));
}

TEST(GltfWriter, RefusesEmptyInputAndUnwritablePaths) {
  EXPECT_THROW(make_glb({}), std::invalid_argument);
  motion::Clip empty;
  const GltfFigure figure{"x", &empty, 1.0f};
  EXPECT_THROW(make_glb({&figure, 1}), std::invalid_argument);
  const GltfFigure none{"x", nullptr, 1.0f};
  EXPECT_THROW(make_glb({&none, 1}), std::invalid_argument);
  motion::Clip one = motion::parse_bvh(
      "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n End Site\n "
      "{\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n10 20 30\n",
      "one.bvh");
  const GltfFigure ok{"one", &one, 1.0f};
  EXPECT_THROW(write_glb({&ok, 1}, "/nonexistent/dir/x.glb"), InputError);
  EXPECT_GT(make_glb({&ok, 1}).size(), 100u);
}

}  // namespace
}  // namespace mocap::exporting
