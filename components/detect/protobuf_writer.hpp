#pragma once
// A minimal protocol-buffers encoder: just enough of the wire format (varints, length-delimited
// fields, fixed32 floats, packed repeats) to write a TensorFlow GraphDef for OpenCV's importer
// without depending on libprotobuf or TensorFlow's .proto files.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace mocap::detect {

class ProtoMessage {
 public:
  void add_varint(int field, std::uint64_t value);
  // int64 fields: negative values are written as their 10-byte two's complement, as protobuf does.
  void add_int64(int field, std::int64_t value) {
    add_varint(field, static_cast<std::uint64_t>(value));
  }
  void add_float(int field, float value);
  void add_bytes(int field, std::string_view bytes);
  void add_message(int field, const ProtoMessage& message) { add_bytes(field, message.bytes_); }
  void add_packed_int64(int field, std::span<const std::int64_t> values);
  void add_packed_float(int field, std::span<const float> values);

  const std::string& bytes() const { return bytes_; }

 private:
  void add_tag(int field, int wire_type);
  static void append_varint(std::string& out, std::uint64_t value);

  std::string bytes_;
};

}  // namespace mocap::detect
