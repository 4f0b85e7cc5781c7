#include "export/gltf_writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>

#include "core/input_error.hpp"
// The one translation unit with tinygltf's implementation.
#define TINYGLTF_IMPLEMENTATION
#include "export/tiny_gltf_config.hpp"
#include "motion/body_mapping.hpp"
#include "motion/pose_sequence.hpp"

namespace mocap::exporting {
namespace {

constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
constexpr int kUnsignedShort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
constexpr int kUnsignedInt = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;

// Builds the one buffer and its views and accessors.
class BufferBuilder {
 public:
  explicit BufferBuilder(tinygltf::Model& model) : model_(model) { model_.buffers.emplace_back(); }

  // A buffer view holding `bytes` (4-byte aligned), `target` 0 for none.
  int view(const void* data, std::size_t bytes, int target) {
    std::vector<unsigned char>& buffer = model_.buffers[0].data;
    while (buffer.size() % 4 != 0) buffer.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer.size();
    v.byteLength = bytes;
    if (target != 0) v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), p, p + bytes);
    model_.bufferViews.push_back(std::move(v));
    return static_cast<int>(model_.bufferViews.size()) - 1;
  }

  int accessor(int view, int component, int type, std::size_t count, std::vector<double> min = {},
               std::vector<double> max = {}) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.byteOffset = 0;
    a.componentType = component;
    a.type = type;
    a.count = count;
    a.minValues = std::move(min);
    a.maxValues = std::move(max);
    model_.accessors.push_back(std::move(a));
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  template <typename T>
  int floats(const std::vector<T>& values, int type, int target = 0, bool bounds = false) {
    const std::size_t width = sizeof(T) / sizeof(float);
    std::vector<double> min, max;
    if (bounds) {
      min.assign(width, std::numeric_limits<double>::infinity());
      max.assign(width, -std::numeric_limits<double>::infinity());
      for (const T& v : values) {
        const auto* f = reinterpret_cast<const float*>(&v);
        for (std::size_t i = 0; i < width; ++i) {
          min[i] = std::min(min[i], static_cast<double>(f[i]));
          max[i] = std::max(max[i], static_cast<double>(f[i]));
        }
      }
    }
    const int v = view(values.data(), values.size() * sizeof(T), target);
    return accessor(v, kFloat, type, values.size(), std::move(min), std::move(max));
  }

 private:
  tinygltf::Model& model_;
};

std::vector<double> to_doubles(const glm::vec3& v) { return {v.x, v.y, v.z}; }

void validate(const GltfFigure& figure) {
  if (!figure.clip)
    throw std::invalid_argument("make_glb: figure '" + figure.name + "' has no clip");
  const motion::Clip& clip = *figure.clip;
  if (clip.skeleton.joints.empty())
    throw std::invalid_argument("make_glb: " + clip.source + " has no joints");
  if (clip.frame_count < 1)
    throw std::invalid_argument("make_glb: " + clip.source + " has no frames");
  if (!(clip.frame_time > 0.0) || !std::isfinite(clip.frame_time))
    throw std::invalid_argument("make_glb: " + clip.source + " has no positive frame time");
  if (!(figure.start_seconds >= 0.0) || !std::isfinite(figure.start_seconds))
    throw std::invalid_argument("make_glb: figure '" + figure.name + "' starts before 0 s");
  if (clip.values.size() < static_cast<std::size_t>(clip.frame_count) *
                               static_cast<std::size_t>(clip.skeleton.channel_count))
    throw std::invalid_argument("make_glb: " + clip.source + " has fewer values than frames");
}

// An octahedron from a to b (a bone): 6 vertices, 8 triangles.
void add_bone_mesh(const glm::vec3& a, const glm::vec3& b, std::uint16_t joint,
                   std::vector<glm::vec3>& positions,
                   std::vector<std::array<std::uint16_t, 4>>& joints,
                   std::vector<glm::vec4>& weights, std::vector<std::uint32_t>& indices) {
  const glm::vec3 axis = b - a;
  const float length = glm::length(axis);
  if (!(length > 1e-6f)) return;
  const glm::vec3 d = axis / length;
  const glm::vec3 helper = std::abs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  const glm::vec3 u = glm::normalize(glm::cross(d, helper));
  const glm::vec3 v = glm::cross(d, u);
  const float width = std::min(0.1f * length, 0.03f);
  const glm::vec3 ring = a + 0.2f * axis;
  const auto first = static_cast<std::uint32_t>(positions.size());
  for (const glm::vec3& p :
       {a, b, ring + width * u, ring + width * v, ring - width * u, ring - width * v}) {
    positions.push_back(p);
    joints.push_back({joint, 0, 0, 0});
    weights.emplace_back(1.0f, 0.0f, 0.0f, 0.0f);
  }
  for (std::uint32_t k = 0; k < 4; ++k) {
    const std::uint32_t r0 = first + 2 + k;
    const std::uint32_t r1 = first + 2 + (k + 1) % 4;
    // Counter-clockwise seen from outside: the base cone (towards a) and the tip cone (towards b).
    indices.insert(indices.end(), {first, r1, r0, first + 1, r0, r1});
  }
}

