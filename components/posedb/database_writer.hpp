#pragma once
// Everything a pose database holds, in memory, and the function that writes it to a file.

#include <string>
#include <vector>

#include "posedb/database.hpp"

namespace mocap::posedb {

struct DatabaseContents {
  BuildInfo build;
  std::vector<ClipInfo> clips;
  std::vector<View> views;
  std::vector<FrameRecord> frames;
  std::vector<float> joints;       // frames * 15 * 3
  std::vector<float> rotations;    // quaternions * 4 (w, x, y, z)
  std::vector<float> projections;  // projections * kPoseDims, sorted by cluster
  std::vector<ProjectionRecord> projection_records;
  std::vector<float> centroids;              // clusters * kPoseDims
  std::vector<std::uint32_t> cluster_begin;  // clusters + 1
};

// Writes through a temporary file renamed into place; throws InputError naming the file when it
// cannot be written (no space, no permission).
void write_database(const DatabaseContents& contents, const std::string& path);

}  // namespace mocap::posedb
