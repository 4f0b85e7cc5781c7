// Fuzz target: the ZeroMQ wire-format decoder (graph/wire_format.hpp decode), i.e. bytes from the
// network. The input is cut into message frames: each frame is a 4-byte little-endian length and
// that many bytes; the rest of the input, if any, is one more frame. A message that decodes must
// encode again and decode to the same type and counts.

#include <algorithm>
#include <cstring>
#include <memory>
#include <vector>

#include "fuzz_support.hpp"
#include "graph/wire_format.hpp"

namespace {

std::vector<mocap::graph::wire::Frame> frames_of(const std::uint8_t* data, std::size_t size,
                                                 const std::shared_ptr<const void>& owner) {
  std::vector<mocap::graph::wire::Frame> frames;
  std::size_t at = 0;
  while (at < size && frames.size() < 16) {
    if (size - at < 4) {
      frames.push_back({reinterpret_cast<const std::byte*>(data + at), size - at, owner});
      break;
    }
    std::uint32_t length = 0;
    std::memcpy(&length, data + at, 4);
    at += 4;
    const std::size_t n = std::min<std::size_t>(length, size - at);
    frames.push_back({reinterpret_cast<const std::byte*>(data + at), n, owner});
    at += n;
  }
  return frames;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap::graph;
  // The frames point into a copy owned like a received ZeroMQ message (image pixels keep it).
  auto copy = std::make_shared<std::vector<std::uint8_t>>(data, data + size);
  const std::vector<wire::Frame> frames = frames_of(copy->data(), copy->size(), copy);
  wire::Decoded decoded;
  try {
    decoded = wire::decode(frames);
  } catch (const wire::WireError&) {
    return 0;
  }
  std::vector<wire::Frame> again;
  try {
    again = wire::encode(decoded.packet, decoded.send_ns);
  } catch (const wire::WireError& e) {
    mocap::fuzz::fail(std::string("a decoded message does not encode: ") + e.what());
  }
  try {
    const wire::Decoded twice = wire::decode(again);
    mocap::fuzz::check(twice.packet.type == decoded.packet.type &&
                           twice.send_ns == decoded.send_ns &&
                           twice.packet.header().seq == decoded.packet.header().seq,
                       "a re-encoded message decodes differently");
  } catch (const wire::WireError& e) {
    mocap::fuzz::fail(std::string("a re-encoded message does not decode: ") + e.what());
  }
  return 0;
}
