#pragma once
// A small pose database built in a test from a few clips of ../shared/data/mocap: two CMU clips
// (cgspeed, 31 joints) and, for a second skeleton, one Bandai clip. Built once per test program.

#include <memory>
#include <string>
#include <vector>

#include "posedb/builder.hpp"
#include "support/shared_data.hpp"

namespace mocap::test {

// The clips, relative to ../shared/data/mocap; the Bandai one last.
inline const std::vector<std::string>& small_database_clips() {
  static const std::vector<std::string> clips = {"cmu31/08_01.bvh", "cmu31/09_10.bvh",
                                                 "bandai/dataset-1/dataset-1_bow_normal_001.bvh"};
  return clips;
}

// Builds the database file once; returns its path, or "" when the shared data is absent.
inline std::string small_pose_database() {
  static std::unique_ptr<TempDir> dir;
  static std::string path;
  if (!path.empty()) return path;
  std::vector<std::string> files;
  for (const std::string& clip : small_database_clips()) {
    const auto file = shared_data() / "mocap" / clip;
    if (!std::filesystem::exists(file)) return "";
    files.push_back(file.string());
  }
  posedb::BuildOptions options;
  options.views.yaw_steps = 12;
  options.clusters = 16;
  posedb::BuildReport report;
  const posedb::DatabaseContents contents = posedb::build_database(files, options, {}, report);
  dir = std::make_unique<TempDir>();
  path = dir->file("small.mdb");
  posedb::write_database(contents, path);
  return path;
}

#define MOCAP_REQUIRE_SMALL_DATABASE(path_variable)                                          \
  const std::string path_variable = ::mocap::test::small_pose_database();                    \
  if (path_variable.empty()) {                                                               \
    GTEST_SKIP() << "shared mocap clips absent (../shared/data/mocap/cmu31 and bandai): no " \
                    "test database";                                                         \
  }

}  // namespace mocap::test
