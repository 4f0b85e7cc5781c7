#include "io/zip_archive.hpp"

#include <algorithm>
#include <limits>
#include <optional>

#include <zlib.h>

#include "core/input_error.hpp"
#include "io/byte_reader.hpp"
#include "io/read_file.hpp"

namespace mocap::io {
namespace {

constexpr std::uint32_t kEndOfCentralDirectory = 0x06054b50;
constexpr std::uint32_t kZip64EndOfCentralDirectory = 0x06064b50;
constexpr std::uint32_t kZip64Locator = 0x07064b50;
constexpr std::uint32_t kCentralHeader = 0x02014b50;
constexpr std::uint32_t kLocalHeader = 0x04034b50;
constexpr std::size_t kEndRecordBytes = 22;
constexpr std::size_t kLocatorBytes = 20;
constexpr std::size_t kCentralHeaderBytes = 46;
constexpr std::size_t kLocalHeaderBytes = 30;
constexpr std::uint16_t kZip64ExtraId = 0x0001;
constexpr std::uint32_t kSaturated32 = 0xffffffff;
constexpr std::uint64_t kMaxDeflateRatio = 1032;

struct Directory {
  std::uint64_t entries = 0;
  std::uint64_t size = 0;
  std::uint64_t offset = 0;
};

// The end record sits in the last 22 + 65535 (comment) bytes; search backwards for it.
std::size_t find_end_record(std::string_view bytes, const std::string& source) {
  if (bytes.size() < kEndRecordBytes) {
    throw InputError(source, "not a ZIP archive (" + std::to_string(bytes.size()) + " bytes)");
  }
  const std::size_t last = bytes.size() - kEndRecordBytes;
  const std::size_t first = last > 0xffff ? last - 0xffff : 0;
  for (std::size_t pos = last + 1; pos-- > first;) {
    if (ByteReader(bytes, source, pos).u32() == kEndOfCentralDirectory) return pos;
  }
  throw InputError(source, "not a ZIP archive (no end of central directory record)");
}

Directory read_zip64_directory(std::string_view bytes, const std::string& source,
                               std::size_t end_record) {
  if (end_record < kLocatorBytes) throw InputError(source, "ZIP64 locator missing");
  ByteReader locator(bytes, source, end_record - kLocatorBytes);
  if (locator.u32() != kZip64Locator) throw InputError(source, "ZIP64 locator missing");
  locator.skip(4);
  ByteReader record(bytes, source, locator.offset_from(locator.u64()));
  if (record.u32() != kZip64EndOfCentralDirectory) {
    throw InputError(source, "ZIP64 end of central directory record missing");
  }
  record.skip(8 + 2 + 2 + 4 + 4 + 8);  // record size, versions, disk numbers, entries on disk
  Directory d;
  d.entries = record.u64();
  d.size = record.u64();
  d.offset = record.u64();
  return d;
}

Directory read_directory_location(std::string_view bytes, const std::string& source) {
  const std::size_t end_record = find_end_record(bytes, source);
  ByteReader r(bytes, source, end_record + 4);
  const std::uint16_t disk = r.u16(), directory_disk = r.u16();
  r.skip(2);
  Directory d;
  d.entries = r.u16();
  d.size = r.u32();
  d.offset = r.u32();
  if (d.entries == 0xffff || d.size == kSaturated32 || d.offset == kSaturated32) {
    d = read_zip64_directory(bytes, source, end_record);
  } else if (disk != 0 || directory_disk != 0) {
    throw InputError(source, "multi-part ZIP archives are not supported");
  }
  if (d.offset > bytes.size() || d.size > bytes.size() - d.offset) {
    throw InputError(source, "central directory lies outside the archive");
  }
  return d;
}

// Replaces saturated 32-bit fields with the values of the ZIP64 extra field, in the order the
// format gives them: uncompressed size, compressed size, local header offset.
void apply_zip64_extra(ByteReader extra, std::size_t extra_end, ZipMember& m, bool size32_full,
                       bool compressed32_full, bool offset32_full) {
  while (extra.position() + 4 <= extra_end) {
    const std::uint16_t id = extra.u16(), length = extra.u16();
    if (extra.position() + length > extra_end) break;
    if (id != kZip64ExtraId) {
      extra.skip(length);
      continue;
    }
    const std::size_t field_end = extra.position() + length;
    if (size32_full && extra.position() + 8 <= field_end) m.size = extra.u64();
    if (compressed32_full && extra.position() + 8 <= field_end) m.compressed_size = extra.u64();
    if (offset32_full && extra.position() + 8 <= field_end) m.local_header_offset = extra.u64();
    return;
  }
}

ZipMember read_central_header(ByteReader& r) {
  if (r.u32() != kCentralHeader) r.fail("central directory entry has a bad signature");
  r.skip(2 + 2);  // versions
  const std::uint16_t flags = r.u16();
  ZipMember m;
  m.method = r.u16();
  r.skip(2 + 2);  // time, date
  m.crc32 = r.u32();
  const std::uint32_t compressed32 = r.u32(), size32 = r.u32();
  const std::uint16_t name_length = r.u16(), extra_length = r.u16(), comment_length = r.u16();
  r.skip(2 + 2 + 4);  // disk, attributes
  const std::uint32_t offset32 = r.u32();
  m.name = std::string(r.bytes(name_length));
  if (flags & 0x1) r.fail("member " + m.name + " is encrypted");
  m.compressed_size = compressed32;
  m.size = size32;
  m.local_header_offset = offset32;
  const std::size_t extra_begin = r.position();
  r.skip(extra_length);
  apply_zip64_extra(ByteReader(r, extra_begin), extra_begin + extra_length, m,
                    size32 == kSaturated32, compressed32 == kSaturated32, offset32 == kSaturated32);
  r.skip(comment_length);
  return m;
}

// RAII for a zlib inflate stream (raw deflate, as ZIP stores it).
class Inflater {
 public:
  explicit Inflater(const std::string& source) {
    if (inflateInit2(&stream_, -MAX_WBITS) != Z_OK) throw InputError(source, "zlib init failed");
  }
  ~Inflater() { inflateEnd(&stream_); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;
  z_stream& stream() { return stream_; }

 private:
  z_stream stream_{};
};

// zlib counts in uInt; feed and drain in pieces no larger than that.
uInt piece(std::size_t remaining) {
  return static_cast<uInt>(std::min<std::size_t>(remaining, std::numeric_limits<uInt>::max()));
}

std::string inflate_member(std::string_view input, std::uint64_t size, const std::string& where) {
  std::string out(static_cast<std::size_t>(size), '\0');
  Inflater inflater(where);
  z_stream& z = inflater.stream();
  std::size_t in_used = 0, out_used = 0;
  for (;;) {
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(input.data() + in_used));
    z.avail_in = piece(input.size() - in_used);
    z.next_out = reinterpret_cast<Bytef*>(out.data() + out_used);
    z.avail_out = piece(out.size() - out_used);
    const uInt in_before = z.avail_in, out_before = z.avail_out;
    const int status = inflate(&z, Z_NO_FLUSH);
    in_used += in_before - z.avail_in;
    out_used += out_before - z.avail_out;
    if (status == Z_STREAM_END) break;
    if (status == Z_NEED_DICT || status == Z_DATA_ERROR || status == Z_MEM_ERROR) {
      throw InputError(where,
                       std::string("corrupt deflate data: ") + (z.msg ? z.msg : "zlib error"));
    }
    // No progress: input exhausted (truncated) or output full (more data than declared).
    if (in_before == z.avail_in && out_before == z.avail_out) {
      throw InputError(where,
                       out_used == out.size()
                           ? "inflates to more than the declared " + std::to_string(size) + " bytes"
                           : "deflate data ends early (truncated archive?)");
    }
  }
  if (out_used != out.size()) {
    throw InputError(where, "inflates to " + std::to_string(out_used) + " bytes, declared " +
                                std::to_string(size));
  }
  return out;
}

std::uint32_t crc_of(std::string_view data) {
  uLong crc = crc32(0L, Z_NULL, 0);
  for (std::size_t done = 0; done < data.size();) {
    const uInt n = piece(data.size() - done);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(data.data() + done), n);
    done += n;
  }
  return static_cast<std::uint32_t>(crc);
}

}  // namespace

