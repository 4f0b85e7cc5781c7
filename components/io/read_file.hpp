#pragma once
// Reading a whole input file into memory with its size checked first, so that a wrong path to a
// huge file fails with a clear message instead of exhausting memory.

#include <cstdint>
#include <filesystem>
#include <string>

namespace mocap::io {

// Throws InputError (naming the file) if it is missing, not a regular file, larger than
// `max_bytes` or cannot be read completely.
std::string read_whole_file(const std::filesystem::path& file, std::uintmax_t max_bytes);

}  // namespace mocap::io
