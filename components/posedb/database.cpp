#include "posedb/database.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <exception>

#include "core/input_error.hpp"
#include "posedb/database_format.hpp"

namespace mocap::posedb {

std::string_view body_choice_name(BodyChoice b) {
  return b == BodyChoice::canonical ? "canonical" : "source";
}

bool parse_body_choice(std::string_view text, BodyChoice& out) {
  if (text == "canonical") return out = BodyChoice::canonical, true;
  if (text == "source") return out = BodyChoice::source, true;
  return false;
}
namespace {

// The bytes of a whole file: a read-only mapping of it, or a copy in memory.
class MappedFile {
 public:
  struct InMemory {};
  MappedFile(InMemory, std::string bytes) : copy_(std::move(bytes)) {
    // std::string's buffer comes from operator new: aligned for every record type.
    data_ = copy_.empty() ? nullptr : reinterpret_cast<const std::byte*>(copy_.data());
    size_ = copy_.size();
  }
  explicit MappedFile(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd);
      throw InputError(path, "not a regular file");
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
    if (size_ > 0) {
      void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
      if (p == MAP_FAILED) {
        const int err = errno;
        ::close(fd);
        throw InputError(path, std::string("cannot map: ") + std::strerror(err));
      }
      data_ = static_cast<const std::byte*>(p);
    }
    ::close(fd);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile() {
    if (data_ && copy_.empty()) ::munmap(const_cast<std::byte*>(data_), size_);
  }
  const std::byte* data() const { return data_; }
  std::uint64_t size() const { return size_; }

 private:
  std::string copy_;
  const std::byte* data_ = nullptr;
  std::uint64_t size_ = 0;
};

struct Section {
  const std::byte* data = nullptr;
  std::uint64_t size = 0;
  std::uint64_t count = 0;
  template <typename T>
  const T* as() const {
    return reinterpret_cast<const T*>(data);
  }
};

}  // namespace

struct Database::Impl {
  std::string path;
  MappedFile file;
  BuildInfo build;
  std::vector<ClipInfo> clips;
  std::vector<View> views;
  Section frames, joints, rotations, projections, records, centroids, clusters;

  explicit Impl(const std::string& p) : path(p), file(p) {}
  Impl(std::string bytes, const std::string& name)
      : path(name), file(MappedFile::InMemory{}, std::move(bytes)) {}
  [[noreturn]] void fail(const std::string& what) const { throw InputError(path, what); }

  void load(bool verify);
  Section section(const format::SectionEntry* table, std::uint32_t count, const char* name,
                  std::uint32_t element_size, bool verify) const;
  void check_consistency() const;
};

Section Database::Impl::section(const format::SectionEntry* table, std::uint32_t count,
                                const char* name, std::uint32_t element_size, bool verify) const {
  const auto wanted = format::tag(name);
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto& e = table[i];
    if (e.tag != wanted) continue;
    if (e.offset % format::kAlignment != 0 || e.offset > file.size() ||
        e.size > file.size() - e.offset) {
      fail(std::string("section '") + name + "' lies outside the file: truncated or corrupted");
    }
    if (e.element_size != element_size || e.size % element_size != 0) {
      fail(std::string("section '") + name +
           "' has records of an unexpected size: corrupted or foreign file");
    }
    if (verify && format::crc32_of(file.data() + e.offset, e.size) != e.crc) {
      fail(std::string("checksum mismatch in section '") + name +
           "': the file is corrupted; rebuild it with 'mocap db build'");
    }
    return {file.data() + e.offset, e.size, e.size / element_size};
  }
  fail(std::string("section '") + name + "' is missing: corrupted or foreign file");
}

void Database::Impl::load(bool verify) {
  if (file.size() < sizeof(format::FileHeader))
    fail("too small to be a pose database (" + std::to_string(file.size()) + " bytes)");
  format::FileHeader h;
  std::memcpy(&h, file.data(), sizeof h);
  if (h.magic != format::kMagic) fail("not a mocap pose database (wrong magic bytes)");
  if (h.byte_order != format::kByteOrderMark) fail("written on a machine of another byte order");
  if (h.version > kDatabaseVersion) {
    fail("database version " + std::to_string(h.version) + " is newer than this program reads (" +
         std::to_string(kDatabaseVersion) + "); update mocap");
  }
  if (h.version < 1) fail("invalid database version 0");
  if (h.file_size != file.size()) {
    fail("truncated or extended: the header says " + std::to_string(h.file_size) +
         " bytes, the file has " + std::to_string(file.size()));
  }
  const std::uint64_t table_bytes =
      static_cast<std::uint64_t>(h.section_count) * sizeof(format::SectionEntry);
  if (h.section_count > 64 || sizeof h + table_bytes > file.size()) fail("corrupted section table");
  const auto* table = reinterpret_cast<const format::SectionEntry*>(file.data() + sizeof h);
  if (format::crc32_of(table, table_bytes) != h.table_crc)
    fail("checksum mismatch in the section table: the file is corrupted");

  const Section options = section(table, h.section_count, format::kOptions, 1, verify);
  const Section clip_text = section(table, h.section_count, format::kClips, 1, verify);
  try {
    build = format::build_info_from_json(std::string(options.as<char>(), options.size));
    clips = format::clips_from_json(std::string(clip_text.as<char>(), clip_text.size));
  } catch (const std::exception& e) {
    fail(std::string("corrupted header data: ") + e.what());
  }
  const Section view_section =
      section(table, h.section_count, format::kViews, 4 * sizeof(float), verify);
  for (std::uint64_t i = 0; i < view_section.count; ++i) {
    const float* v = view_section.as<float>() + 4 * i;
    views.push_back({v[0], v[1], v[2], v[3]});
  }
  frames = section(table, h.section_count, format::kFrames, sizeof(FrameRecord), verify);
  joints =
      section(table, h.section_count, format::kJoints, kBodyJoints * 3 * sizeof(float), verify);
  rotations = section(table, h.section_count, format::kRotations, 4 * sizeof(float), verify);
  projections =
      section(table, h.section_count, format::kProjections, kPoseDims * sizeof(float), verify);
  records =
      section(table, h.section_count, format::kProjectionRecords, sizeof(ProjectionRecord), verify);
  centroids =
      section(table, h.section_count, format::kCentroids, kPoseDims * sizeof(float), verify);
  clusters = section(table, h.section_count, format::kClusters, sizeof(std::uint32_t), verify);
  check_consistency();
}

