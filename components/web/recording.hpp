#pragma once
// A recorded run for the viewer: poses.jsonl (sink.jsonl) read back into People3D frames, and the
// playback clock the page controls (play, pause, seek, speed), looping at the end.

#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

#include "core/messages.hpp"

namespace mocap::web {

struct Recording {
  std::vector<People3D> frames;
  std::vector<double> times;   // seconds from the first frame, non-decreasing
  bool cut_last_line = false;  // a last line without its newline that did not parse was skipped
  bool world = false;          // people in a rig's world (joints_world): every frame is world-frame
};

// Reads poses.jsonl. People with `joints_abs` (camera frame) or `joints_world` (a rig's world; a
// file holds one or the other) come back placed (root translation set), `ground`
// sets the floor. Without usable times (missing, or going backwards) frames are `fps` apart.
// A last line without its newline that does not parse is what a killed writer leaves (sink.jsonl):
// it is skipped (cut_last_line). Throws mocap::InputError naming the file and line for anything
// else it cannot read, or an empty file.
Recording read_poses_jsonl(const std::string& path, double fps = 30.0);
// The same from a stream; `name` stands for the file in messages.
Recording parse_poses_jsonl(std::istream& in, const std::string& name, double fps = 30.0);

class Player {
 public:
  explicit Player(std::vector<double> times);

  void play() { playing_ = true; }
  void pause() { playing_ = false; }
  void seek(std::size_t index);
  void set_speed(double speed);  // clamped to [0.05, 16]
  // Moves the clock on by `seconds` of wall time (when playing) and returns the frame to show.
  std::size_t advance(double seconds);
  // A control message from the page: {"cmd":"play"}, {"cmd":"pause"}, {"cmd":"seek","index":N},
  // {"cmd":"speed","value":S}. False (and nothing changes) when it is not one of them.
  bool apply(const std::string& message);

  std::size_t index() const { return index_; }
  std::size_t count() const { return times_.size(); }
  bool playing() const { return playing_; }
  double speed() const { return speed_; }
  double duration() const { return times_.empty() ? 0.0 : times_.back(); }

 private:
  std::vector<double> times_;
  double clock_ = 0.0;
  std::size_t index_ = 0;
  bool playing_ = true;
  double speed_ = 1.0;
};

}  // namespace mocap::web
