// The wire format: every message type round-trips, images are not copied, and garbage (truncated,
// random, wrong version, lying counts) is rejected with a message, never a crash.

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "graph/stats.hpp"
#include "graph/wire_format.hpp"

namespace mocap::graph {
namespace {

using wire::Frame;
using wire::WireError;

Header header(std::uint64_t seq) {
  return Header{"cam0", seq, 1'700'000'000'123'456'789 + static_cast<std::int64_t>(seq),
                40 + static_cast<std::int64_t>(seq)};
}

std::shared_ptr<People2D> people_2d() {
  auto m = std::make_shared<People2D>();
  m->header = header(7);
  m->layout = LayoutId::body25;
  m->camera = "left cam";
  for (int p = 0; p < 3; ++p) {
    Person2D person;
    person.id = p - 1;
    person.box = {1.0f * p, 2, 3, 4};
    for (int j = 0; j < 25; ++j)
      person.joints.push_back({0.5f * j, 100.0f + p, j == 3 ? std::nanf("") : 0.9f});
    m->people.push_back(person);
  }
  return m;
}

std::shared_ptr<People3D> people_3d() {
  auto m = std::make_shared<People3D>();
  m->header = header(9);
  Person3D person;
  person.id = 4;
  for (int j = 0; j < kBodyJoints; ++j)
    person.positions[static_cast<std::size_t>(j)] = {0.1f * j, -1.0f, 3.0f};
  person.rotations[2] = glm::quat(0.5f, 0.5f, -0.5f, 0.5f);
  person.root = {glm::quat(0.0f, 1.0f, 0.0f, 0.0f), {1, 2, 3}};
  person.provenance = {"cmu/02_01", 120, 7};
  person.placed = true;
  person.keypoints[3] = {640.5f, 360.25f, 0.75f};
  m->people = {person, Person3D{}};
  m->frame = CoordinateFrame::of_camera("cam_02");
  m->has_ground = true;
  m->ground = {glm::dvec3(glm::vec3(0.0f, -0.96f, 0.28f)), 1.6};
  return m;
}

std::shared_ptr<VideoFrame> video_frame() {
  auto m = std::make_shared<VideoFrame>();
  m->header = header(3);
  m->camera = "cam_03";
  m->image = ImageBuffer(64, 48, PixelFormat::bgr8);
  auto pixels = m->image.pixels_for_writing();
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::byte>(i * 7);
  return m;
}

// What a receiver sees: each frame copied into its own buffer, as ZeroMQ delivers them.
std::vector<Frame> as_received(const std::vector<Frame>& sent) {
  std::vector<Frame> frames;
  for (const Frame& f : sent) {
    auto copy = std::make_shared<std::vector<std::byte>>(f.data, f.data + f.size);
    frames.push_back({copy->data(), copy->size(), copy});
  }
  return frames;
}

Packet round_trip(const Packet& packet) {
  return wire::decode(as_received(wire::encode(packet, 42))).packet;
}

TEST(WireFormat, People2DRoundTrips) {
  const auto original = people_2d();
  const Packet back = round_trip(Packet::of<People2D>(original));
  ASSERT_EQ(back.type, People2D::kTypeName);
  const auto& m = static_cast<const People2D&>(*back.message);
  EXPECT_EQ(m.header, original->header);
  EXPECT_EQ(m.layout, LayoutId::body25);
  EXPECT_EQ(m.camera, "left cam");
  ASSERT_EQ(m.people.size(), 3u);
  EXPECT_EQ(m.people[0].id, -1);
  EXPECT_EQ(m.people[2].box.x, 2.0f);
  EXPECT_EQ(m.people[1].joints[24].x, 12.0f);
  EXPECT_TRUE(std::isnan(m.people[1].joints[3].confidence));
}

TEST(WireFormat, People3DRoundTrips) {
  const auto original = people_3d();
  const Packet back = round_trip(Packet::of<People3D>(original));
  const auto& m = static_cast<const People3D&>(*back.message);
  ASSERT_EQ(m.people.size(), 2u);
  const Person3D& p = m.people[0];
  EXPECT_EQ(p.id, 4);
  EXPECT_EQ(p.positions[14], original->people[0].positions[14]);
  EXPECT_EQ(p.rotations[2], original->people[0].rotations[2]);
  EXPECT_EQ(p.root.rotation, original->people[0].root.rotation);
  EXPECT_EQ(p.root.translation, glm::vec3(1, 2, 3));
  EXPECT_EQ(p.provenance.clip, "cmu/02_01");
  EXPECT_EQ(p.provenance.frame, 120);
  EXPECT_EQ(p.provenance.view, 7);
  EXPECT_TRUE(p.placed);
  EXPECT_EQ(p.keypoints[3].x, 640.5f);
  EXPECT_EQ(p.keypoints[3].y, 360.25f);
  EXPECT_EQ(p.keypoints[3].confidence, 0.75f);
  EXPECT_EQ(m.people[1].provenance.clip, "");
  EXPECT_FALSE(m.people[1].placed);
  EXPECT_EQ(m.frame, CoordinateFrame::of_camera("cam_02"));
  EXPECT_TRUE(m.has_ground);
  EXPECT_EQ(m.ground.normal, glm::dvec3(glm::vec3(0.0f, -0.96f, 0.28f)));  // binary32 on the wire
  EXPECT_EQ(m.ground.offset, static_cast<double>(1.6f));
  // The rig's world: no camera name.
  original->frame = CoordinateFrame::world();
  const Packet world = round_trip(Packet::of<People3D>(original));
  EXPECT_TRUE(static_cast<const People3D&>(*world.message).frame.is_world());
  EXPECT_EQ(static_cast<const People3D&>(*world.message).frame.camera, "");
}

TEST(WireFormat, PoseMatchesRoundTrips) {
  auto original = std::make_shared<PoseMatches>();
  original->header.stream = "cam0";
  original->camera = "side";
  for (int p = 0; p < 3; ++p) {
    PersonMatch person;
    person.id = 10 + p;
    person.box = {1.0f * p, 2.0f, 3.0f, 4.0f};
    person.normalized_ok = p != 1;
    person.body[5] = {5.0f, 6.0f, 0.5f};
    person.normalized[27] = p == 2 ? std::numeric_limits<float>::quiet_NaN() : 0.25f;
    for (int c = 0; c < p * 2; ++c) person.candidates.push_back({100u + c, 7u, 3u, 0.5f * c});
    original->people.push_back(person);
  }
  const Packet back = round_trip(Packet::of<PoseMatches>(original));
  const auto& m = static_cast<const PoseMatches&>(*back.message);
  EXPECT_EQ(m.camera, "side");
  ASSERT_EQ(m.people.size(), 3u);
  EXPECT_EQ(m.people[2].id, 12);
  EXPECT_FALSE(m.people[1].normalized_ok);
  EXPECT_EQ(m.people[0].body[5].y, 6.0f);
  EXPECT_EQ(m.people[1].normalized[27], 0.25f);
  EXPECT_TRUE(std::isnan(m.people[2].normalized[27]));
  ASSERT_EQ(m.people[2].candidates.size(), 4u);
  EXPECT_EQ(m.people[2].candidates[3].projection, 103u);
  EXPECT_EQ(m.people[2].candidates[3].distance, 1.5f);
  EXPECT_TRUE(m.people[0].candidates.empty());
}

TEST(WireFormat, VideoFrameTravelsWithoutCopies) {
  const auto original = video_frame();
  const std::vector<Frame> sent = wire::encode(Packet::of<VideoFrame>(original), 0);
  ASSERT_EQ(sent.size(), 3u);
  EXPECT_EQ(sent[2].data, original->image.data());  // the encoder references the pixels
  const std::vector<Frame> received = as_received(sent);
  const Packet back = wire::decode(received).packet;
  const auto& m = static_cast<const VideoFrame&>(*back.message);
  EXPECT_EQ(m.image.data(), received[2].data);  // the decoder wraps the received frame
  EXPECT_EQ(m.camera, "cam_03");
  EXPECT_EQ(m.image.width(), 64);
  EXPECT_EQ(m.image.format(), PixelFormat::bgr8);
  EXPECT_EQ(std::memcmp(m.image.data(), original->image.data(), original->image.size_bytes()), 0);
}

TEST(WireFormat, StatsAndEndOfStreamRoundTrip) {
  auto stats = std::make_shared<GraphStats>();
  stats->graph = "g";
  stats->nodes.push_back(NodeStats{"a", "test.counter", "p", 1, 2, 3, 4.5, 6.5, 7, 8, "done", ""});
  stats->nodes.push_back(
      NodeStats{"b", "source.aravis", "p", 0, 9, 1, 0, 0, 0, 0, "running", "reconnected (1)"});
  const Packet back = round_trip(Packet::of<GraphStats>(stats));
  EXPECT_EQ(static_cast<const GraphStats&>(*back.message).nodes, stats->nodes);
  EXPECT_TRUE(round_trip(Packet::end_of_stream(header(5))).is_end_of_stream());
  EXPECT_EQ(round_trip(Packet::end_of_stream(header(5))).header(), header(5));
}

TEST(WireFormat, HeaderLayoutIsWhatTheDocumentSays) {
  const std::vector<Frame> frames = wire::encode(Packet::end_of_stream(header(1)), 99);
  ASSERT_EQ(frames[0].size, wire::kHeaderBytes + 4);
  EXPECT_EQ(std::memcmp(frames[0].data, "MOCP", 4), 0);
  std::uint16_t version = 0;
  std::int64_t send_ns = 0;
  std::memcpy(&version, frames[0].data + 4, 2);
  std::memcpy(&send_ns, frames[0].data + 32, 8);
  EXPECT_EQ(version, wire::kVersion);
  EXPECT_EQ(send_ns, 99);
  EXPECT_EQ(std::memcmp(frames[0].data + 44, "cam0", 4), 0);
}

std::string rejection(const std::vector<Frame>& frames) {
  try {
    wire::decode(frames);
    return "";
  } catch (const WireError& e) {
    return e.what();
  }
}

std::vector<Frame> patched(std::vector<Frame> frames, std::size_t frame, std::size_t offset,
                           const void* bytes, std::size_t size) {
  auto copy = std::make_shared<std::vector<std::byte>>(frames[frame].data,
                                                       frames[frame].data + frames[frame].size);
  std::memcpy(copy->data() + offset, bytes, size);
  frames[frame] = {copy->data(), copy->size(), copy};
  return frames;
}

TEST(WireFormat, MalformedMessagesAreRejectedWithAReason) {
  const auto valid = as_received(wire::encode(Packet::of<People2D>(people_2d()), 0));
  EXPECT_NE(rejection({}).find("empty"), std::string::npos);
  // 1: People3D had no placement frame; 2: messages did not say their camera.
  for (const std::uint16_t version : {1, 2, 4}) {
    const std::string reason = rejection(patched(valid, 0, 4, &version, 2));
    EXPECT_NE(reason.find("version " + std::to_string(version) + " is not supported"),
              std::string::npos)
        << reason;
    EXPECT_EQ(reason.find("update it") != std::string::npos, version < wire::kVersion) << reason;
  }
  EXPECT_NE(rejection(patched(valid, 0, 0, "XXXX", 4)).find("bad magic"), std::string::npos);
  const std::uint16_t type = 77;
  EXPECT_NE(rejection(patched(valid, 0, 6, &type, 2)).find("unknown message type"),
            std::string::npos);
  // A person count that the frames cannot hold is refused before anything is allocated.
  const std::uint32_t people = 4'000'000'000u;
  EXPECT_NE(rejection(patched(valid, 1, 4, &people, 4)).find("beyond the limits"),
            std::string::npos);
  const std::uint32_t some_people = 100;
  EXPECT_NE(rejection(patched(valid, 1, 4, &some_people, 4)).find("bytes, expected"),
            std::string::npos);
  auto missing = valid;
  missing.pop_back();
  EXPECT_NE(rejection(missing).find("payload frames"), std::string::npos);
  auto extra = valid;
  extra.push_back(valid[1]);
  EXPECT_NE(rejection(extra).find("payload frames"), std::string::npos);
  // Every truncation of every frame.
  for (std::size_t f = 0; f < valid.size(); ++f) {
    for (std::size_t size = 0; size < valid[f].size; ++size) {
      auto cut = valid;
      cut[f].size = size;
      EXPECT_NE(rejection(cut), "") << "frame " << f << " cut to " << size;
    }
  }
  // Lying image geometry.
  const auto frame = as_received(wire::encode(Packet::of<VideoFrame>(video_frame()), 0));
  const std::uint32_t huge = 1'000'000;
  EXPECT_NE(rejection(patched(frame, 1, 0, &huge, 4)).find("VideoFrame"), std::string::npos);
  const std::uint32_t narrow_stride = 10;
  EXPECT_NE(rejection(patched(frame, 1, 8, &narrow_stride, 4)).find("stride"), std::string::npos);
  const std::uint8_t format = 9;
  EXPECT_NE(rejection(patched(frame, 1, 12, &format, 1)).find("pixel format"), std::string::npos);
  // Camera names: a length the frame cannot hold, a control character.
  const std::uint16_t long_name = 300;
  EXPECT_NE(rejection(patched(frame, 1, 14, &long_name, 2)).find("camera name longer"),
            std::string::npos);
  EXPECT_NE(rejection(patched(frame, 1, 16, "\n", 1)).find("control character"), std::string::npos);
  const auto people3d = as_received(wire::encode(Packet::of<People3D>(people_3d()), 0));
  const std::uint8_t kind = 7;
  EXPECT_NE(rejection(patched(people3d, 1, 4, &kind, 1)).find("unknown frame kind"),
            std::string::npos);
}

TEST(WireFormat, CameraNamesThatCannotTravelAreRefused) {
  auto m = people_2d();
  m->camera = "";
  EXPECT_THROW(wire::encode(Packet::of<People2D>(m), 0), WireError);
  m->camera = std::string(wire::kMaxCameraNameBytes + 1, 'c');
  EXPECT_THROW(wire::encode(Packet::of<People2D>(m), 0), WireError);
  m->camera = std::string(wire::kMaxCameraNameBytes, 'c');
  EXPECT_NO_THROW(wire::encode(Packet::of<People2D>(m), 0));
  auto p = people_3d();
  p->frame = {CoordinateFrame::Kind::world, "cam_01"};
  EXPECT_THROW(wire::encode(Packet::of<People3D>(p), 0), WireError);
}

TEST(WireFormat, RandomBytesNeverCrashTheDecoder) {
  std::mt19937 random(12345);
  const auto valid = as_received(wire::encode(Packet::of<People3D>(people_3d()), 0));
  std::size_t rejected = 0;
  for (int round = 0; round < 20000; ++round) {
    std::vector<Frame> frames;
    if (round % 2 == 0) {
      // Random frames of random sizes, sometimes starting with a valid header.
      const std::size_t count = 1 + random() % 6;
      for (std::size_t f = 0; f < count; ++f) {
        auto bytes = std::make_shared<std::vector<std::byte>>(random() % 200);
        for (auto& b : *bytes) b = static_cast<std::byte>(random());
        if (f == 0 && round % 4 == 0 && bytes->size() >= valid[0].size) {
          std::memcpy(bytes->data(), valid[0].data, valid[0].size);
        }
        frames.push_back({bytes->data(), bytes->size(), bytes});
      }
    } else {
      // A valid message with a few bytes flipped.
      frames = valid;
      for (int flips = 0; flips < 3; ++flips) {
        const std::size_t f = random() % frames.size();
        if (frames[f].size == 0) continue;
        const auto value = static_cast<std::uint8_t>(random());
        frames = patched(frames, f, random() % frames[f].size, &value, 1);
      }
    }
    try {
      wire::decode(frames);
    } catch (const WireError&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 10000u);
}

TEST(WireFormat, UnencodableMessagesAreRefused) {
  auto m = people_2d();
  m->people[1].joints.pop_back();
  EXPECT_THROW(wire::encode(Packet::of<People2D>(m), 0), WireError);
}

}  // namespace
}  // namespace mocap::graph
