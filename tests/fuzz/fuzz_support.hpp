#pragma once
// Helpers shared by the fuzz targets (tests/fuzz/*.cpp; docs/fuzzing.md). A target feeds the
// bytes to one reader and lets only the reader's documented error type pass: anything else
// (another exception, a crash, a sanitizer report, a broken invariant) stops the fuzzer.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

namespace mocap::fuzz {

inline std::string_view text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Stops the run with a message: a broken invariant is a finding like a crash.
[[noreturn]] inline void fail(std::string_view what) {
  std::fprintf(stderr, "fuzz target: %.*s\n", static_cast<int>(what.size()), what.data());
  std::abort();
}

inline void check(bool ok, std::string_view what) {
  if (!ok) fail(what);
}

// Readers' errors name the input: an error message without `name` is a finding.
inline void expect_named(const std::exception& e, std::string_view name) {
  if (std::string_view(e.what()).find(name) == std::string_view::npos)
    fail(std::string("error message does not name the input: ") + e.what());
}

// Splits `input` at the first occurrence of `separator` (for targets that read two files).
inline bool split(std::string_view input, std::string_view separator, std::string_view& first,
                  std::string_view& second) {
  const std::size_t at = input.find(separator);
  if (at == std::string_view::npos) return false;
  first = input.substr(0, at);
  second = input.substr(at + separator.size());
  return true;
}

}  // namespace mocap::fuzz
