#pragma once
// The temporal selection of every person of one stream (the state behind
// recon.temporal_selector): the matcher's candidates per frame in (PoseMatches), one People3D per
// input frame out, in order, each tracked person's chosen candidate turned into a 3D body in the
// camera frame (view refined against the person's 2D pose, turned onto the ray through their
// root pixel) with the 2D keypoints it came from; each People3D is in the frame of the
// PoseMatches' camera. A frame leaves once every person in it is
// decided (HeldFrames): at once (greedy, nearest) or `lag` frames later (path).

#include <array>
#include <map>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>

#include "core/messages.hpp"
#include "posedb/database.hpp"
#include "recon/ray_alignment.hpp"
#include "recon/temporal_selector.hpp"

namespace mocap::recon {

enum class SelectionMode { greedy, path, nearest };

struct PeopleSelectorOptions {
  SelectionMode mode = SelectionMode::greedy;
  SelectorOptions greedy;
  PathOptions path;
  int lag = 8;          // path: frames of look-ahead before a frame is decided
  int max_missed = 10;  // frames a person may be missing before their state is dropped
  // Without intrinsics the poses stay as the database cameras see them; with them each pose is
  // turned onto the ray through its root pixel (undistorted by the camera's lens).
  camera::Camera camera;
  bool refine_view = true;
};

class PeopleSelector {
 public:
  // `db` and `bones` must outlive the selector.
  PeopleSelector(const posedb::Database& db, const FrameBones& bones,
                 PeopleSelectorOptions options);
  ~PeopleSelector();
  PeopleSelector(PeopleSelector&&) noexcept;
  PeopleSelector& operator=(PeopleSelector&&) noexcept;

  // One input frame; the frames decided now, oldest first.
  std::vector<People3D> push(const PoseMatches& frame);
  // The end of the stream: every frame still held, in order.
  std::vector<People3D> finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::recon
