#pragma once
// Just enough of the ZIP format for NumPy's .npz files: the central directory (with ZIP64
// sizes), members stored or deflated, CRC-32 checked. Every size and offset is checked against
// the archive and the limits before anything is allocated, so a damaged or hostile archive
// gives an InputError, never a crash, a huge allocation or a hang.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::io {

struct ZipLimits {
  std::uint64_t max_archive_bytes = 2ull << 30;
  std::uint64_t max_member_bytes = 1ull << 30;  // uncompressed size of one member
  std::uint32_t max_members = 100'000;
};

struct ZipMember {
  std::string name;
  std::uint16_t method = 0;  // 0 stored, 8 deflate
  std::uint32_t crc32 = 0;
  std::uint64_t compressed_size = 0;
  std::uint64_t size = 0;  // uncompressed
  std::uint64_t local_header_offset = 0;
};

class ZipArchive {
 public:
  // Reads the whole archive into memory and parses its central directory.
  static ZipArchive open(const std::filesystem::path& file, const ZipLimits& limits = {});
  // The same from bytes in memory; `source` names them in messages.
  static ZipArchive from_bytes(std::string bytes, std::string source, const ZipLimits& limits = {});

  const std::vector<ZipMember>& members() const { return members_; }
  const ZipMember* find(std::string_view name) const;
  // The uncompressed bytes of a member, CRC-checked.
  std::string extract(const ZipMember& member) const;
  const std::string& source() const { return source_; }

 private:
  ZipArchive(std::string bytes, std::string source, const ZipLimits& limits);
  void read_central_directory();

  std::string bytes_;
  std::string source_;
  ZipLimits limits_;
  std::vector<ZipMember> members_;
};

}  // namespace mocap::io