ZipArchive::ZipArchive(std::string bytes, std::string source, const ZipLimits& limits)
    : bytes_(std::move(bytes)), source_(std::move(source)), limits_(limits) {}

ZipArchive ZipArchive::open(const std::filesystem::path& file, const ZipLimits& limits) {
  return from_bytes(read_whole_file(file, limits.max_archive_bytes), file.string(), limits);
}

ZipArchive ZipArchive::from_bytes(std::string bytes, std::string source, const ZipLimits& limits) {
  if (bytes.size() > limits.max_archive_bytes) {
    throw InputError(source, "archive larger than the limit of " +
                                 std::to_string(limits.max_archive_bytes) + " bytes");
  }
  ZipArchive archive(std::move(bytes), std::move(source), limits);
  archive.read_central_directory();
  return archive;
}

void ZipArchive::read_central_directory() {
  const Directory d = read_directory_location(bytes_, source_);
  // Every entry takes at least 46 bytes, which bounds the count before anything is reserved.
  if (d.entries > d.size / kCentralHeaderBytes || d.entries > limits_.max_members) {
    throw InputError(source_, "central directory claims " + std::to_string(d.entries) +
                                  " members in " + std::to_string(d.size) + " bytes");
  }
  const std::string_view directory(bytes_.data() + d.offset, static_cast<std::size_t>(d.size));
  ByteReader r(directory, source_ + " (central directory)", 0);
  members_.reserve(static_cast<std::size_t>(d.entries));
  for (std::uint64_t i = 0; i < d.entries; ++i) members_.push_back(read_central_header(r));
}

