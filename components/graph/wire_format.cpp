#include "graph/wire_format.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "graph/stats.hpp"

namespace mocap::graph::wire {

static_assert(std::endian::native == std::endian::little,
              "the wire format is little-endian; add byte swapping for this platform");

namespace {

class Writer {
 public:
  template <class T>
  void put(T value) {
    const auto* p = reinterpret_cast<const std::byte*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void put_bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const std::byte*>(data);
    bytes_.insert(bytes_.end(), p, p + size);
  }
  Frame frame() && {
    auto owned = std::make_shared<std::vector<std::byte>>(std::move(bytes_));
    return Frame{owned->data(), owned->size(), owned};
  }

 private:
  std::vector<std::byte> bytes_;
};

class Reader {
 public:
  Reader(const Frame& frame, const char* what) : frame_(frame), what_(what) {}
  template <class T>
  T get() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, frame_.data + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  std::string get_string(std::size_t size) {
    need(size);
    std::string text(reinterpret_cast<const char*>(frame_.data + pos_), size);
    pos_ += size;
    return text;
  }
  void skip(std::size_t size) {
    need(size);
    pos_ += size;
  }
  // A u16 length and that many bytes of a camera name (check_camera_name).
  std::string get_camera_name(const char* what);
  void expect_end() const {
    if (pos_ != frame_.size) {
      throw WireError(std::string(what_) + " frame has " + std::to_string(frame_.size - pos_) +
                      " unexpected trailing bytes");
    }
  }

