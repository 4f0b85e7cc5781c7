#include "io/humaneva.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "core/keypoint_layout.hpp"
#include "io/read_file.hpp"

namespace mocap::io::humaneva {
namespace {

struct RangeEntry {
  Split split;
  std::string_view subject;
  std::string_view action;
  FrameRange range;
};

// VideoPose3D data/prepare_data_humaneva.py, `index` (trial 1 of every action).
constexpr RangeEntry kRanges[] = {
    {Split::train, "S1", "Walking", {590, 1203}},
    {Split::train, "S1", "Jog", {367, 740}},
    {Split::train, "S1", "ThrowCatch", {473, 945}},
    {Split::train, "S1", "Gestures", {395, 801}},
    {Split::train, "S1", "Box", {385, 789}},
    {Split::train, "S2", "Walking", {438, 876}},
    {Split::train, "S2", "Jog", {398, 795}},
    {Split::train, "S2", "ThrowCatch", {550, 1128}},
    {Split::train, "S2", "Gestures", {500, 901}},
    {Split::train, "S2", "Box", {382, 734}},
    {Split::train, "S3", "Walking", {448, 939}},
    {Split::train, "S3", "Jog", {401, 842}},
    {Split::train, "S3", "ThrowCatch", {493, 1027}},
    {Split::train, "S3", "Gestures", {533, 1102}},
    {Split::train, "S3", "Box", {512, 1021}},
    {Split::validate, "S1", "Walking", {5, 590}},
    {Split::validate, "S1", "Jog", {5, 367}},
    {Split::validate, "S1", "ThrowCatch", {5, 473}},
    {Split::validate, "S1", "Gestures", {5, 395}},
    {Split::validate, "S1", "Box", {5, 385}},
    {Split::validate, "S2", "Walking", {5, 438}},
    {Split::validate, "S2", "Jog", {5, 398}},
    {Split::validate, "S2", "ThrowCatch", {5, 550}},
    {Split::validate, "S2", "Gestures", {5, 500}},
    {Split::validate, "S2", "Box", {5, 382}},
    {Split::validate, "S3", "Walking", {5, 448}},
    {Split::validate, "S3", "Jog", {5, 401}},
    {Split::validate, "S3", "ThrowCatch", {5, 493}},
    {Split::validate, "S3", "Gestures", {5, 533}},
    {Split::validate, "S3", "Box", {5, 512}},
};

// "Validate/S2" → (validate, "S2").
std::pair<Split, std::string> parse_subject_key(const std::string& key, const std::string& source) {
  const auto slash = key.find('/');
  const std::string split = key.substr(0, slash);
  if (slash == std::string::npos || (split != "Train" && split != "Validate")) {
    throw InputError(source, "subject key '" + key + "' is not Train/<S> or Validate/<S>");
  }
  return {split == "Train" ? Split::train : Split::validate, key.substr(slash + 1)};
}

bool all_digits(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// "Walking 1 chunk0" → action, trial, chunk.
std::tuple<std::string, int, int> parse_action_key(const std::string& key,
                                                   const std::string& source) {
  const auto bad = [&]() {
    return InputError(source, "action key '" + key + "' is not '<Action> <trial> chunk<n>'");
  };
  const auto first = key.find(' '), second = key.rfind(' ');
  if (first == std::string::npos || first == second) throw bad();
  const std::string trial = key.substr(first + 1, second - first - 1);
  const std::string chunk = key.substr(second + 1);
  if (trial.empty() || trial.size() > 3 || chunk.size() <= 5 || chunk.size() > 9 ||
      chunk.rfind("chunk", 0) != 0 || !all_digits(trial) || !all_digits(chunk.substr(5))) {
    throw bad();
  }
  return {key.substr(0, first), std::stoi(trial), std::stoi(chunk.substr(5))};
}

// Checks the shape (frames, 15, dims) and returns the elements as floats.
std::vector<float> joint_array(const NdArray& a, std::size_t dims, const std::string& where) {
  if (a.shape.size() != 3 || a.shape[1] != kJoints || a.shape[2] != dims) {
    std::string shape;
    for (std::size_t d : a.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
    throw InputError(
        where, "expected shape (frames, 15, " + std::to_string(dims) + "), found (" + shape + ")");
  }
  if (a.dtype == DType::object) throw InputError(where, "expected numbers, found objects");
  std::vector<float> values = a.to_floats();
  if (!std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); })) {
    throw InputError(where, "holds NaN or infinite values");
  }
  return values;
}

std::vector<Pose3> poses_3d(const NdArray& a, const std::string& where) {
  const std::vector<float> v = joint_array(a, 3, where);
  std::vector<Pose3> out(a.shape[0]);
  for (std::size_t i = 0; i < v.size() / 3; ++i) {
    out[i / kJoints][i % kJoints] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  }
  return out;
}

std::vector<Pose2> poses_2d(const NdArray& a, const std::string& where) {
  const std::vector<float> v = joint_array(a, 2, where);
  std::vector<Pose2> out(a.shape[0]);
  for (std::size_t i = 0; i < v.size() / 2; ++i) {
    out[i / kJoints][i % kJoints] = {v[2 * i], v[2 * i + 1]};
  }
  return out;
}

Pickle::Value dict_root(const NpyContent& content, const std::string& where) {
  if (!content.objects) throw InputError(where, "expected a pickled dict (object array)");
  const Pickle::Value root = content.objects->root().item();
  if (root.kind() != Pickle::Kind::dict) throw InputError(where, "expected a dict");
  return root;
}

Chunk make_chunk(const std::string& subject_key, const std::string& action_key,
                 const std::string& source) {
  Chunk c;
  std::tie(c.split, c.subject) = parse_subject_key(subject_key, source);
  std::tie(c.action, c.trial, c.chunk) = parse_action_key(action_key, source);
  c.key = action_key;
  const auto range = frame_range(c.split, c.subject, c.action);
  if (!range || c.trial != 1) {
    throw InputError(source, subject_key + " / " + action_key + " has no known frame range");
  }
  c.range = *range;
  if (c.chunk == 0) c.first_frame = range->begin;
  return c;
}

void sort_chunks(std::vector<Chunk>& chunks) {
  std::sort(chunks.begin(), chunks.end(), [](const Chunk& a, const Chunk& b) {
    return std::tie(a.split, a.subject, a.action, a.chunk) <
           std::tie(b.split, b.subject, b.action, b.chunk);
  });
}

// The frames of one (split, subject, action) cannot exceed its range.
void check_ranges(const std::vector<Chunk>& chunks, const std::string& source) {
  std::map<std::tuple<Split, std::string, std::string>, std::size_t> frames;
  for (const auto& c : chunks) {
    std::size_t& n = frames[{c.split, c.subject, c.action}];
    n += c.frames();
    if (n > static_cast<std::size_t>(c.range.size())) {
      throw InputError(source, std::string(to_string(c.split)) + "/" + c.subject + " " + c.action +
                                   " has more frames than its range " +
                                   std::to_string(c.range.begin) + ".." +
                                   std::to_string(c.range.end));
    }
  }
}

void check_metadata(const NpzFile& npz, const std::string& source) {
  if (!npz.contains("metadata")) return;
  const NpyContent content = npz.read("metadata");
  const Pickle::Value meta = dict_root(content, source + ":metadata");
  const auto joints = meta.find("num_joints");
  if (joints && joints->as_int() != kJoints) {
    throw InputError(source, "metadata says " + std::to_string(joints->as_int()) +
                                 " joints; HumanEva-15 has 15");
  }
}

Chunk& chunk_for(Dataset& dataset, const std::string& subject_key, const std::string& action_key,
                 const std::string& source) {
  const Chunk probe = make_chunk(subject_key, action_key, source);
  for (auto& c : dataset.chunks) {
    if (c.split == probe.split && c.subject == probe.subject && c.key == probe.key) return c;
  }
  throw InputError(source, "2D chunk " + subject_key + " / " + action_key + " has no 3D chunk");
}

using nlohmann::json;

const json& member(const json& object, const std::string& key, const std::string& path,
                   const std::string& source) {
  if (!object.is_object() || !object.contains(key)) {
    throw InputError(source, "missing key " + path + (path.empty() ? "" : ".") + key);
  }
  return object.at(key);
}

double number(const json& value, const std::string& path, const std::string& source) {
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    throw InputError(source, path + " is not a finite number");
  }
  return value.get<double>();
}