const ZipMember* ZipArchive::find(std::string_view name) const {
  const auto it = std::find_if(members_.begin(), members_.end(),
                               [&](const ZipMember& m) { return m.name == name; });
  return it == members_.end() ? nullptr : &*it;
}

std::string ZipArchive::extract(const ZipMember& m) const {
  const std::string where = source_ + ": member " + m.name;
  if (m.size > limits_.max_member_bytes) {
    throw InputError(where, std::to_string(m.size) + " bytes uncompressed; the limit is " +
                                std::to_string(limits_.max_member_bytes));
  }
  ByteReader local(bytes_, where, 0);
  local.seek(m.local_header_offset);
  if (local.u32() != kLocalHeader) local.fail("local header has a bad signature");
  local.skip(22);  // versions, flags, method, time, date, crc, sizes (the directory's count)
  const std::uint16_t name_length = local.u16(), extra_length = local.u16();
  local.skip(std::size_t{name_length} + extra_length);
  const std::string_view data = local.bytes(m.compressed_size);
  std::string out;
  if (m.method == 0) {
    if (m.compressed_size != m.size) throw InputError(where, "stored member sizes differ");
    out.assign(data);
  } else if (m.method == 8) {
    // Deflate expands at most ~1032:1; a larger claim is damage, and is refused before the
    // output buffer is allocated.
    if (m.size / kMaxDeflateRatio > data.size() + 1) {
      throw InputError(where, "declares " + std::to_string(m.size) + " bytes from " +
                                  std::to_string(data.size()) +
                                  " compressed bytes, more than deflate can produce");
    }
    out = inflate_member(data, m.size, where);
  } else {
    throw InputError(where, "compression method " + std::to_string(m.method) +
                                " is not supported (only stored and deflate)");
  }
  if (crc_of(out) != m.crc32) throw InputError(where, "CRC-32 mismatch (damaged archive)");
  return out;
}

}  // namespace mocap::io
