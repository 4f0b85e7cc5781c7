#include "io/read_file.hpp"

#include <fstream>
#include <system_error>

#include "core/input_error.hpp"

namespace mocap::io {

std::string read_whole_file(const std::filesystem::path& file, std::uintmax_t max_bytes) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    throw InputError(name, ec ? "cannot open: " + ec.message() : "not a regular file");
  }
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(name, "cannot read the size: " + ec.message());
  if (size > max_bytes) {
    throw InputError(name, std::to_string(size) + " bytes; the limit for this kind of file is " +
                               std::to_string(max_bytes));
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(name, "cannot open for reading");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (in.gcount() != static_cast<std::streamsize>(size)) {
    throw InputError(name, "read " + std::to_string(in.gcount()) + " of " + std::to_string(size) +
                               " bytes (file changed or unreadable)");
  }
  return bytes;
}

}  // namespace mocap::io
