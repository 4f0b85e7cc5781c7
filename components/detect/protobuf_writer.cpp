#include "detect/protobuf_writer.hpp"

#include <bit>
#include <cstring>

namespace mocap::detect {
namespace {

constexpr int kWireVarint = 0;
constexpr int kWireLengthDelimited = 2;
constexpr int kWireFixed32 = 5;

void append_fixed32(std::string& out, float value) {
  static_assert(std::endian::native == std::endian::little, "the wire format is little-endian");
  char raw[4];
  std::memcpy(raw, &value, sizeof raw);
  out.append(raw, sizeof raw);
}

}  // namespace

void ProtoMessage::append_varint(std::string& out, std::uint64_t value) {
  while (value >= 0x80) {
    out.push_back(static_cast<char>((value & 0x7f) | 0x80));
    value >>= 7;
  }
  out.push_back(static_cast<char>(value));
}

void ProtoMessage::add_tag(int field, int wire_type) {
  append_varint(bytes_,
                (static_cast<std::uint64_t>(field) << 3) | static_cast<unsigned>(wire_type));
}

void ProtoMessage::add_varint(int field, std::uint64_t value) {
  add_tag(field, kWireVarint);
  append_varint(bytes_, value);
}

void ProtoMessage::add_float(int field, float value) {
  add_tag(field, kWireFixed32);
  append_fixed32(bytes_, value);
}

void ProtoMessage::add_bytes(int field, std::string_view bytes) {
  add_tag(field, kWireLengthDelimited);
  append_varint(bytes_, bytes.size());
  bytes_.append(bytes);
}

void ProtoMessage::add_packed_int64(int field, std::span<const std::int64_t> values) {
  std::string packed;
  for (const std::int64_t v : values) append_varint(packed, static_cast<std::uint64_t>(v));
  add_bytes(field, packed);
}

void ProtoMessage::add_packed_float(int field, std::span<const float> values) {
  std::string packed;
  for (const float v : values) append_fixed32(packed, v);
  add_bytes(field, packed);
}

}  // namespace mocap::detect
