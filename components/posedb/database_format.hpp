#pragma once
// The on-disk layout shared by the database reader and writer (documented in
// docs/pose-database.md). Little-endian; every section 64-byte aligned with its own CRC-32.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "posedb/database.hpp"

namespace mocap::posedb::format {

inline constexpr std::array<char, 8> kMagic = {'M', 'O', 'C', 'A', 'P', 'D', 'B', '\x1a'};
inline constexpr std::uint32_t kByteOrderMark = 0x01020304;
inline constexpr std::uint64_t kAlignment = 64;

struct FileHeader {
  std::array<char, 8> magic;
  std::uint32_t version;
  std::uint32_t byte_order;  // kByteOrderMark as written by the machine that built the file
  std::uint64_t file_size;
  std::uint32_t section_count;
  std::uint32_t table_crc;  // CRC-32 of the section table
};
static_assert(sizeof(FileHeader) == 32);

struct SectionEntry {
  std::array<char, 8> tag;
  std::uint64_t offset;
  std::uint64_t size;
  std::uint32_t crc;
  std::uint32_t element_size;
};
static_assert(sizeof(SectionEntry) == 32);

// Section tags, in file order.
inline constexpr char kOptions[] = "OPTIONS";
inline constexpr char kClips[] = "CLIPS";
inline constexpr char kViews[] = "VIEWS";
inline constexpr char kFrames[] = "FRAMES";
inline constexpr char kJoints[] = "JOINTS";
inline constexpr char kRotations[] = "ROTATION";
inline constexpr char kProjections[] = "PROJ";
inline constexpr char kProjectionRecords[] = "PROJMETA";
inline constexpr char kCentroids[] = "CENTROID";
inline constexpr char kClusters[] = "CLUSTERS";

std::array<char, 8> tag(const char* name);
std::uint32_t crc32_of(const void* data, std::uint64_t size);

std::string build_info_to_json(const BuildInfo& info);
// Throws std::runtime_error with a short reason; the caller adds the file name.
BuildInfo build_info_from_json(const std::string& text);
std::string clips_to_json(const std::vector<ClipInfo>& clips);
std::vector<ClipInfo> clips_from_json(const std::string& text);

}  // namespace mocap::posedb::format
