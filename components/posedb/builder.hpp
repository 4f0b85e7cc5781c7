#pragma once
// Builds the pose database from mocap files: read, map to the 15-joint body, resample, turn each
// frame to face +Z, project through every virtual camera, normalise, cluster.

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "posedb/database_writer.hpp"

namespace mocap::posedb {

struct BuildOptions {
  double fps = 24.0;
  ViewSetOptions views;
  Scaling scaling = Scaling::bbox_height;
  int clusters = 0;  // 0: about sqrt(projections), at least 16
  int kmeans_iterations = 8;
  std::size_t kmeans_sample = 200'000;
  std::uint64_t seed = 1;
  int threads = 2;
  std::string command;  // recorded in the file
};

// Called as work proceeds; `stage` names the step ("read", "project", "cluster", ...).
using BuildProgress = std::function<void(std::string_view stage, double fraction)>;

struct BuildReport {
  std::size_t files_read = 0;
  std::vector<std::string> skipped;  // "path: reason" for every file that could not be used
  std::size_t reference_frames_dropped = 0;
  std::size_t blank_frames_dropped = 0;
  std::size_t projections_dropped = 0;  // could not be normalised
};

// Expands folders (recursively) into the motion files they hold: *.bvh, and *.amc with the
// matching *.asf (NN.asf for NN_TT.amc, or the only .asf in the folder). Sorted, no duplicates.
// Throws InputError for a path that does not exist.
std::vector<std::string> collect_motion_files(const std::vector<std::string>& paths);

// Builds the database contents. Files that cannot be read are skipped and listed in `report`;
// throws InputError when no file at all could be used.
DatabaseContents build_database(const std::vector<std::string>& files, const BuildOptions& options,
                                const BuildProgress& progress, BuildReport& report);

}  // namespace mocap::posedb
