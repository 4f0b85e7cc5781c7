#pragma once
// Several people from several calibrated views, frame by frame: association across views,
// triangulation and tracking in 3D (docs/multiview.md).
//
// Per frame:
// 1. Tracking: each track's predicted keypoints are matched with each view's detections (cost:
//    the trimmed mean distance from the predicted points to the detection's rays, metres;
//    Hungarian per view, gated). A track's detections are triangulated together, with the
//    track's prediction as a prior (tracking.hpp); a detection that does not fit the 3D person
//    is taken out, the worst first: its median held-out residual is above max(member_gate_m, the
//    person's outlier threshold), or, with three views or more, its size in the image is off by
//    more than size_tolerance (someone lined up in front of or behind the person in that view).
// 2. Detections left over join a tracked person whose 3D keypoints their rays pass (attach_gate_m).
// 3. The rest are clustered from scratch (association.hpp) and checked the same way; two groups
//    with no view in common whose keypoints coincide are merged (a track that lost some views and
//    a new group of them); leftovers are offered to every person once more.
// 4. A detection that agrees with two people goes to the one nearer to its camera, who hides the
//    other in that view (occlusion_margin_m).
// 5. A group of two views or more with at least min_keypoints triangulated keypoints is a person
//    if its centre is inside the capture volume (when one is set) and, when no track predicted
//    it, it is seen by at least min_view_fraction of the views that have it in the image. A
//    track continues; any other person gets a returning track's id or a new one; people of
//    unconfirmed tracks (their first frames) are left out unless report_tentative.
//    A detection in no group is a single-view person, reported separately (with the track it
//    matched in its view, if any): the caller sends it through the monocular path or drops it
//    with a count.
// Without tracking, steps 1–2 are skipped, there is no prior and ids are -1.
//
// The views, the keypoints and all costs are in the world frame of the projections, in metres.
// One core; once the largest frame has been seen nothing is allocated per frame.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "multiview/association.hpp"
#include "multiview/detections.hpp"
#include "multiview/observations.hpp"
#include "multiview/person_triangulation.hpp"
#include "multiview/tracking.hpp"
#include "multiview/view_geometry.hpp"

namespace mocap::multiview {

struct ReconstructionOptions {
  RayCostOptions rays;
  // Cold association: two detections whose ray cost (metres) is at most this may be one person.
  float pair_gate_m = 0.15f;
  // A detection whose median held-out residual exceeds max(this, the person's outlier
  // threshold) is not part of that person.
  float member_gate_m = 0.15f;
  // In a group of three views or more, a detection more than this factor larger or smaller than
  // the person projected into its view is not part of it.
  float size_tolerance = 1.2f;
  // A leftover detection joins a person whose 3D keypoints its rays pass within this (metres).
  float attach_gate_m = 0.15f;
  // Triangulated keypoints a group needs to be reported as a person.
  int min_keypoints = 4;
  // A person no track predicted must be seen by at least this share of the views that have it in
  // front and in the image (and by two): two false detections agreeing by chance in a large rig
  // are not a person. (0.25 / 0.35 / 0.5 on the virtual scenes, 8 views, no tracking: 10 / 0 / 0
  // wrong people in 450 person-frames; coverage unchanged with 6 people.)
  float min_view_fraction = 0.35f;
  TriangulationOptions triangulation;
  bool tracking = true;
  TrackingOptions tracker;
  // With tracking, people whose track is not confirmed yet (a person's first min_hits - 1
  // frames, or a chance agreement of false detections) are left out of the result and counted in
  // FrameResult::tentative_people, unless this is set.
  bool report_tentative = false;
  // A detection that fits two people is the nearer one's in its view (it hides the other): a
  // member moves to a person at least this much nearer to that camera whose detections it
  // agrees with (metres).
  float occlusion_margin_m = 0.3f;
  // The capture volume, an axis-aligned box in the world (metres): a person whose body centre is
  // outside is not reported (counted in FrameResult::outside_people), e.g. somebody standing
  // behind the cameras that two of them see. Empty (min > max, the default): everywhere.
  glm::vec3 volume_min{1.0f};
  glm::vec3 volume_max{-1.0f};
};

struct PersonResult {
  int id = -1;               // track id; -1 without tracking
  bool confirmed = true;     // its track was seen in TrackingOptions::min_hits frames
  std::uint64_t views = 0;   // views whose detection is part of the person
  float threshold_m = 0.0f;  // the outlier threshold its keypoints were triangulated with
};

struct SingleViewPerson {
  int view = 0;
  int detection = 0;  // index in the view's people
  int track_id = -1;  // the track its view matched it with, or -1
};

struct FrameResult {
  std::int64_t frame = 0;
  int views = 0;
  int keypoints = 0;
  std::vector<PersonResult> people;
  std::vector<int> detections;  // people × views: index in the view's people, or -1
  std::vector<TriangulatedPoint> keypoint_points;  // people × keypoints, world
  std::vector<TriangulatedPoint> body_points;      // people × 15 body joints, world
  std::vector<SingleViewPerson> single_view;
  int sparse_detections = 0;  // detections with too few keypoints to associate
  int tentative_people = 0;   // people of unconfirmed tracks left out (report_tentative)
  int outside_people = 0;     // people outside the capture volume, left out