struct FigureNodes {
  std::vector<int> node_of_joint;  // -1 for End Sites
};

// Adds one figure's nodes, skin, mesh and animation channels; returns its scene root nodes.
std::vector<int> add_figure(const GltfFigure& figure, bool prefix, const GltfOptions& options,
                            tinygltf::Model& model, BufferBuilder& buffers,
                            tinygltf::Animation& animation, GltfSummary& summary) {
  const motion::Clip& clip = *figure.clip;
  const motion::Skeleton& skeleton = clip.skeleton;
  const float scale = figure.metres_per_unit > 0.0f ? figure.metres_per_unit
                                                    : metres_per_unit_of(skeleton, clip.source);
  const std::string name_prefix = prefix ? figure.name + ":" : "";
  const int joint_count = skeleton.joint_count();

  // Rest pose (identity rotations): global positions in metres.
  std::vector<glm::vec3> rest(static_cast<std::size_t>(joint_count));
  for (int j = 0; j < joint_count; ++j) {
    const motion::SkeletonJoint& joint = skeleton.joints[j];
    rest[j] = joint.offset * scale + (joint.parent >= 0 ? rest[joint.parent] : glm::vec3(0.0f));
  }

  // Joint nodes.
  FigureNodes nodes;
  nodes.node_of_joint.assign(static_cast<std::size_t>(joint_count), -1);
  std::vector<int> skin_joints;
  std::vector<int> skin_index(static_cast<std::size_t>(joint_count), -1);
  std::vector<int> roots;
  for (int j = 0; j < joint_count; ++j) {
    const motion::SkeletonJoint& joint = skeleton.joints[j];
    if (joint.end_site) continue;
    tinygltf::Node node;
    node.name = name_prefix + joint.name;
    const glm::vec3 t = joint.offset * scale;
    node.translation = to_doubles(t);
    const int index = static_cast<int>(model.nodes.size());
    model.nodes.push_back(std::move(node));
    nodes.node_of_joint[j] = index;
    skin_index[j] = static_cast<int>(skin_joints.size());
    skin_joints.push_back(index);
    if (joint.parent >= 0) {
      model.nodes[nodes.node_of_joint[joint.parent]].children.push_back(index);
    } else {
      roots.push_back(index);
    }
  }
  if (skin_joints.size() > std::numeric_limits<std::uint16_t>::max())
    throw std::invalid_argument("make_glb: " + clip.source + " has too many joints");
  summary.joint_nodes += static_cast<int>(skin_joints.size());

  // Skin: the inverse bind matrices undo the rest pose's translations.
  std::vector<glm::mat4> inverse_bind;
  for (int j = 0; j < joint_count; ++j) {
    if (skin_index[j] < 0) continue;
    glm::mat4 m(1.0f);
    m[3] = glm::vec4(-rest[j], 1.0f);
    inverse_bind.push_back(m);
  }
  tinygltf::Skin skin;
  skin.name = figure.name;
  skin.joints = skin_joints;
  skin.skeleton = roots.front();
  skin.inverseBindMatrices = buffers.floats(inverse_bind, TINYGLTF_TYPE_MAT4);
  model.skins.push_back(std::move(skin));
  const int skin_id = static_cast<int>(model.skins.size()) - 1;

  // The stick figure, skinned: each bone follows its parent joint.
  if (options.mesh) {
    std::vector<glm::vec3> positions;
    std::vector<std::array<std::uint16_t, 4>> joints;
    std::vector<glm::vec4> weights;
    std::vector<std::uint32_t> indices;
    for (int j = 0; j < joint_count; ++j) {
      const int parent = skeleton.joints[j].parent;
      if (parent < 0 || skin_index[parent] < 0) continue;
      add_bone_mesh(rest[parent], rest[j], static_cast<std::uint16_t>(skin_index[parent]),
                    positions, joints, weights, indices);
    }
    if (!indices.empty()) {
      tinygltf::Primitive primitive;
      primitive.mode = TINYGLTF_MODE_TRIANGLES;
      primitive.attributes["POSITION"] =
          buffers.floats(positions, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
      primitive.attributes["WEIGHTS_0"] =
          buffers.floats(weights, TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER);
      const int joints_view = buffers.view(joints.data(), joints.size() * sizeof(joints[0]),
                                           TINYGLTF_TARGET_ARRAY_BUFFER);
      primitive.attributes["JOINTS_0"] =
          buffers.accessor(joints_view, kUnsignedShort, TINYGLTF_TYPE_VEC4, joints.size());
      const int index_view = buffers.view(indices.data(), indices.size() * sizeof(std::uint32_t),
                                          TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      primitive.indices =
          buffers.accessor(index_view, kUnsignedInt, TINYGLTF_TYPE_SCALAR, indices.size());
      primitive.material = 0;
      tinygltf::Mesh mesh;
      mesh.name = figure.name + " bones";
      mesh.primitives.push_back(std::move(primitive));
      model.meshes.push_back(std::move(mesh));
      tinygltf::Node node;
      node.name = figure.name + " bones";
      node.mesh = static_cast<int>(model.meshes.size()) - 1;
      node.skin = skin_id;
      model.nodes.push_back(std::move(node));
      roots.push_back(static_cast<int>(model.nodes.size()) - 1);
    }
  }

  // Animation: one key per frame.
  const motion::PoseSequence poses = motion::to_poses(clip);
  std::vector<float> times(static_cast<std::size_t>(clip.frame_count));
  for (int f = 0; f < clip.frame_count; ++f)
    times[f] = static_cast<float>(figure.start_seconds + f * clip.frame_time);
  const int time_accessor =
      buffers.accessor(buffers.view(times.data(), times.size() * sizeof(float), 0), kFloat,
                       TINYGLTF_TYPE_SCALAR, times.size(), {times.front()}, {times.back()});
  auto add_channel = [&](int node, const char* path, int output) {
    tinygltf::AnimationSampler sampler;
    sampler.input = time_accessor;
    sampler.output = output;
    sampler.interpolation = "LINEAR";
    animation.samplers.push_back(std::move(sampler));
    tinygltf::AnimationChannel channel;
    channel.sampler = static_cast<int>(animation.samplers.size()) - 1;
    channel.target_node = node;
    channel.target_path = path;
    animation.channels.push_back(std::move(channel));
    ++summary.samplers;
  };
  for (int j = 0; j < joint_count; ++j) {
    const motion::SkeletonJoint& joint = skeleton.joints[j];
    if (joint.end_site) continue;
    bool rotates = false, moves = false;
    for (motion::Channel c : joint.channels) (motion::is_rotation(c) ? rotates : moves) = true;
    if (rotates) {
      std::vector<glm::vec4> keys;  // x, y, z, w as glTF stores them
      glm::quat previous(1.0f, 0.0f, 0.0f, 0.0f);
      for (int f = 0; f < clip.frame_count; ++f) {
        glm::quat q = glm::normalize(poses.rotation[poses.at(f, j)]);
        if (glm::dot(q, previous) < 0.0f) q = -q;  // LINEAR keys along the shorter arc
        previous = q;
        keys.emplace_back(q.x, q.y, q.z, q.w);
      }
      add_channel(nodes.node_of_joint[j], "rotation", buffers.floats(keys, TINYGLTF_TYPE_VEC4));
    }
    if (moves) {
      std::vector<glm::vec3> keys;
      for (int f = 0; f < clip.frame_count; ++f)
        keys.push_back(poses.translation[poses.at(f, j)] * scale);
      add_channel(nodes.node_of_joint[j], "translation", buffers.floats(keys, TINYGLTF_TYPE_VEC3));
    }
  }
  summary.frames = std::max(summary.frames, clip.frame_count);
  return roots;
}

}  // namespace

float metres_per_unit_of(const motion::Skeleton& skeleton, const std::string& source) {
  try {
    return motion::map_to_body(skeleton, source).metres_per_unit;
  } catch (const InputError&) {
    return 0.01f;
  }
}

std::vector<std::uint8_t> make_glb(std::span<const GltfFigure> figures, const GltfOptions& options,
                                   GltfSummary* summary_out) {
  if (figures.empty()) throw std::invalid_argument("make_glb: no figures");
  for (const GltfFigure& figure : figures) validate(figure);

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "mocap (tinygltf)";
  BufferBuilder buffers(model);
  tinygltf::Material material;
  material.name = "bones";
  material.pbrMetallicRoughness.baseColorFactor = {0.8, 0.55, 0.2, 1.0};
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 0.7;
  if (options.mesh) model.materials.push_back(std::move(material));

  GltfSummary summary;
  summary.figures = static_cast<int>(figures.size());
  tinygltf::Animation animation;
  animation.name = figures.size() == 1 ? figures.front().name : "mocap";
  tinygltf::Scene scene;
  scene.name = "mocap";
  for (const GltfFigure& figure : figures) {
    const std::vector<int> roots =
        add_figure(figure, figures.size() > 1, options, model, buffers, animation, summary);
    scene.nodes.insert(scene.nodes.end(), roots.begin(), roots.end());
  }
  if (!animation.channels.empty()) model.animations.push_back(std::move(animation));
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;
  model.buffers[0].name = "data";

  tinygltf::TinyGLTF gltf;
  std::ostringstream out;
  if (!gltf.WriteGltfSceneToStream(&model, out, false, true))
    throw std::runtime_error("make_glb: tinygltf could not serialise the model");
  const std::string bytes = out.str();
  summary.bytes = bytes.size();
  if (summary_out) *summary_out = summary;
  return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
}

GltfSummary write_glb(std::span<const GltfFigure> figures, const std::string& path,
                      const GltfOptions& options) {
  GltfSummary summary;
  const std::vector<std::uint8_t> bytes = make_glb(figures, options, &summary);
  const std::string tmp = path + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, "cannot open for writing");
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      throw InputError(path, "write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(path, "cannot move the written file into place");
  }
  return summary;
}

}  // namespace mocap::exporting
