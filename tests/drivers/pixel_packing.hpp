#pragma once
// Camera buffers of more than 8 bits per pixel, written the way cameras write them (for tests):
// unpacked little-endian 16-bit words, GigE Vision "Packed" (two pixels in three bytes, the high
// 8 bits whole) and PFNC "p" (one little-endian bit stream).

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mocap::test {

inline std::vector<std::byte> pack_words(const std::vector<std::uint16_t>& values) {
  std::vector<std::byte> out;
  for (const std::uint16_t v : values) {
    out.push_back(static_cast<std::byte>(v & 0xff));
    out.push_back(static_cast<std::byte>(v >> 8));
  }
  return out;
}

// Mono10Packed / Mono12Packed: byte 0 = first pixel's bits [bits-1 .. bits-8], byte 2 = the
// second's; byte 1 = the first pixel's low bits in its low nibble, the second's in its high nibble.
inline std::vector<std::byte> pack_gige(const std::vector<std::uint16_t>& values, int bits) {
  const int low = bits - 8;
  std::vector<std::byte> out;
  for (std::size_t i = 0; i < values.size(); i += 2) {
    const unsigned a = values[i], b = i + 1 < values.size() ? values[i + 1] : 0u;
    const unsigned mask = (1u << low) - 1u;
    out.push_back(static_cast<std::byte>(a >> low));
    out.push_back(static_cast<std::byte>((a & mask) | (b & mask) << 4));
    out.push_back(static_cast<std::byte>(b >> low));
  }
  return out;
}

// Mono10p / Mono12p: value k occupies bits [k*bits, (k+1)*bits) of a little-endian bit stream.
inline std::vector<std::byte> pack_bit_stream(const std::vector<std::uint16_t>& values, int bits) {
  std::vector<std::byte> out((values.size() * static_cast<std::size_t>(bits) + 7) / 8);
  for (std::size_t k = 0; k < values.size(); ++k) {
    for (int b = 0; b < bits; ++b) {
      if ((values[k] >> b) & 1u) {
        const std::size_t bit = k * static_cast<std::size_t>(bits) + static_cast<std::size_t>(b);
        out[bit / 8] |= static_cast<std::byte>(1u << (bit % 8));
      }
    }
  }
  return out;
}

}  // namespace mocap::test
