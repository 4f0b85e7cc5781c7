#pragma once
// The pose database: every mocap frame's 3D body and source rotations, and its normalised 2D
// projections from many virtual cameras, with a cluster index. Read-only and memory-mapped: the
// matcher reads the projection rows straight from the page cache. File layout:
// docs/pose-database.md.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "motion/skeleton.hpp"
#include "posedb/normalization.hpp"
#include "posedb/search.hpp"
#include "posedb/view_set.hpp"

namespace mocap::posedb {

inline constexpr std::uint32_t kDatabaseVersion = 1;

// One database frame (a mocap frame after resampling).
struct FrameRecord {
  std::uint32_t clip;
  std::uint32_t clip_frame;  // index within the clip at the database frame rate
  float heading_rad;         // the body's facing (yaw about +Y) that was removed; 0 = facing +Z
  float root_m[3];           // root (mid-hips) position in the mocap world, metres
};
static_assert(sizeof(FrameRecord) == 24);

struct ProjectionRecord {
  std::uint32_t frame;  // index into frames()
  std::uint32_t view;   // index into views()
};
static_assert(sizeof(ProjectionRecord) == 8);

struct ClipInfo {
  std::string name;     // file name without folder
  std::string source;   // path as given at build time
  std::string family;   // cmu31, cmu_daz, bandai, generic, asf_amc
  std::string mapping;  // how the body joints were taken from the skeleton
  double source_fps = 0.0;
  std::uint32_t source_first_frame = 0;  // first source frame used (after reference/blank frames)
  std::uint32_t first_frame = 0;         // index of its first frame in frames()
  std::uint32_t frame_count = 0;
  std::uint64_t rotation_offset = 0;  // index of its first quaternion in rotations()
  float metres_per_unit = 1.0f;
  motion::Skeleton skeleton;  // source hierarchy, for BVH output
};

// Which body the database's joints and projections are on: the source skeletons' own
// proportions, or every clip rescaled to the canonical body (motion/canonical_body.hpp).
enum class BodyChoice { source, canonical };
std::string_view body_choice_name(BodyChoice b);
bool parse_body_choice(std::string_view text, BodyChoice& out);

struct BuildInfo {
  double fps = 24.0;
  Scaling scaling = Scaling::bbox_height;
  // Files written before the choice existed have no "body" entry: they are on the source body.
  BodyChoice body = BodyChoice::source;
  ViewSetOptions views;
  int clusters = 0;
  std::uint64_t seed = 0;
  std::string created;  // ISO time
  std::string command;  // command line that built it
  double build_seconds = 0.0;
};

class Database {
 public:
  // Maps and validates the file; throws InputError naming the file and the problem for a
  // missing, truncated, corrupted (checksum), foreign or newer-version file.
  static Database open(const std::string& path, bool verify_checksums = true);
  // The same checks on the bytes of a database file held in memory (copied in); `name` stands
  // for the file in messages.
  static Database from_bytes(std::string bytes, const std::string& name,
                             bool verify_checksums = true);

  Database(Database&&) noexcept;
  Database& operator=(Database&&) noexcept;
  ~Database();

  const std::string& path() const;
  std::uint64_t file_size() const;
  const BuildInfo& build_info() const;
  const std::vector<ClipInfo>& clips() const;
  std::span<const View> views() const;
  std::span<const FrameRecord> frames() const;
  // Root-relative body joints of a frame, metres, body turned to face +Z: 15 x (x, y, z).
  std::span<const float, kBodyJoints * 3> joints(std::uint32_t frame) const;
  // Local rotations of the clip's source skeleton: joint_count quaternions (w, x, y, z) per frame.
  std::span<const float> rotations(std::uint32_t frame) const;
  MatrixView projections() const;  // rows = projections, kPoseDims columns, sorted by cluster
  std::span<const ProjectionRecord> projection_records() const;
  MatrixView centroids() const;
  std::span<const std::uint32_t> cluster_begin() const;  // clusters + 1 offsets into projections
  std::string options_json() const;

 private:
  struct Impl;
  explicit Database(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::posedb
