#pragma once
// One BVH file per tracked person, written frame by frame as the reconstruction runs (the sink.bvh
// node): <dir>/<prefix><id>.bvh on the mocap skeleton of the person's first matched clip, valid
// on disk after every frame (motion::BvhStreamWriter), even if the program is killed.
//
// Time stays regular: frame k of a file is input frame (first appearance + k). When a person is
// missing for some input frames and comes back, their last pose is repeated for the frames
// missed, so the file stays in step with the video and the JSON lines; a person who never comes
// back gets no frames after their last appearance (nothing is padded at the end).
//
// A tracker also makes short-lived ids (a false detection, a person seen for a moment): a file is
// only started once its person has `min_frames` frames, which are held in memory until then; an
// id that never gets there leaves no file and is counted as a short track.
//
// With `in_memory` the same frames are kept as one motion::Clip per person instead of files
// (take_clips() after close()): for writers of whole files at the end of a stream (sink.gltf).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "motion/bvh_stream_writer.hpp"
#include "posedb/database.hpp"
#include "recon/bvh_frame.hpp"

namespace mocap::recon {

struct PeopleBvhOptions {
  std::string dir;                 // created when missing
  std::string prefix = "person_";  // file name before the id
  double fps = 30.0;               // the input frame rate, written as the frame time
  int max_open_files = 64;         // more people than this: the longest-unseen file is suspended
  int min_frames = 1;              // frames (held gaps included) before a person's file is made
  // The database's rotations change abruptly where the chosen motion jumps between clips: the
  // 1-Euro filter (on the rotation group, per joint) smooths them, as the paper smooths its motion.
  bool smooth_rotations = true;
  OneEuroParams smoothing;  // the paper's beta 0.4, fc_min 1 Hz
  bool in_memory = false;   // no files (dir unused): every person's frames stay in memory
};

// A person's motion kept in memory: `first_frame` is the input frame of clip frame 0.
struct PersonClip {
  int id = -1;
  std::int64_t first_frame = 0;
  motion::Clip clip;
};

struct PeopleBvhSummary {
  std::int64_t files = 0;              // in memory: people kept
  std::int64_t frames = 0;             // frame lines written, held ones included
  std::int64_t held_over_gaps = 0;     // repeated poses for input frames a person was missing in
  std::int64_t skeleton_mismatch = 0;  // pose from a clip of another skeleton: previous one held
  std::int64_t no_provenance = 0;      // pose naming no database frame: previous one held or none
  std::int64_t no_skeleton = 0;        // first pose's clip has no skeleton: file not started yet
  std::int64_t short_tracks = 0;       // ids that ended with fewer than min_frames: no file

  std::string describe() const;  // one line for logs
};

class PeopleBvhWriter {
 public:
  // Creates `options.dir`; throws InputError naming it when that fails. `db` must outlive this.
  PeopleBvhWriter(const posedb::Database& db, PeopleBvhOptions options);

  // Appends one input frame (header.frame) for every person in it. Throws InputError naming the
  // file on a write error, or the database when a pose was matched against another one.
  void write(const People3D& people);
  // Closes every file (all of them, even when one fails); throws the first error. Idempotent.
  void close();

  // In memory: every person with at least min_frames frames, by id, after close(); the
  // writer's frames are moved out.
  std::vector<PersonClip> take_clips();

  std::string path_for(int id) const;
  const PeopleBvhSummary& summary() const { return summary_; }

 private:
  struct Track {
    std::optional<motion::BvhStreamWriter> file;  // made once the track has min_frames
    motion::Skeleton skeleton;
    BvhFrameMaker maker;
    std::vector<float> values;                // the last pose written
    std::vector<std::vector<float>> pending;  // frames before the file exists
    std::int64_t last_frame = 0;
    std::int64_t first_frame = 0;
    bool counted = false;  // in memory: in the summary already (close() is idempotent)
  };

  double seconds(std::int64_t frame) const;
  void start(const Person3D& person, std::int64_t frame,
             const std::optional<BvhPlacement>& placement);
  void append(Track& track, const Person3D& person, std::int64_t frame,
              const std::optional<BvhPlacement>& placement);
  void emit(int id, Track& track);  // one frame: track.values
  void keep_open_files_bounded(int arriving_id);

  const posedb::Database& db_;
  PeopleBvhOptions options_;
  std::map<int, Track> tracks_;
  PeopleBvhSummary summary_;
};

}  // namespace mocap::recon
