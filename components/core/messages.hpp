#pragma once
// The messages that flow between nodes. Every message starts with a Header; in a process it is
// shared as std::shared_ptr<const T> (immutable once sent, so fan-out costs nothing), between
// processes it travels in the wire format described in docs/wire-format.md.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "core/ground_plane.hpp"
#include "core/image_buffer.hpp"
#include "core/keypoint_layout.hpp"

namespace mocap {

struct Header {
  std::string stream;           // which stream (camera, file) the message belongs to
  std::uint64_t seq = 0;        // counts the messages of one stream from 0
  std::int64_t capture_ns = 0;  // when the source captured it (CLOCK_REALTIME), never a later time
  std::int64_t frame = 0;       // frame index in the source

  bool operator==(const Header&) const = default;
};

// Base of every message type; each derived type names itself with kTypeName, the string used by
// port declarations, graph validation and the wire format.
struct Message {
  Header header;
};

// Cameras are named as in the rig file (camera::Rig, docs/cameras.md): a message says which
// camera saw it by that name, so it stays unambiguous across processes and hosts. A graph with one
// camera uses kDefaultCamera unless its source names another (its `camera` parameter); a
// single-camera file reads as a rig whose one camera has this name.
inline constexpr std::string_view kDefaultCamera = "cam_01";

struct VideoFrame : Message {
  static constexpr std::string_view kTypeName = "VideoFrame";
  std::string camera{kDefaultCamera};  // the camera's name in the rig
  ImageBuffer image;
};

struct Keypoint2D {
  float x = 0, y = 0;
  float confidence = 0;  // NaN coordinates or confidence 0: the keypoint is missing
};

struct Box2D {
  float x = 0, y = 0, width = 0, height = 0;
};

struct Person2D {
  int id = -1;                     // -1 until a tracker assigns one
  std::vector<Keypoint2D> joints;  // in the order of the message's layout
  Box2D box;
};

struct People2D : Message {
  static constexpr std::string_view kTypeName = "People2D";
  LayoutId layout = LayoutId::coco17;
  std::string camera{kDefaultCamera};  // whose image the keypoints are in (its name in the rig)
  std::vector<Person2D> people;
};

// The coordinate frame 3D values are in: a camera's (x right, y down, z forward, metres, the
// camera centre at the origin), named as in the rig, or the rig's world (metres; its axes are the
// rig file's, e.g. Z up for Pose2Sim's and HumanEva's).
struct CoordinateFrame {
  enum class Kind : std::uint8_t { camera = 0, world = 1 };
  Kind kind = Kind::camera;
  std::string camera{kDefaultCamera};  // kind camera: which camera; world: empty

  static CoordinateFrame of_camera(std::string name) { return {Kind::camera, std::move(name)}; }
  static CoordinateFrame world() { return {Kind::world, {}}; }
  bool is_world() const { return kind == Kind::world; }
  bool operator==(const CoordinateFrame&) const = default;
};

struct RigidTransform {
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z
  glm::vec3 translation{0.0f};
};

// Where a 3D pose came from, for debugging the matcher: database clip, frame and view.
struct Provenance {
  std::string clip;
  std::int64_t frame = -1;
  int view = -1;
};

inline std::array<glm::quat, kBodyJoints> identity_rotations() {
  std::array<glm::quat, kBodyJoints> rotations;
  rotations.fill(glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  return rotations;
}

// One person in the coordinate frame of their People3D message (People3D::frame).
struct Person3D {
  int id = -1;
  // Metres, indexed by mocap::Joint, along the axes of the message's frame; relative to the root
  // (mid-hips), which sits at the origin. The joints in the frame: joints_in_frame().
  std::array<glm::vec3, kBodyJoints> positions{};
  std::array<glm::quat, kBodyJoints> rotations = identity_rotations();  // local joint rotations
  // rotation: the matched database body turned into the message's frame. translation: where the
  // root is in that frame (metres) once it is estimated (`placed`: the fitting, or a multi-view
  // triangulation), else zero. A person in the world frame is always placed: their joints in the
  // world are positions + root.translation (poses.jsonl's `joints_world`).
  RigidTransform root;
  bool placed = false;
  Provenance provenance;
  // The 15 body joints of the 2D person this pose was reconstructed from (image pixels, as
  // detected: not undistorted); confidence 0 where missing or unknown.
  std::array<Keypoint2D, kBodyJoints> keypoints{};
};

// The joints where they are in the message's frame: positions + root.translation (meaningful
// when the person is `placed`).
inline std::array<glm::vec3, kBodyJoints> joints_in_frame(const Person3D& person) {
  std::array<glm::vec3, kBodyJoints> out = person.positions;
  for (glm::vec3& p : out) p += person.root.translation;
  return out;
}

struct People3D : Message {
  static constexpr std::string_view kTypeName = "People3D";
  // The frame of every person's positions and root, and of `ground`. The monocular pipeline
  // works in its camera's frame; a multi-view reconstruction in the rig's world.
  CoordinateFrame frame;
  std::vector<Person3D> people;
  bool has_ground = false;  // the floor is known (calibrated or estimated from the feet)
  GroundPlane ground;       // in `frame`
};

// A person prepared for the pose database (the scaler fills `normalized`) and matched against
// it (the matcher fills `candidates`): the message between scaler, matcher and temporal selector.
inline constexpr int kNormalizedDims = 2 * (kBodyJoints - 1);  // the 14 non-root joints as x, y

struct PoseCandidate {
  std::uint32_t projection = 0;  // row of the database's projections
  std::uint32_t frame = 0;       // database frame
  std::uint32_t view = 0;        // database view
  float distance = 0;            // squared distance over the joints present
};

struct PersonMatch {
  int id = -1;
  Box2D box;
  std::array<Keypoint2D, kBodyJoints> body{};       // the 15 body joints, image pixels
  bool normalized_ok = false;                       // false: too few joints or no root
  std::array<float, kNormalizedDims> normalized{};  // root-centred, scaled; NaN = missing
  std::vector<PoseCandidate> candidates;            // nearest first
};

struct PoseMatches : Message {
  static constexpr std::string_view kTypeName = "PoseMatches";
  std::string camera{kDefaultCamera};  // the People2D's camera: the poses are made in its frame
  std::vector<PersonMatch> people;
};

// Flows through every edge after a stream's last message; a node closes once all its inputs have
// ended. Node code never sees it: the framework handles it.
struct EndOfStream : Message {
  static constexpr std::string_view kTypeName = "EndOfStream";
};

}  // namespace mocap