// Every index the readers follow is checked once here, so no accessor can run out of bounds.
void Database::Impl::check_consistency() const {
  if (joints.count != frames.count) fail("frame and joint tables disagree: corrupted");
  if (records.count != projections.count) fail("projection tables disagree: corrupted");
  if (clusters.count != centroids.count + 1) fail("cluster tables disagree: corrupted");
  const auto* begin = clusters.as<std::uint32_t>();
  if (begin[0] != 0 || begin[clusters.count - 1] != projections.count)
    fail("cluster offsets do not cover the projections: corrupted");
  for (std::uint64_t c = 1; c < clusters.count; ++c) {
    if (begin[c] < begin[c - 1]) fail("cluster offsets are not ordered: corrupted");
  }
  for (std::uint64_t i = 0; i < records.count; ++i) {
    const auto& r = records.as<ProjectionRecord>()[i];
    if (r.frame >= frames.count || r.view >= views.size())
      fail("projection " + std::to_string(i) + " points outside the tables: corrupted");
  }
  for (std::size_t c = 0; c < clips.size(); ++c) {
    const ClipInfo& clip = clips[c];
    const std::uint64_t quats =
        static_cast<std::uint64_t>(clip.frame_count) * clip.skeleton.joint_count();
    if (static_cast<std::uint64_t>(clip.first_frame) + clip.frame_count > frames.count ||
        clip.rotation_offset > rotations.count || quats > rotations.count - clip.rotation_offset) {
      fail("clip '" + clip.name + "' points outside the tables: corrupted");
    }
  }
  for (std::uint64_t f = 0; f < frames.count; ++f) {
    const auto& r = frames.as<FrameRecord>()[f];
    if (r.clip >= clips.size() || r.clip_frame >= clips[r.clip].frame_count)
      fail("frame " + std::to_string(f) + " points outside its clip: corrupted");
  }
}

Database Database::open(const std::string& path, bool verify_checksums) {
  auto impl = std::make_unique<Impl>(path);
  impl->load(verify_checksums);
  return Database(std::move(impl));
}

Database Database::from_bytes(std::string bytes, const std::string& name, bool verify_checksums) {
  auto impl = std::make_unique<Impl>(std::move(bytes), name);
  impl->load(verify_checksums);
  return Database(std::move(impl));
}

Database::Database(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Database::Database(Database&&) noexcept = default;
Database& Database::operator=(Database&&) noexcept = default;
Database::~Database() = default;

const std::string& Database::path() const { return impl_->path; }
std::uint64_t Database::file_size() const { return impl_->file.size(); }
const BuildInfo& Database::build_info() const { return impl_->build; }
const std::vector<ClipInfo>& Database::clips() const { return impl_->clips; }
std::span<const View> Database::views() const { return impl_->views; }
std::span<const FrameRecord> Database::frames() const {
  return {impl_->frames.as<FrameRecord>(), impl_->frames.count};
}
std::span<const float, kBodyJoints * 3> Database::joints(std::uint32_t frame) const {
  return std::span<const float, kBodyJoints * 3>(
      impl_->joints.as<float>() + static_cast<std::size_t>(frame) * kBodyJoints * 3,
      kBodyJoints * 3);
}
std::span<const float> Database::rotations(std::uint32_t frame) const {
  const FrameRecord& r = frames()[frame];
  const ClipInfo& clip = impl_->clips[r.clip];
  const std::size_t n = static_cast<std::size_t>(clip.skeleton.joint_count());
  return {impl_->rotations.as<float>() + 4 * (clip.rotation_offset + r.clip_frame * n), 4 * n};
}
MatrixView Database::projections() const {
  return {impl_->projections.as<float>(), impl_->projections.count, kPoseDims};
}
std::span<const ProjectionRecord> Database::projection_records() const {
  return {impl_->records.as<ProjectionRecord>(), impl_->records.count};
}
MatrixView Database::centroids() const {
  return {impl_->centroids.as<float>(), impl_->centroids.count, kPoseDims};
}
std::span<const std::uint32_t> Database::cluster_begin() const {
  return {impl_->clusters.as<std::uint32_t>(), impl_->clusters.count};
}
std::string Database::options_json() const { return format::build_info_to_json(impl_->build); }

}  // namespace mocap::posedb