glm::dvec3 vector3(const json& value, const std::string& path, const std::string& source) {
  if (!value.is_array() || value.size() != 3) throw InputError(source, path + " is not [x, y, z]");
  return {number(value[0], path + "[0]", source), number(value[1], path + "[1]", source),
          number(value[2], path + "[2]", source)};
}

glm::dquat quaternion(const json& value, const std::string& path, const std::string& source) {
  if (!value.is_array() || value.size() != 4)
    throw InputError(source, path + " is not [w, x, y, z]");
  glm::dquat q(number(value[0], path + "[0]", source), number(value[1], path + "[1]", source),
               number(value[2], path + "[2]", source), number(value[3], path + "[3]", source));
  const double length = glm::length(q);
  if (std::abs(length - 1.0) > 1e-3) throw InputError(source, path + " is not a unit quaternion");
  return q / length;
}

camera::Camera read_camera(const json& extrinsic, const json& intrinsics, int index,
                           const std::string& path, const std::string& source) {
  camera::Camera cam;
  cam.name = std::string(kCameraNames[index]);
  cam.width = 640;
  cam.height = 480;
  const json& id = member(extrinsic, "id", path, source);
  if (!id.is_string() || id.get<std::string>() != cam.name) {
    throw InputError(source, path + ".id should be " + cam.name);
  }
  // VideoPose3D's orientation rotates camera-frame vectors into the world.
  const glm::dquat orientation =
      quaternion(member(extrinsic, "orientation", path, source), path + ".orientation", source);
  const glm::dvec3 centre =
      vector3(member(extrinsic, "translation_mm", path, source), path + ".translation_mm", source) /
      1000.0;
  cam.set_pose_from_centre(glm::mat3_cast(orientation), centre);
  const std::string ipath = "approx_intrinsics_fitted." + cam.name;
  const json& k = member(intrinsics, cam.name, "approx_intrinsics_fitted", source);
  cam.fx = number(member(k, "fx", ipath, source), ipath + ".fx", source);
  cam.fy = number(member(k, "fy", ipath, source), ipath + ".fy", source);
  cam.cx = number(member(k, "cx", ipath, source), ipath + ".cx", source);
  cam.cy = number(member(k, "cy", ipath, source), ipath + ".cy", source);
  if (const std::string p = camera::camera_problem(cam); !p.empty())
    throw InputError(source, ipath + ": the camera " + p);
  return cam;
}

}  // namespace