 private:
  void need(std::size_t size) const {
    if (frame_.size - pos_ < size) throw WireError(std::string(what_) + " frame is truncated");
  }
  const Frame& frame_;
  const char* what_;
  std::size_t pos_ = 0;
};

void expect_size(const Frame& frame, std::size_t expected, const char* what) {
  if (frame.size != expected) {
    throw WireError(std::string(what) + " frame has " + std::to_string(frame.size) +
                    " bytes, expected " + std::to_string(expected));
  }
}

// A camera name: 1..kMaxCameraNameBytes bytes without control characters.
void check_camera_name(std::string_view name, const char* what) {
  if (name.empty()) throw WireError(std::string(what) + ": empty camera name");
  if (name.size() > kMaxCameraNameBytes)
    throw WireError(std::string(what) + ": camera name longer than " +
                    std::to_string(kMaxCameraNameBytes) + " bytes");
  for (const char c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw WireError(std::string(what) + ": a control character in the camera name");
}

std::string Reader::get_camera_name(const char* what) {
  const auto size = get<std::uint16_t>();
  if (size > kMaxCameraNameBytes)
    throw WireError(std::string(what) + ": camera name longer than " +
                    std::to_string(kMaxCameraNameBytes) + " bytes");
  std::string name = get_string(size);
  check_camera_name(name, what);
  return name;
}

void put_camera_name(Writer& w, const std::string& name, const char* what) {
  check_camera_name(name, what);
  w.put<std::uint16_t>(static_cast<std::uint16_t>(name.size()));
  w.put_bytes(name.data(), name.size());
}

template <class T>
std::shared_ptr<T> with_header(const Header& header) {
  auto message = std::make_shared<T>();
  message->header = header;
  return message;
}

// --- encoders: return the payload frames of one message type

std::vector<Frame> encode_video(const VideoFrame& m) {
  const ImageBuffer& image = m.image;
  Writer meta;
  meta.put<std::uint32_t>(static_cast<std::uint32_t>(image.width()));
  meta.put<std::uint32_t>(static_cast<std::uint32_t>(image.height()));
  meta.put<std::uint32_t>(static_cast<std::uint32_t>(image.stride()));
  meta.put<std::uint8_t>(static_cast<std::uint8_t>(image.format()));
  meta.put_bytes("\0", 1);
  put_camera_name(meta, m.camera, "VideoFrame");
  std::vector<Frame> frames;
  frames.push_back(std::move(meta).frame());
  frames.push_back(Frame{image.data(), image.size_bytes(), image.owner()});  // no copy
  return frames;
}

std::vector<Frame> encode_people_2d(const People2D& m) {
  const std::size_t joints = m.people.empty() ? 0 : m.people.front().joints.size();
  Writer meta, values;
  meta.put<std::uint16_t>(static_cast<std::uint16_t>(m.layout));
  meta.put<std::uint16_t>(static_cast<std::uint16_t>(joints));
  meta.put<std::uint32_t>(static_cast<std::uint32_t>(m.people.size()));
  put_camera_name(meta, m.camera, "People2D");
  for (const Person2D& person : m.people) {
    if (person.joints.size() != joints)
      throw WireError("People2D: people with different joint counts");
    meta.put<std::int32_t>(person.id);
    meta.put<float>(person.box.x);
    meta.put<float>(person.box.y);
    meta.put<float>(person.box.width);
    meta.put<float>(person.box.height);
    for (const Keypoint2D& k : person.joints) {
      values.put<float>(k.x);
      values.put<float>(k.y);
      values.put<float>(k.confidence);
    }
  }
  std::vector<Frame> frames;
  frames.push_back(std::move(meta).frame());
  frames.push_back(std::move(values).frame());
  return frames;
}

std::vector<Frame> encode_people_3d(const People3D& m) {
  Writer meta, positions, rotations, clips, placement;
  meta.put<std::uint32_t>(static_cast<std::uint32_t>(m.people.size()));
  meta.put<std::uint8_t>(static_cast<std::uint8_t>(m.frame.kind));
  meta.put<std::uint8_t>(0);
  if (m.frame.is_world()) {
    if (!m.frame.camera.empty()) throw WireError("People3D: the world frame with a camera name");
    meta.put<std::uint16_t>(0);
  } else {
    put_camera_name(meta, m.frame.camera, "People3D");
  }
  placement.put<std::uint32_t>(m.has_ground ? 1u : 0u);
  for (int i = 0; i < 3; ++i) placement.put<float>(static_cast<float>(m.ground.normal[i]));
  placement.put<float>(static_cast<float>(m.ground.offset));
  for (const Person3D& p : m.people) {
    meta.put<std::int32_t>(p.id);
    meta.put<std::int32_t>(p.provenance.view);
    meta.put<std::int64_t>(p.provenance.frame);
    for (float v : {p.root.rotation.w, p.root.rotation.x, p.root.rotation.y, p.root.rotation.z})
      meta.put(v);
    for (int i = 0; i < 3; ++i) meta.put<float>(p.root.translation[i]);
    for (const glm::vec3& v : p.positions) {
      for (int i = 0; i < 3; ++i) positions.put<float>(v[i]);
    }
    for (const glm::quat& q : p.rotations) {
      for (float v : {q.w, q.x, q.y, q.z}) rotations.put(v);
    }
    if (p.provenance.clip.size() > 0xFFFF) throw WireError("People3D: clip name too long");
    clips.put<std::uint16_t>(static_cast<std::uint16_t>(p.provenance.clip.size()));
    clips.put_bytes(p.provenance.clip.data(), p.provenance.clip.size());
    placement.put<std::uint32_t>(p.placed ? 1u : 0u);
    for (const Keypoint2D& k : p.keypoints) {
      placement.put<float>(k.x);
      placement.put<float>(k.y);
      placement.put<float>(k.confidence);
    }
  }
  std::vector<Frame> frames;
  frames.push_back(std::move(meta).frame());
  frames.push_back(std::move(positions).frame());
  frames.push_back(std::move(rotations).frame());
  frames.push_back(std::move(clips).frame());
  frames.push_back(std::move(placement).frame());
  return frames;
}

std::vector<Frame> encode_pose_matches(const PoseMatches& m) {
  Writer meta, body, normalized, candidates;
  meta.put<std::uint32_t>(static_cast<std::uint32_t>(m.people.size()));
  put_camera_name(meta, m.camera, "PoseMatches");
  for (const PersonMatch& p : m.people) {
    if (p.candidates.size() > kMaxCandidates) throw WireError("PoseMatches: too many candidates");
    meta.put<std::int32_t>(p.id);
    for (float v : {p.box.x, p.box.y, p.box.width, p.box.height}) meta.put(v);
    meta.put<std::uint32_t>(p.normalized_ok ? 1u : 0u);
    meta.put<std::uint32_t>(static_cast<std::uint32_t>(p.candidates.size()));
    for (const Keypoint2D& k : p.body) {
      for (float v : {k.x, k.y, k.confidence}) body.put(v);
    }
    for (float v : p.normalized) normalized.put(v);
    for (const PoseCandidate& c : p.candidates) {
      candidates.put(c.projection);
      candidates.put(c.frame);
      candidates.put(c.view);
      candidates.put(c.distance);
    }
  }
  std::vector<Frame> frames;
  frames.push_back(std::move(meta).frame());
  frames.push_back(std::move(body).frame());
  frames.push_back(std::move(normalized).frame());
  frames.push_back(std::move(candidates).frame());
  return frames;
}

std::vector<Frame> encode_stats(const GraphStats& m) {
  nlohmann::json nodes = nlohmann::json::array();
  for (const NodeStats& n : m.nodes) {
    nodes.push_back({{"node", n.node},
                     {"type", n.type},
                     {"process", n.process},
                     {"in", n.in},
                     {"out", n.out},
                     {"drops", n.drops},
                     {"p50_us", n.p50_us},
                     {"p95_us", n.p95_us},
                     {"queue_depth", n.queue_depth},
                     {"max_queue_depth", n.max_queue_depth},
                     {"state", n.state},
                     {"status", n.status}});
  }
  const std::string text = nlohmann::json{{"graph", m.graph}, {"nodes", nodes}}.dump();
  Writer json;
  json.put_bytes(text.data(), text.size());
  std::vector<Frame> frames;
  frames.push_back(std::move(json).frame());
  return frames;
}

// --- decoders

Packet decode_video(const Header& header, std::span<const Frame> payload) {
  Reader meta(payload[0], "VideoFrame meta");
  auto m = with_header<VideoFrame>(header);
  const auto width = meta.get<std::uint32_t>(), height = meta.get<std::uint32_t>();
  const auto stride = meta.get<std::uint32_t>();
  const auto format = pixel_format_from_code(meta.get<std::uint8_t>());
  meta.skip(1);
  m->camera = meta.get_camera_name("VideoFrame");
  meta.expect_end();
  if (!format) throw WireError("VideoFrame: unknown pixel format");
  if (width > kMaxImageSide || height > kMaxImageSide || stride > kMaxImageSide * 4) {
    throw WireError("VideoFrame: image size beyond the limits");
  }
  if (stride < width * static_cast<std::uint32_t>(bytes_per_pixel(*format))) {
    throw WireError("VideoFrame: stride smaller than a row");
  }
  expect_size(payload[1], std::size_t{stride} * height, "VideoFrame pixels");
  m->image = ImageBuffer(static_cast<int>(width), static_cast<int>(height),
                         static_cast<int>(stride), *format, payload[1].owner, payload[1].data);
  return Packet::of<VideoFrame>(std::move(m));
}

Packet decode_people_2d(const Header& header, std::span<const Frame> payload) {
  Reader meta(payload[0], "People2D meta");
  auto m = with_header<People2D>(header);
  const auto layout = meta.get<std::uint16_t>();
  const auto joints = meta.get<std::uint16_t>();
  const auto count = meta.get<std::uint32_t>();
  if (layout > static_cast<std::uint16_t>(LayoutId::humaneva15))
    throw WireError("People2D: unknown layout");
  if (count > kMaxPeople || joints > kMaxJoints)
    throw WireError("People2D: counts beyond the limits");
  m->camera = meta.get_camera_name("People2D");
  expect_size(payload[0], 10 + m->camera.size() + std::size_t{count} * 20, "People2D meta");
  expect_size(payload[1], std::size_t{count} * joints * 12, "People2D keypoints");
  m->layout = static_cast<LayoutId>(layout);
  Reader values(payload[1], "People2D keypoints");
  m->people.resize(count);
  for (Person2D& person : m->people) {
    person.id = meta.get<std::int32_t>();
    person.box = {meta.get<float>(), meta.get<float>(), meta.get<float>(), meta.get<float>()};
    person.joints.resize(joints);
    for (Keypoint2D& k : person.joints)
      k = {values.get<float>(), values.get<float>(), values.get<float>()};
  }
  return Packet::of<People2D>(std::move(m));
}

Packet decode_people_3d(const Header& header, std::span<const Frame> payload) {
  Reader meta(payload[0], "People3D meta");
  auto m = with_header<People3D>(header);
  const auto count = meta.get<std::uint32_t>();
  if (count > kMaxPeople) throw WireError("People3D: person count beyond the limits");
  const auto kind = meta.get<std::uint8_t>();
  meta.skip(1);
  if (kind == static_cast<std::uint8_t>(CoordinateFrame::Kind::world)) {
    if (meta.get<std::uint16_t>() != 0) throw WireError("People3D: the world frame with a camera");
    m->frame = CoordinateFrame::world();
  } else if (kind == static_cast<std::uint8_t>(CoordinateFrame::Kind::camera)) {
    m->frame = CoordinateFrame::of_camera(meta.get_camera_name("People3D"));
  } else {
    throw WireError("People3D: unknown frame kind " + std::to_string(kind));
  }
  expect_size(payload[0], 8 + m->frame.camera.size() + std::size_t{count} * 44, "People3D meta");
  expect_size(payload[1], std::size_t{count} * kBodyJoints * 12, "People3D positions");
  expect_size(payload[2], std::size_t{count} * kBodyJoints * 16, "People3D rotations");
  Reader positions(payload[1], "People3D positions"), rotations(payload[2], "People3D rotations");
  Reader clips(payload[3], "People3D provenance");
  expect_size(payload[4], 20 + std::size_t{count} * (4 + kBodyJoints * 12), "People3D placement");
  Reader placement(payload[4], "People3D placement");
  m->has_ground = placement.get<std::uint32_t>() != 0;
  for (int i = 0; i < 3; ++i) m->ground.normal[i] = placement.get<float>();
  m->ground.offset = placement.get<float>();
  m->people.resize(count);
  for (Person3D& p : m->people) {
    p.id = meta.get<std::int32_t>();
    p.provenance.view = meta.get<std::int32_t>();
    p.provenance.frame = meta.get<std::int64_t>();
    const float w = meta.get<float>(), x = meta.get<float>(), y = meta.get<float>(),
                z = meta.get<float>();
    p.root.rotation = glm::quat(w, x, y, z);
    for (int i = 0; i < 3; ++i) p.root.translation[i] = meta.get<float>();
    for (glm::vec3& v : p.positions) {
      for (int i = 0; i < 3; ++i) v[i] = positions.get<float>();
    }
    for (glm::quat& q : p.rotations) {
      const float qw = rotations.get<float>(), qx = rotations.get<float>();
      const float qy = rotations.get<float>(), qz = rotations.get<float>();
      q = glm::quat(qw, qx, qy, qz);
    }
    p.provenance.clip = clips.get_string(clips.get<std::uint16_t>());
    p.placed = placement.get<std::uint32_t>() != 0;
    for (Keypoint2D& k : p.keypoints)
      k = {placement.get<float>(), placement.get<float>(), placement.get<float>()};
  }
  clips.expect_end();
  placement.expect_end();
  return Packet::of<People3D>(std::move(m));
}

Packet decode_pose_matches(const Header& header, std::span<const Frame> payload) {
  Reader meta(payload[0], "PoseMatches meta");
  auto m = with_header<PoseMatches>(header);
  const auto count = meta.get<std::uint32_t>();
  if (count > kMaxPeople) throw WireError("PoseMatches: person count beyond the limits");
  m->camera = meta.get_camera_name("PoseMatches");
  expect_size(payload[0], 6 + m->camera.size() + std::size_t{count} * 28, "PoseMatches meta");
  expect_size(payload[1], std::size_t{count} * kBodyJoints * 12, "PoseMatches body");
  expect_size(payload[2], std::size_t{count} * kNormalizedDims * 4, "PoseMatches normalized");
  Reader body(payload[1], "PoseMatches body"), normalized(payload[2], "PoseMatches normalized");
  Reader candidates(payload[3], "PoseMatches candidates");
  m->people.resize(count);
  std::size_t total = 0;
  for (PersonMatch& p : m->people) {
    p.id = meta.get<std::int32_t>();
    p.box = {meta.get<float>(), meta.get<float>(), meta.get<float>(), meta.get<float>()};
    p.normalized_ok = meta.get<std::uint32_t>() != 0;
    const auto n = meta.get<std::uint32_t>();
    if (n > kMaxCandidates) throw WireError("PoseMatches: candidate count beyond the limits");
    total += n;
    if (total * 16 > payload[3].size) throw WireError("PoseMatches: candidates frame too short");
    for (Keypoint2D& k : p.body) k = {body.get<float>(), body.get<float>(), body.get<float>()};
    for (float& v : p.normalized) v = normalized.get<float>();
    p.candidates.resize(n);
    for (PoseCandidate& c : p.candidates) {
      c.projection = candidates.get<std::uint32_t>();
      c.frame = candidates.get<std::uint32_t>();
      c.view = candidates.get<std::uint32_t>();
      c.distance = candidates.get<float>();
    }
  }
  candidates.expect_end();
  return Packet::of<PoseMatches>(std::move(m));
}

// A number of a GraphStats node entry: counts must be non-negative integers, times any finite
// number (a JSON 1e61 converted to an integer would be undefined behaviour).
std::uint64_t stats_count(const nlohmann::json& node, const char* key) {
  const nlohmann::json& v = node.at(key);
  if (v.is_number_unsigned()) return v.get<std::uint64_t>();
  throw WireError(std::string("GraphStats: '") + key + "' is not a non-negative integer");
}

double stats_time(const nlohmann::json& node, const char* key) {
  const nlohmann::json& v = node.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    throw WireError(std::string("GraphStats: '") + key + "' is not a finite number");
  return v.get<double>();
}

Packet decode_stats(const Header& header, std::span<const Frame> payload) {
  if (payload[0].size > kMaxStatsBytes) throw WireError("GraphStats: too large");
  auto m = with_header<GraphStats>(header);
  try {
    const auto json =
        nlohmann::json::parse(reinterpret_cast<const char*>(payload[0].data),
                              reinterpret_cast<const char*>(payload[0].data) + payload[0].size);
    m->graph = json.at("graph").get<std::string>();
    for (const auto& n : json.at("nodes")) {
      // "status" came later within version 1: a sender without it has no status to report.
      m->nodes.push_back(NodeStats{
          n.at("node"), n.at("type"), n.at("process"), stats_count(n, "in"), stats_count(n, "out"),
          stats_count(n, "drops"), stats_time(n, "p50_us"), stats_time(n, "p95_us"),
          static_cast<std::size_t>(stats_count(n, "queue_depth")),
          static_cast<std::size_t>(stats_count(n, "max_queue_depth")), n.at("state"),
          n.value("status", std::string())});
    }
  } catch (const nlohmann::json::exception& e) {
    throw WireError(std::string("GraphStats: ") + e.what());
  }
  return Packet::of<GraphStats>(std::move(m));
}

struct TypeInfo {
  TypeCode code;
  std::string_view name;
  std::size_t payload_frames;
};
constexpr TypeInfo kTypes[] = {
    {TypeCode::end_of_stream, EndOfStream::kTypeName, 0},
    {TypeCode::video_frame, VideoFrame::kTypeName, 2},
    {TypeCode::people_2d, People2D::kTypeName, 2},
    {TypeCode::people_3d, People3D::kTypeName, 5},
    {TypeCode::graph_stats, GraphStats::kTypeName, 1},
    {TypeCode::pose_matches, PoseMatches::kTypeName, 4},
};

const TypeInfo& info_by_name(std::string_view name) {
  for (const TypeInfo& t : kTypes) {
    if (t.name == name) return t;
  }
  throw WireError("message type " + std::string(name) + " has no wire encoding");
}

}  // namespace

std::vector<Frame> encode(const Packet& packet, std::int64_t send_ns) {
  const TypeInfo& info = info_by_name(packet.type);
  std::vector<Frame> payload;
  switch (info.code) {
    case TypeCode::end_of_stream:
      break;
    case TypeCode::video_frame:
      payload = encode_video(static_cast<const VideoFrame&>(*packet.message));
      break;
    case TypeCode::people_2d:
      payload = encode_people_2d(static_cast<const People2D&>(*packet.message));
      break;
    case TypeCode::people_3d:
      payload = encode_people_3d(static_cast<const People3D&>(*packet.message));
      break;
    case TypeCode::graph_stats:
      payload = encode_stats(static_cast<const GraphStats&>(*packet.message));
      break;
    case TypeCode::pose_matches:
      payload = encode_pose_matches(static_cast<const PoseMatches&>(*packet.message));
      break;
  }
  const Header& h = packet.header();
  if (h.stream.size() > kMaxStreamIdBytes) throw WireError("stream id longer than 1024 bytes");
  Writer header;
  header.put_bytes(kMagic, 4);
  header.put<std::uint16_t>(kVersion);
  header.put<std::uint16_t>(static_cast<std::uint16_t>(info.code));
  header.put<std::uint64_t>(h.seq);
  header.put<std::int64_t>(h.capture_ns);
  header.put<std::int64_t>(h.frame);
  header.put<std::int64_t>(send_ns);
  header.put<std::uint16_t>(static_cast<std::uint16_t>(h.stream.size()));
  header.put<std::uint16_t>(static_cast<std::uint16_t>(payload.size()));
  header.put_bytes(h.stream.data(), h.stream.size());
  std::vector<Frame> frames;
  frames.reserve(payload.size() + 1);
  frames.push_back(std::move(header).frame());
  for (Frame& f : payload) frames.push_back(std::move(f));
  return frames;
}

Decoded decode(std::span<const Frame> frames) {
  if (frames.empty()) throw WireError("empty message");
  if (frames.size() > kMaxFrames + 1)
    throw WireError("too many frames (" + std::to_string(frames.size()) + ")");
  Reader reader(frames[0], "header");
  if (frames[0].size < kHeaderBytes || std::memcmp(frames[0].data, kMagic, 4) != 0) {
    throw WireError("not a mocap message (bad magic or short header)");
  }
  reader.skip(4);
  const auto version = reader.get<std::uint16_t>();
  if (version != kVersion) {
    throw WireError("wire format version " + std::to_string(version) +
                    " is not supported (this program speaks " + std::to_string(kVersion) +
                    (version < kVersion ? "; the sender is older: update it, e.g. "
                                          "tools/remote/send_keypoints.py, to version " +
                                              std::to_string(kVersion) + ")"
                                        : ")"));
  }
  const auto code = reader.get<std::uint16_t>();
  const TypeInfo* info = nullptr;
  for (const TypeInfo& t : kTypes) {
    if (static_cast<std::uint16_t>(t.code) == code) info = &t;
  }
  if (!info) throw WireError("unknown message type code " + std::to_string(code));
  Header header;
  header.seq = reader.get<std::uint64_t>();
  header.capture_ns = reader.get<std::int64_t>();
  header.frame = reader.get<std::int64_t>();
  const auto send_ns = reader.get<std::int64_t>();
  const auto stream_bytes = reader.get<std::uint16_t>();
  const auto payload_frames = reader.get<std::uint16_t>();
  if (stream_bytes > kMaxStreamIdBytes) throw WireError("stream id too long");
  header.stream = reader.get_string(stream_bytes);
  reader.expect_end();
  if (payload_frames != info->payload_frames || frames.size() != payload_frames + 1u) {
    throw WireError(std::string(info->name) + " needs " + std::to_string(info->payload_frames) +
                    " payload frames, got " + std::to_string(frames.size() - 1));
  }
  const auto payload = frames.subspan(1);
  switch (info->code) {
    case TypeCode::end_of_stream:
      return {Packet::end_of_stream(header), send_ns};
    case TypeCode::video_frame:
      return {decode_video(header, payload), send_ns};
    case TypeCode::people_2d:
      return {decode_people_2d(header, payload), send_ns};
    case TypeCode::people_3d:
      return {decode_people_3d(header, payload), send_ns};
    case TypeCode::graph_stats:
      return {decode_stats(header, payload), send_ns};
    case TypeCode::pose_matches:
      return {decode_pose_matches(header, payload), send_ns};
  }
  throw WireError("unknown message type");
}

}  // namespace mocap::graph::wire
