#include "recon/people_selector.hpp"

#include <algorithm>
#include <optional>

#include "recon/held_frames.hpp"
#include "recon/sequence_reconstruction.hpp"

namespace mocap::recon {

struct PeopleSelector::State {
  struct Track {
    std::int64_t first_frame = 0, last_seen = 0;
    std::optional<TemporalSelector> greedy;
    std::optional<LaggedPathSelector> path;
  };
  // A frame while its people are decided.
  struct Pending {
    People3D out;
    std::map<int, glm::vec2> root_pixel;      // of each person in this frame's input
    std::map<int, posedb::PoseVector> query;  // each person's normalised 2D pose
    std::map<int, std::array<Keypoint2D, kBodyJoints>> keypoints;  // each person's 2D body
  };

  const posedb::Database& db;
  const FrameBones& bones;
  PeopleSelectorOptions options;
  std::map<int, Track> tracks;
  HeldFrames<Pending> held;

  State(const posedb::Database& d, const FrameBones& b, PeopleSelectorOptions o)
      : db(d), bones(b), options(std::move(o)) {
    if (options.mode != SelectionMode::path) options.lag = 0;
  }

  Person3D to_person(int id, const Pose3D& pose) const {
    Person3D p;
    p.id = id;
    p.positions = pose.joints;
    p.root.rotation = pose.body_to_camera;
    const auto& frame = db.frames()[pose.chosen.frame];
    p.provenance = {db.clips()[frame.clip].name, static_cast<std::int64_t>(pose.chosen.frame),
                    static_cast<int>(pose.chosen.view)};
    return p;
  }

  // Person `id` decided in `frame`: the chosen candidate (if any) becomes their body there.
  void decide(int id, std::int64_t frame, const std::optional<Candidate>& choice) {
    Pending* pending = held.find(frame);
    if (pending == nullptr || !held.decide(frame, id) || !choice) return;
    Pose3D turned = pose_in_camera(db, *choice);
    if (const auto query = pending->query.find(id);
        options.refine_view && query != pending->query.end())
      turned = refined_pose_in_camera(db, *choice, query->second);
    if (const auto root = pending->root_pixel.find(id);
        options.camera.has_intrinsics() && root != pending->root_pixel.end())
      turn_onto_ray(turned, options.camera, root->second);
    pending->out.people.push_back(to_person(id, turned));
    if (const auto body = pending->keypoints.find(id); body != pending->keypoints.end())
      pending->out.people.back().keypoints = body->second;
  }

  void decide_path(int id, const Track& track,
                   const std::vector<LaggedPathSelector::Decision>& decisions) {
    for (const auto& [local, choice] : decisions)
      decide(id, track.first_frame + static_cast<std::int64_t>(local), choice);
  }

  // The track's choice in frame t (`candidates` empty: the person is absent or unmatched).
  void select(int id, Track& track, std::int64_t t, const std::vector<PoseCandidate>& candidates) {
    if (track.path) return decide_path(id, track, track.path->push(candidates));
    if (candidates.empty()) {
      track.greedy->reset();
      return decide(id, t, std::nullopt);
    }
    const std::size_t pick =
        options.mode == SelectionMode::nearest ? 0 : track.greedy->select(candidates);
    decide(id, t, candidates[pick]);
  }

  void start(Track& track, std::int64_t t) {
    track.first_frame = t;
    if (options.mode == SelectionMode::path)
      track.path.emplace(bones, options.path, options.lag);
    else
      track.greedy.emplace(bones, options.greedy);
  }

  void release(std::vector<People3D>& out, bool all) {
    auto send = [&](Pending&& p) {
      std::sort(p.out.people.begin(), p.out.people.end(),
                [](const Person3D& a, const Person3D& b) { return a.id < b.id; });
      out.push_back(std::move(p.out));
    };
    all ? held.release_all(send) : held.release_decided(send);
  }
};

PeopleSelector::PeopleSelector(const posedb::Database& db, const FrameBones& bones,
                               PeopleSelectorOptions options)
    : state_(std::make_unique<State>(db, bones, std::move(options))) {}
PeopleSelector::~PeopleSelector() = default;
PeopleSelector::PeopleSelector(PeopleSelector&&) noexcept = default;
PeopleSelector& PeopleSelector::operator=(PeopleSelector&&) noexcept = default;

std::vector<People3D> PeopleSelector::push(const PoseMatches& in) {
  State& s = *state_;
  State::Pending pending;
  pending.out.header = in.header;
  pending.out.frame = CoordinateFrame::of_camera(in.camera);
  std::vector<int> ids;
  for (const PersonMatch& person : in.people) {
    if (person.id < 0) continue;  // untracked: no history to choose with
    ids.push_back(person.id);
    pending.keypoints[person.id] = person.body;
    const Keypoint2D& root = person.body[index(Joint::root)];
    pending.root_pixel[person.id] = glm::vec2(s.options.camera.undistort_pixel({root.x, root.y}));
    if (person.normalized_ok) {
      posedb::PoseVector query;
      std::copy(person.normalized.begin(), person.normalized.end(), query.begin());
      pending.query[person.id] = query;
    }
  }
  const std::int64_t t = s.held.hold(std::move(pending), std::move(ids));
  for (const PersonMatch& person : in.people) {
    if (person.id < 0) continue;
    auto [it, added] = s.tracks.try_emplace(person.id);
    if (added) s.start(it->second, t);
    if (it->second.last_seen == t && !added) continue;  // the id twice in one frame
    it->second.last_seen = t;
    s.select(person.id, it->second, t, person.candidates);
  }
  for (auto it = s.tracks.begin(); it != s.tracks.end();) {
    State::Track& track = it->second;
    if (track.last_seen != t) s.select(it->first, track, t, {});  // absent: a gap in its path
    if (t - track.last_seen > s.options.max_missed) {
      if (track.path) s.decide_path(it->first, track, track.path->flush());
      it = s.tracks.erase(it);
    } else {
      ++it;
    }
  }
  std::vector<People3D> out;
  s.release(out, false);
  return out;
}

std::vector<People3D> PeopleSelector::finish() {
  State& s = *state_;
  for (auto& [id, track] : s.tracks)
    if (track.path) s.decide_path(id, track, track.path->flush());
  s.tracks.clear();
  std::vector<People3D> out;
  s.release(out, true);
  return out;
}

}  // namespace mocap::recon