std::string_view to_string(Split split) { return split == Split::train ? "Train" : "Validate"; }

std::optional<FrameRange> frame_range(Split split, std::string_view subject,
                                      std::string_view action) {
  for (const auto& r : kRanges) {
    if (r.split == split && r.subject == subject && r.action == action) return r.range;
  }
  return std::nullopt;
}

std::vector<const Chunk*> Dataset::select(std::optional<Split> split, std::string_view subject,
                                          std::string_view action) const {
  std::vector<const Chunk*> out;
  for (const auto& c : chunks) {
    if ((!split || c.split == *split) && (subject.empty() || c.subject == subject) &&
        (action.empty() || c.action == action)) {
      out.push_back(&c);
    }
  }
  return out;
}

Dataset read_positions_3d(const std::filesystem::path& npz, const NpyLimits& limits) {
  return read_positions_3d(NpzFile::open(npz, limits), npz.string());
}

Dataset read_positions_3d(const NpzFile& file, const std::string& source) {
  const NpyContent content = file.read("positions_3d");
  const Pickle::Value subjects = dict_root(content, source);
  Dataset out;
  for (std::size_t s = 0; s < subjects.dict_size(); ++s) {
    const std::string& subject_key = subjects.key(s).as_string();
    const Pickle::Value actions = subjects.value(s);
    for (std::size_t a = 0; a < actions.dict_size(); ++a) {
      const std::string& action_key = actions.key(a).as_string();
      Chunk c = make_chunk(subject_key, action_key, source);
      c.positions_3d =
          poses_3d(actions.value(a).array(), source + " " + subject_key + " / " + action_key);
      if (c.positions_3d.empty())
        throw InputError(source, subject_key + " / " + action_key + " is empty");
      out.chunks.push_back(std::move(c));
    }
  }
  if (out.chunks.empty()) throw InputError(source, "no chunks");
  sort_chunks(out.chunks);
  check_ranges(out.chunks, source);
  return out;
}

