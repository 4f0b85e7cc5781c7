#pragma once
// The wire format between processes, version 3 (docs/wire-format.md): one message is a ZeroMQ
// multipart message made of a fixed header frame and type-specific payload frames; image pixels
// are a frame of their own so they are sent and received without a copy. This file knows
// nothing of ZeroMQ: frames are byte ranges with an owner that keeps them alive.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "graph/packet.hpp"

namespace mocap::graph::wire {

inline constexpr std::uint16_t kVersion = 3;
inline constexpr char kMagic[4] = {'M', 'O', 'C', 'P'};
inline constexpr std::size_t kHeaderBytes = 44;  // without the stream id
inline constexpr std::size_t kMaxFrames = 8;     // no message type has more payload frames

// Sent back by the consumer of an edge once its end of stream arrived (a one-frame message).
inline constexpr std::string_view kEndAcknowledgement = "MOCP-END-ACK";

enum class TypeCode : std::uint16_t {
  end_of_stream = 0,
  video_frame = 1,
  people_2d = 2,
  people_3d = 3,
  graph_stats = 4,
  pose_matches = 5,
};

// Limits checked before any allocation: bytes from a socket are untrusted.
inline constexpr std::size_t kMaxStreamIdBytes = 1024;
inline constexpr std::size_t kMaxCameraNameBytes = 256;
inline constexpr std::uint32_t kMaxPeople = 4096;
inline constexpr std::uint32_t kMaxJoints = 256;
inline constexpr std::uint32_t kMaxImageSide = 32768;
inline constexpr std::size_t kMaxStatsBytes = 1 << 20;
inline constexpr std::uint32_t kMaxCandidates = 4096;  // per person

struct Frame {
  const std::byte* data = nullptr;
  std::size_t size = 0;
  std::shared_ptr<const void> owner;  // keeps `data` alive

  std::span<const std::byte> bytes() const { return {data, size}; }
};

class WireError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws WireError for messages the format cannot carry (e.g. people with different joint counts).
std::vector<Frame> encode(const Packet& packet, std::int64_t send_ns);

struct Decoded {
  Packet packet;
  std::int64_t send_ns = 0;
};
// Throws WireError saying what is wrong: bad magic, unknown version or type, wrong frame count or
// size, counts beyond the limits. Image pixels keep pointing into their frame (no copy).
Decoded decode(std::span<const Frame> frames);

}  // namespace mocap::graph::wire
