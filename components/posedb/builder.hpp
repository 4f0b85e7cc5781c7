#pragma once
// Builds the pose database from mocap files: read, map to the 15-joint body, resample, turn each
// frame to face +Z, project through every virtual camera, normalise, cluster. Motion that has
// joint positions only (no skeleton, e.g. HumanEva-I) enters at the mapped-body step.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "posedb/database_writer.hpp"

namespace mocap::posedb {

struct BuildOptions {
  double fps = 24.0;
  ViewSetOptions views;
  Scaling scaling = Scaling::bbox_height;
  // source: every clip on its own skeleton's proportions; canonical: every frame's 15 joints
  // rescaled to the canonical body (motion/canonical_body.hpp) before facing and projection.
  // The source rotations are kept either way. `mocap db build` defaults to canonical.
  BodyChoice body = BodyChoice::source;
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

// The files a folder's splits.txt ("train 01_01.bvh" lines) assigns to `split`, as paths in the
// folder, in the list's order. Throws InputError naming the folder when it has no splits.txt.
std::vector<std::string> split_files(const std::string& folder, const std::string& split);

// Builds the database contents. Files that cannot be read are skipped and listed in `report`;
// throws InputError when no file at all could be used.
DatabaseContents build_database(const std::vector<std::string>& files, const BuildOptions& options,
                                const BuildProgress& progress, BuildReport& report);

// Motion known only as the 15 body joints' positions, already mapped from its source.
struct BodySequence {
  std::string name;     // unique among the sequences, e.g. "Train/S1 Walking 1 chunk0"
  std::string source;   // file or data set it came from
  std::string family;   // e.g. "humaneva"
  std::string mapping;  // how the body joints were made from the source's joints
  double fps = 0.0;     // source frame rate
  std::vector<std::array<glm::vec3, kBodyJoints>> frames;  // world, metres, y up
};

// Builds the database contents from position-only motion: resampled to options.fps by linear
// interpolation of the positions, then faced, projected and clustered exactly as mocap files.
// Its clips have an empty skeleton and no rotations. A sequence with no frames, no frame rate or
// a non-finite position is skipped and listed in `report`; throws InputError when none is usable.
DatabaseContents build_database_from_bodies(const std::vector<BodySequence>& sequences,
                                            const BuildOptions& options,
                                            const BuildProgress& progress, BuildReport& report);

}  // namespace mocap::posedb
