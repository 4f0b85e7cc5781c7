#include "posedb/database_writer.hpp"

#include <filesystem>
#include <fstream>

#include "core/input_error.hpp"
#include "posedb/database_format.hpp"

namespace mocap::posedb {
namespace {

struct PendingSection {
  const char* tag;
  const void* data;
  std::uint64_t size;
  std::uint32_t element_size;
};

template <typename T>
PendingSection section(const char* tag, const std::vector<T>& v,
                       std::uint32_t element_size = sizeof(T)) {
  return {tag, v.data(), v.size() * sizeof(T), element_size};
}

std::uint64_t align_up(std::uint64_t n) {
  return (n + format::kAlignment - 1) / format::kAlignment * format::kAlignment;
}

}  // namespace

void write_database(const DatabaseContents& c, const std::string& path) {
  const std::string options = format::build_info_to_json(c.build);
  const std::string clips = format::clips_to_json(c.clips);
  std::vector<float> views;
  for (const View& v : c.views)
    views.insert(views.end(), {v.yaw_deg, v.height_m, v.distance_m, v.pitch_deg});
  const PendingSection pending[] = {
      {format::kOptions, options.data(), options.size(), 1},
      {format::kClips, clips.data(), clips.size(), 1},
      section(format::kViews, views, 4 * sizeof(float)),
      section(format::kFrames, c.frames),
      section(format::kJoints, c.joints, kBodyJoints * 3 * sizeof(float)),
      section(format::kRotations, c.rotations, 4 * sizeof(float)),
      section(format::kProjections, c.projections, kPoseDims * sizeof(float)),
      section(format::kProjectionRecords, c.projection_records),
      section(format::kCentroids, c.centroids, kPoseDims * sizeof(float)),
      section(format::kClusters, c.cluster_begin),
  };
  constexpr std::uint32_t count = std::size(pending);
  std::vector<format::SectionEntry> table;
  std::uint64_t offset =
      align_up(sizeof(format::FileHeader) + count * sizeof(format::SectionEntry));
  for (const auto& p : pending) {
    table.push_back(
        {format::tag(p.tag), offset, p.size, format::crc32_of(p.data, p.size), p.element_size});
    offset = align_up(offset + p.size);
  }
  format::FileHeader header{
      format::kMagic,
      kDatabaseVersion,
      format::kByteOrderMark,
      offset,
      count,
      format::crc32_of(table.data(), table.size() * sizeof(format::SectionEntry))};

  const std::string tmp = path + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, "cannot create the database file");
    out.write(reinterpret_cast<const char*>(&header), sizeof header);
    out.write(reinterpret_cast<const char*>(table.data()),
              static_cast<std::streamsize>(table.size() * sizeof(table[0])));
    static const char zeros[format::kAlignment] = {};
    std::uint64_t written = sizeof header + table.size() * sizeof(table[0]);
    for (size_t i = 0; i < count; ++i) {
      out.write(zeros, static_cast<std::streamsize>(table[i].offset - written));
      out.write(static_cast<const char*>(pending[i].data),
                static_cast<std::streamsize>(pending[i].size));
      written = table[i].offset + pending[i].size;
    }
    out.write(zeros, static_cast<std::streamsize>(offset - written));
    out.flush();
    if (!out) {
      std::filesystem::remove(tmp);
      throw InputError(path, "writing the database failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path, "cannot move the finished database into place: " + ec.message());
}

}  // namespace mocap::posedb