void attach_positions_2d(Dataset& dataset, const std::filesystem::path& npz,
                         const NpyLimits& limits) {
  attach_positions_2d(dataset, NpzFile::open(npz, limits), npz.string());
}

void attach_positions_2d(Dataset& dataset, const NpzFile& file, const std::string& source) {
  check_metadata(file, source);
  const NpyContent content = file.read("positions_2d");
  const Pickle::Value subjects = dict_root(content, source);
  std::size_t attached = 0;
  for (std::size_t s = 0; s < subjects.dict_size(); ++s) {
    const std::string& subject_key = subjects.key(s).as_string();
    const Pickle::Value actions = subjects.value(s);
    for (std::size_t a = 0; a < actions.dict_size(); ++a) {
      const std::string& action_key = actions.key(a).as_string();
      const std::string where = source + " " + subject_key + " / " + action_key;
      Chunk& chunk = chunk_for(dataset, subject_key, action_key, source);
      const Pickle::Value cameras = actions.value(a);
      if (cameras.size() != kCameras) throw InputError(where, "expected 3 cameras");
      for (int k = 0; k < kCameras; ++k) {
        auto poses = poses_2d(cameras[k].array(), where + " " + std::string(kCameraNames[k]));
        if (poses.size() != chunk.frames()) {
          throw InputError(where, std::to_string(poses.size()) + " 2D frames for " +
                                      std::to_string(chunk.frames()) + " 3D frames");
        }
        chunk.positions_2d[k] = std::move(poses);
      }
      ++attached;
    }
  }
  if (attached != dataset.chunks.size()) {
    throw InputError(source, std::to_string(dataset.chunks.size() - attached) +
                                 " 3D chunks have no 2D ground truth");
  }
}

Dataset load_dataset(const std::filesystem::path& folder, const LoadOptions& options) {
  Dataset d = read_positions_3d(folder / kPositions3dFile, options.limits);
  if (options.load_2d) attach_positions_2d(d, folder / kPositions2dFile, options.limits);
  return d;
}

std::map<std::string, camera::Rig> load_cameras(const std::filesystem::path& file) {
  return parse_cameras(read_whole_file(file, 1u << 20), file.string());
}

std::map<std::string, camera::Rig> parse_cameras(std::string_view text, const std::string& source) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(source, std::string("not valid JSON: ") + e.what());
  }
  const json& extrinsics = member(doc, "extrinsics", "", source);
  const json& intrinsics = member(doc, "approx_intrinsics_fitted", "", source);
  if (!extrinsics.is_object() || extrinsics.empty()) throw InputError(source, "no extrinsics");
  std::map<std::string, camera::Rig> out;
  for (const auto& [subject, cameras] : extrinsics.items()) {
    const std::string path = "extrinsics." + subject;
    if (!cameras.is_array() || cameras.size() != kCameras) {
      throw InputError(source, path + " is not a list of 3 cameras");
    }
    camera::Rig& rig = out[subject];
    for (int k = 0; k < kCameras; ++k) {
      rig.cameras.push_back(
          read_camera(cameras[k], intrinsics, k, path + "[" + std::to_string(k) + "]", source));
    }
    rig.floor = GroundPlane{{0.0, 0.0, 1.0}, 0.0};  // the world's Z = 0 plane, Z up
  }
  return out;
}

std::array<glm::vec3, kBodyJoints> to_body15(const Pose3& pose) {
  const KeypointLayout& he = layout(LayoutId::humaneva15);
  std::array<glm::vec3, kBodyJoints> out{};
  for (int j = 0; j < kBodyJoints; ++j) {
    const JointSource& s = he.body[j];
    out[j] = s.second < 0 ? pose[s.first] : 0.5f * (pose[s.first] + pose[s.second]);
  }
  return out;
}

}  // namespace mocap::io::humaneva
