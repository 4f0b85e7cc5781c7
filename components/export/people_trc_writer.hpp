#pragma once
// One TRC marker file per tracked person (the sink.trc node), for OpenSim and Pose2Sim users: the
// 15 body joints in the world frame of a multi-view reconstruction, written frame by frame and
// valid on disk after every frame, also when the program is killed (io/trc_writer.hpp).
//
// Markers: the 15 body joints (core/body15.hpp) under Pose2Sim's marker names where the joint is
// the same point (Head, Neck, RShoulder, ..., LAnkle) and `Hip` for the root (the mid-hip, as
// Pose2Sim's HALPE_26 layout names it). Axes: OpenSim's TRC is Y-up; a Z-up world (the rigs of
// Pose2Sim, anipose and Caliscope calibrations) is turned as Pose2Sim turns it, (X, Y, Z)_trc =
// (Y, Z, X)_world; a Y-up world is written as it is.
//
// Time stays regular: a file's Frame# is the input frame number + 1 (Pose2Sim's Frame# of JSON
// index i is i + 1), its first row the person's first appearance; frames a person is missing in
// are rows with empty cells, so every file stays in step with the video and poses.jsonl.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "io/trc_writer.hpp"

namespace mocap::exporting {

enum class WorldUp { z, y };

struct PeopleTrcOptions {
  // File of each person: "{id}" is replaced by the person's id (the folder is made when missing).
  std::string path_pattern = "person_{id}.trc";
  double fps = 30.0;
  WorldUp world_up = WorldUp::z;
  int max_open_files = 64;  // more people than this: the longest-unseen file is suspended
};

struct PeopleTrcSummary {
  std::int64_t files = 0;
  std::int64_t rows = 0;          // rows written, empty ones included
  std::int64_t empty_rows = 0;    // rows of frames a person was missing in
  std::int64_t untracked = 0;     // people without an id (-1): no file can hold them
  std::int64_t out_of_order = 0;  // a person's frame not after their previous one: skipped

  std::string describe() const;  // one line for logs
};

// The marker names, in file order (the 15 body joints' order).
const std::vector<std::string>& trc_marker_names();

class PeopleTrcWriter {
 public:
  // Throws InputError naming the pattern when it has no "{id}" or its folder cannot be made.
  explicit PeopleTrcWriter(PeopleTrcOptions options);

  // Appends one input frame (header.frame) for every person in it. Throws InputError when the
  // message is not in the world frame (naming its camera) or on a write error (naming the file).
  void write(const People3D& people);
  // Closes every file (all of them, even when one fails); throws the first error. Idempotent.
  void close();

  std::string path_for(int id) const;
  const PeopleTrcSummary& summary() const { return summary_; }

 private:
  struct Person {
    io::TrcStreamWriter file;
    std::int64_t last_frame = 0;
  };
  Person& person(int id, std::int64_t frame);
  void limit_open_files(int keep);

  PeopleTrcOptions options_;
  std::map<int, Person> people_;
  PeopleTrcSummary summary_;
};

}  // namespace mocap::exporting
