#pragma once
// A cursor over bytes in memory that checks every read against the end and reads little-endian
// integers; running past the end throws InputError naming the source and the offset. The
// binary readers (ZIP, .npy, pickle) parse untrusted bytes only through it.

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>

#include "core/input_error.hpp"

namespace mocap::io {

class ByteReader {
 public:
  ByteReader(std::string_view bytes, std::string source, std::size_t position = 0)
      : bytes_(bytes), source_(std::move(source)), position_(position) {
    if (position_ > bytes_.size()) fail("offset " + std::to_string(position_) + " is past the end");
  }
  // A second cursor over the same bytes at `position`.
  ByteReader(const ByteReader& other, std::size_t position)
      : ByteReader(other.bytes_, other.source_, position) {}

  std::size_t position() const { return position_; }
  std::size_t remaining() const { return bytes_.size() - position_; }
  bool at_end() const { return position_ == bytes_.size(); }

  void seek(std::uint64_t position) {
    if (position > bytes_.size()) fail("offset " + std::to_string(position) + " is past the end");
    position_ = static_cast<std::size_t>(position);
  }
  // Converts an absolute offset read from the data into a checked position.
  std::size_t offset_from(std::uint64_t value) const {
    if (value > bytes_.size()) fail("offset " + std::to_string(value) + " is past the end");
    return static_cast<std::size_t>(value);
  }
  void skip(std::uint64_t n) { bytes(n); }

  std::string_view bytes(std::uint64_t n) {
    if (n > remaining()) {
      fail("needs " + std::to_string(n) + " bytes at offset " + std::to_string(position_) +
           ", only " + std::to_string(remaining()) + " left (truncated?)");
    }
    const std::string_view out = bytes_.substr(position_, static_cast<std::size_t>(n));
    position_ += static_cast<std::size_t>(n);
    return out;
  }
  std::uint8_t u8() { return static_cast<std::uint8_t>(bytes(1)[0]); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(little_endian(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(little_endian(4)); }
  std::uint64_t u64() { return little_endian(8); }
  std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
  double f64_big_endian() {
    const std::string_view b = bytes(8);
    std::uint64_t bits = 0;
    for (char c : b) bits = (bits << 8) | static_cast<std::uint8_t>(c);
    double value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(source_, "byte " + std::to_string(position_) + ": " + what);
  }

 private:
  std::uint64_t little_endian(int n) {
    const std::string_view b = bytes(static_cast<std::uint64_t>(n));
    std::uint64_t value = 0;
    for (int i = n - 1; i >= 0; --i) value = (value << 8) | static_cast<std::uint8_t>(b[i]);
    return value;
  }

  std::string_view bytes_;
  std::string source_;
  std::size_t position_ = 0;
};

}  // namespace mocap::io
