// recon.temporal_selector: picks, per person, one of the matcher's candidates in time and turns it
// into a 3D body in the camera's frame. Modes: the paper's greedy rule (w previous frames, Lee et
// al. distance), a Viterbi path with a fixed lag, or the nearest candidate alone. With a lag, frame
// t leaves once frame t + lag has arrived; every input frame gives exactly one output frame.

#include <deque>
#include <map>
#include <optional>

#include "core/input_error.hpp"
#include "graph/registry.hpp"
#include "nodes/recon/node_camera.hpp"
#include "posedb/database.hpp"
#include "recon/sequence_reconstruction.hpp"
#include "recon/temporal_selector.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

namespace {

Person3D to_person(int id, const recon::Pose3D& pose, const posedb::Database& db) {
  Person3D p;
  p.id = id;
  p.positions = pose.joints;
  p.root.rotation = pose.body_to_camera;
  const auto& frame = db.frames()[pose.chosen.frame];
  p.provenance = {db.clips()[frame.clip].name, static_cast<std::int64_t>(pose.chosen.frame),
                  static_cast<int>(pose.chosen.view)};
  return p;
}

}  // namespace

class TemporalSelectorNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Chooses each person's candidate in time and outputs 3D bodies in the camera frame");
    c.input<PoseMatches>("in", "from recon.matcher");
    c.output<People3D>("out", "one message per input frame");
    c.required_param<std::string>("db", "pose database file (the matcher's)");
    c.param<std::string>("mode", "greedy",
                         "greedy (the paper), path (Viterbi with a lag) or nearest");
    c.param<int>("window", 4, "greedy: previous frames compared (w)", {1, 64});
    c.param<bool>("reject_repeat", false, "greedy: never choose the previous frame again");
    c.param<int>("lag", 8, "path: frames of look-ahead before a frame is decided", {0, 1000});
    c.param<double>("data_weight", 50.0, "path: weight of the 2D match distance", {0.0, 1e6});
    c.param<int>("max_missed", 10, "frames a person may be missing before its state is dropped",
                 {0, 10000});
    declare_camera_params(c);
  }

  void open(Context& ctx) override {
    db_.emplace(posedb::Database::open(ctx.param<std::string>("db")));
    bones_.emplace(*db_);
    const std::string mode = ctx.param<std::string>("mode");
    if (mode != "greedy" && mode != "path" && mode != "nearest") {
      throw std::invalid_argument("mode must be greedy, path or nearest, not '" + mode + "'");
    }
    mode_ = mode;
    greedy_.window = ctx.param<int>("window");
    greedy_.reject_repeat = ctx.param<bool>("reject_repeat");
    path_.data_weight = ctx.param<float>("data_weight");
    lag_ = mode_ == "path" ? ctx.param<int>("lag") : 0;
    max_missed_ = ctx.param<int>("max_missed");
    camera_ = read_camera_params(ctx);
  }

  void process(Context& ctx) override {
    const auto& in = ctx.input<PoseMatches>("in");
    const std::int64_t t = next_frame_++;
    pending_.push_back({ctx.header(), in.camera, {}, {}, {}, {}});
    for (const PersonMatch& person : in.people) {
      if (person.id < 0) continue;  // untracked: no history to choose with
      pending_.back().keypoints[person.id] = person.body;
      const Keypoint2D root = person.body[index(Joint::root)];
      const glm::dvec2 ideal = camera_.camera.undistort_pixel({root.x, root.y});
      pending_.back().root_pixel[person.id] = glm::vec2(ideal);
      if (person.normalized_ok) {
        posedb::PoseVector query;
        std::copy(person.normalized.begin(), person.normalized.end(), query.begin());
        pending_.back().query[person.id] = query;
      }
      Track& track = tracks_[person.id];
      if (!track.path && !track.greedy) start(track, t);
      track.last_seen = t;
      decide(person.id, track, person.candidates);
    }
    for (auto it = tracks_.begin(); it != tracks_.end();) {
      Track& track = it->second;
      if (track.last_seen == t) {
        ++it;
        continue;
      }
      decide(it->first, track, {});  // absent this frame: a gap in its path
      if (t - track.last_seen > max_missed_) {
        flush(it->first, track);
        it = tracks_.erase(it);
      } else {
        ++it;
      }
    }
    emit(ctx, t - lag_);
  }

  void close(Context& ctx) override {
    for (auto& [id, track] : tracks_) flush(id, track);
    tracks_.clear();
    emit(ctx, next_frame_);
  }

 private:
  struct Track {
    std::int64_t first_frame = 0, last_seen = 0;
    std::optional<recon::TemporalSelector> greedy;
    std::optional<recon::LaggedPathSelector> path;
  };
  struct PendingFrame {
    Header header;
    std::string camera;  // whose frame the poses are in
    std::vector<Person3D> people;
    std::map<int, glm::vec2> root_pixel;      // of each person in this frame's input
    std::map<int, posedb::PoseVector> query;  // each person's normalised 2D pose
    std::map<int, std::array<Keypoint2D, kBodyJoints>> keypoints;  // each person's 2D body
  };

  void start(Track& track, std::int64_t t) {
    track.first_frame = t;
    if (mode_ == "path") {
      track.path.emplace(*bones_, path_, lag_);
    } else {
      track.greedy.emplace(*bones_, greedy_);
    }
  }

  void decide(int id, Track& track, const std::vector<PoseCandidate>& candidates) {
    if (track.path) {
      place(id, track, track.path->push(candidates));
      return;
    }
    if (candidates.empty()) {
      track.greedy->reset();
      return;
    }
    const std::size_t pick = mode_ == "nearest" ? 0 : track.greedy->select(candidates);
    add(id, track.last_seen, recon::pose_in_camera(*db_, candidates[pick]));
  }

  void flush(int id, Track& track) {
    if (track.path) place(id, track, track.path->flush());
  }

  void place(int id, const Track& track,
             const std::vector<recon::LaggedPathSelector::Decision>& decisions) {
    for (const auto& [local, choice] : decisions) {
      if (choice)
        add(id, track.first_frame + static_cast<std::int64_t>(local),
            recon::pose_in_camera(*db_, *choice));
    }
  }

  void add(int id, std::int64_t frame, const recon::Pose3D& pose) {
    const std::int64_t slot = frame - first_pending_;
    if (slot < 0 || slot >= static_cast<std::int64_t>(pending_.size())) return;  // already sent
    PendingFrame& pending = pending_[static_cast<std::size_t>(slot)];
    recon::Pose3D turned = pose;
    if (const auto query = pending.query.find(id); refine_view_ && query != pending.query.end()) {
      turned = recon::refined_pose_in_camera(*db_, pose.chosen, query->second);
    }
    if (const auto root = pending.root_pixel.find(id);
        camera_.known() && root != pending.root_pixel.end()) {
      recon::turn_onto_ray(turned, camera_.camera, root->second);
    }
    pending.people.push_back(to_person(id, turned, *db_));
    if (const auto body = pending.keypoints.find(id); body != pending.keypoints.end())
      pending.people.back().keypoints = body->second;
  }

  // Sends every pending frame up to and including `last`, in order.
  void emit(Context& ctx, std::int64_t last) {
    while (!pending_.empty() && first_pending_ <= last) {
      People3D out;
      out.header = pending_.front().header;
      out.frame = CoordinateFrame::of_camera(std::move(pending_.front().camera));
      out.people = std::move(pending_.front().people);
      std::sort(out.people.begin(), out.people.end(),
                [](const Person3D& a, const Person3D& b) { return a.id < b.id; });
      ctx.send("out", std::move(out));
      pending_.pop_front();
      ++first_pending_;
    }
  }

  std::optional<posedb::Database> db_;
  std::optional<recon::FrameBones> bones_;
  std::string mode_;
  recon::SelectorOptions greedy_;
  recon::PathOptions path_;
  int lag_ = 0;
  int max_missed_ = 10;
  NodeCamera camera_;  // unknown: poses stay as the database cameras see them
  bool refine_view_ = true;
  std::map<int, Track> tracks_;
  std::deque<PendingFrame> pending_;
  std::int64_t next_frame_ = 0, first_pending_ = 0;
};

MOCAP_REGISTER_NODE("recon.temporal_selector", TemporalSelectorNode)

}  // namespace mocap::nodes