  std::span<const int> detections_of(std::size_t person) const;
  std::span<const TriangulatedPoint> keypoints_of(std::size_t person) const;
  std::span<const TriangulatedPoint> body_of(std::size_t person) const;
};

// The 15 body joints from triangulated keypoints, as `set` makes each joint: a keypoint, or the
// midpoint of two (views: both sets; error: the mean).
void body_from_keypoints(const KeypointSet& set, std::span<const TriangulatedPoint> keypoints,
                         std::span<TriangulatedPoint> body);

class MultiViewReconstructor {
 public:
  // At most kMaxViews views. Throws std::invalid_argument for none or too many.
  MultiViewReconstructor(std::vector<ViewGeometry> views, const KeypointSet& keypoints,
                         const ReconstructionOptions& options = {});

  // One frame set: `frame` holds one entry per view (in the views' order), `frame_number` counts
  // frames (tracks predict and expire by it). The result stays valid until the next call.
  const FrameResult& process(const FrameObservations& frame, std::int64_t frame_number);
  // Forgets every track.
  void reset();

  std::span<const ViewGeometry> views() const { return views_; }
  const ReconstructionOptions& options() const { return options_; }

 private:
  struct Group {
    int track = -1;  // tracker index, or -1
    std::uint64_t views = 0;
    int members = 0;
    int triangulated = 0;
    float threshold_m = 0.0f;
  };

  int add_group(int track);
  void add_member(int group, int detection);
  void remove_member(int group, int detection);
  void triangulate(int group);
  void verify(int group);
  void match_tracks();
  void cluster_leftovers();
  void merge_duplicates();
  void reassign_hidden();
  glm::dvec3 group_centre(int group) const;
  double size_ratio(int group, const Sighting& sighting) const;
  void drop_tentative();
  bool seen_enough(int group) const;
  bool inside_volume(int group) const;
  void attach_leftovers(bool tracked_only);
  void emit(std::int64_t frame_number);
  std::span<TriangulatedPoint> points(int group);

  std::vector<ViewGeometry> views_;
  KeypointSet keypoints_;
  ReconstructionOptions options_;
  Tracker tracker_;
  DetectionTable table_;
  ViewClustering clustering_;
  PersonTriangulator triangulator_;
  recon::AssignmentSolver solver_;
  const FrameObservations* frame_ = nullptr;

  std::vector<Group> groups_;
  std::vector<int> slots_;                 // groups × views: detection (table index) or -1
  std::vector<TriangulatedPoint> points_;  // groups × keypoints
  std::vector<glm::vec3> positions_;       // groups × keypoints: points_' positions
  std::vector<float> innovations_;         // groups × keypoints (person_triangulation.hpp)
  std::vector<KeypointPrior> priors_;
  std::vector<glm::dvec3> centres_;
  std::vector<int> owner_;        // per detection: group or -1
  std::vector<int> view_track_;   // per detection: track matched in its view, or -1
  std::vector<int> track_group_;  // per track: group or -1
  std::vector<Sighting> sightings_;
  std::vector<int> sighting_detection_;
  std::vector<float> residuals_;
  std::vector<int> scratch_;
  std::vector<float> cost_;
  std::vector<int> assignment_;
  struct Offer {
    float cost;
    int detection;
    int group;
  };
  std::vector<Offer> offers_;
  std::vector<TrackInput> new_people_;
  std::vector<int> new_groups_;
  std::vector<int> new_ids_;
  FrameResult result_;
};

}  // namespace mocap::multiview
