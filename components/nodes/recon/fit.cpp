// recon.fit: the kinematic skeleton fitting after the temporal selector (issue 7; the algorithm is
// components/fit, docs/fitting.md). Per person, the retrieved pose and the 2D keypoints it came
// from are fitted with the person's constant bone lengths, and the root is placed in the camera
// frame (Person3D::placed, root.translation). The floor comes from the camera file, or is
// estimated from the people's contact feet, and travels on every output message once known.
//
// live: fixed lag; frame t leaves once frame t + lag has arrived, and never changes after.
// full: every frame of the stream is held and fitted at the end in one problem per person
//       (offline; with an estimated floor, once without it and once with it).
// off:  passes the poses on untouched (the graphs carry the node; `mocap reconstruct --fit`).
// Every input frame gives exactly one output frame.

#include <deque>
#include <iostream>
#include <map>
#include <optional>

#include "camera/camera_file.hpp"
#include "fit/foot_contact.hpp"
#include "fit/ground_estimation.hpp"
#include "fit/skeleton_fit.hpp"
#include "graph/registry.hpp"
#include "nodes/recon/node_camera.hpp"
#include "posedb/database.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class FitNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Fits each person's skeleton to their 2D keypoints (Ceres): constant bone lengths, root "
        "placed in the camera frame, feet on the floor");
    c.input<People3D>("in", "from recon.temporal_selector (poses with their 2D keypoints)");
    c.output<People3D>("out", "one message per input frame; placed people, floor when known");
    c.required_param<std::string>("db", "the pose database the poses come from (foot contact)");
    c.param<std::string>("mode", "live",
                         "live (fixed lag), full (whole stream, offline) or off (pass through)");
    c.param<int>("lag", 3, "live: frames of look-ahead before a frame is output", {0, 100});
    c.param<int>("iterations", 8, "live: solver iterations per frame", {1, 100});
    c.param<int>("max_missed", 10, "frames a person may be missing before their fit ends",
                 {0, 10000});
    declare_camera_params(c);  // a camera file's floor is used too (ground: auto)
    c.param<std::string>("ground", "auto",
                         "auto (the camera file's floor, else estimated from the feet), feet "
                         "(always estimated) or off (no floor)");
    c.param<double>("clearance", 0.07, "ankle joint height over the floor, metres", {0.0, 0.5});
    c.param<bool>("contact", true,
                  "keep feet in contact still (off for walking in place: a treadmill)");
  }

  void open(Context& ctx) override {
    const std::string mode = ctx.param<std::string>("mode");
    if (mode != "live" && mode != "full" && mode != "off")
      throw std::invalid_argument("mode must be live, full or off, not '" + mode + "'");
    off_ = mode == "off";
    if (off_) return;
    full_ = mode == "full";
    db_.emplace(posedb::Database::open(ctx.param<std::string>("db")));
    contacts_.emplace(*db_);
    ground_mode_ = ctx.param<std::string>("ground");
    if (ground_mode_ != "auto" && ground_mode_ != "feet" && ground_mode_ != "off")
      throw std::invalid_argument("ground must be auto, feet or off, not '" + ground_mode_ + "'");
    options_.lag = full_ ? 0 : ctx.param<int>("lag");
    options_.live_iterations = ctx.param<int>("iterations");
    options_.ankle_clearance_m = ctx.param<double>("clearance");
    max_missed_ = ctx.param<int>("max_missed");
    use_contact_ = ctx.param<bool>("contact");
    open_camera(ctx);
    fit::GroundEstimationOptions estimation;
    estimation.ankle_clearance_m = options_.ankle_clearance_m;
    estimator_.emplace(estimation);
  }

  void process(Context& ctx) override {
    if (off_) return ctx.forward("out", "in");
    const auto& in = ctx.input<People3D>("in");
    const std::int64_t t = next_frame_++;
    pending_.push_back({ctx.header(), in.people});
    for (const Person3D& person : in.people) {
      if (person.id < 0) continue;
      Track& track = tracks_[person.id];
      if (!track.started) start(track, t);
      while (track.next_frame < t) push(track, person.id, std::nullopt);  // frames it missed
      push(track, person.id, person);
      track.last_seen = t;
    }
    for (auto it = tracks_.begin(); it != tracks_.end();) {
      Track& track = it->second;
      if (track.next_frame <= t) push(track, it->first, std::nullopt);  // absent this frame
      if (!full_ && t - track.last_seen > max_missed_) {
        finish(track, it->first);
        it = tracks_.erase(it);
      } else {
        ++it;
      }
    }
    if (!full_) {
      update_ground();
      emit(ctx, t - options_.lag);
    }
  }

  void close(Context& ctx) override {
    if (off_) return;
    if (full_) {
      fit_all();
    } else {
      for (auto& [id, track] : tracks_) finish(track, id);
    }
    tracks_.clear();
    emit(ctx, next_frame_);
    std::cerr << "recon.fit '" << ctx.node_name() << "': " << fitted_ << " person-frames fitted"
              << (ground_ ? ground_text() : std::string(", no floor")) << "\n";
  }

 private:
  struct Track {
    bool started = false;
    std::int64_t first_frame = 0, next_frame = 0, last_seen = 0, next_output = 0;
    std::optional<fit::LiveFitter> live;
    std::vector<fit::FrameInput> inputs;  // full mode: every frame since first_frame
  };
  struct PendingFrame {
    Header header;
    std::vector<Person3D> people;  // as they came in; placed ones replace their pose
  };

  void open_camera(Context& ctx) {
    camera_ = read_camera_params(ctx);
    if (!camera_.pinhole.valid())
      throw std::invalid_argument(
          "the fitting needs the camera: set 'camera' (a calibration file) or 'image_width' and "
          "'image_height' (with 'hfov_deg')");
    options_.camera = camera_.pinhole;
    if (camera_.assumed) {
      std::cerr << "recon.fit '" << ctx.node_name() << "': no camera file, assuming a pinhole of "
                << camera_.hfov_deg << " deg horizontal field of view, principal point at the "
                << "image centre, no distortion\n";
    } else if (ground_mode_ == "auto") {
      if (const auto plane = camera::read_ground_plane(ctx.param<std::string>("camera"))) {
        set_ground({glm::vec3(glm::dvec3(plane->normal[0], plane->normal[1], plane->normal[2])),
                    static_cast<float>(plane->offset)},
                   "calibrated");
      }
    }
  }

  void start(Track& track, std::int64_t t) {
    track.started = true;
    track.first_frame = track.next_frame = track.last_seen = track.next_output = t;
    if (!full_) track.live.emplace(options_);
  }

  fit::FrameInput frame_input(const Person3D& person) const {
    fit::FrameInput in;
    std::array<Keypoint2D, kBodyJoints> keypoints = person.keypoints;
    undistort(camera_, keypoints);
    for (int j = 0; j < kBodyJoints; ++j) {
      const auto [x, y, confidence] = keypoints[static_cast<std::size_t>(j)];
      in.keypoints[static_cast<std::size_t>(3 * j)] = x;
      in.keypoints[static_cast<std::size_t>(3 * j + 1)] = y;
      in.keypoints[static_cast<std::size_t>(3 * j + 2)] = std::isfinite(x + y) ? confidence : 0;
    }
    in.retrieved_valid = true;
    in.retrieved = person.positions;
    if (use_contact_ && person.provenance.frame >= 0 &&
        person.provenance.frame < static_cast<std::int64_t>(db_->frames().size()))
      in.contact = contacts_->contact(static_cast<std::uint32_t>(person.provenance.frame));
    return in;
  }

  // One frame of a track: the person as seen, or nullopt (absent: a gap in their window).
  void push(Track& track, int id, const std::optional<Person3D>& person) {
    const fit::FrameInput in = person ? frame_input(*person) : fit::FrameInput{};
    ++track.next_frame;
    if (full_) {
      track.inputs.push_back(in);
      return;
    }
    if (const auto out = track.live->push(in)) place(id, track.next_output++, *out, in.contact);
  }

  void finish(Track& track, int id) {
    if (!track.live) return;
    for (const fit::FittedFrame& out : track.live->finish())
      place(id, track.next_output++, out, {});
  }

  // Puts a fitted body into its pending frame, where the person's retrieved pose is.
  void place(int id, std::int64_t frame, const fit::FittedFrame& fitted,
             std::array<bool, 2> contact) {
    const std::int64_t slot = frame - first_pending_;
    if (!fitted.valid || !fitted.observed || slot < 0 ||
        slot >= static_cast<std::int64_t>(pending_.size()))
      return;
    for (Person3D& person : pending_[static_cast<std::size_t>(slot)].people) {
      if (person.id != id) continue;
      const glm::vec3 root = fitted.root();
      for (int j = 0; j < kBodyJoints; ++j)
        person.positions[static_cast<std::size_t>(j)] =
            fitted.joints[static_cast<std::size_t>(j)] - root;
      person.root.translation = root;
      person.placed = true;
      ++fitted_;
      if (!full_ && ground_mode_ != "off" && !ground_calibrated_)
        estimator_->add(fitted.joints, contact);
    }
  }

  // Full mode: every person's whole stream in one problem; with a floor to estimate, once to find
  // it and once with it.
  void fit_all() {
    std::map<int, fit::FitResult> results;
    for (const auto& [id, track] : tracks_) results[id] = fit::fit_sequence(track.inputs, options_);
    if (!ground_ && ground_mode_ != "off") {
      for (const auto& [id, result] : results) {
        const auto& inputs = tracks_.at(id).inputs;
        for (std::size_t i = 0; i < result.frames.size(); ++i) {
          if (result.frames[i].valid && result.frames[i].observed)
            estimator_->add(result.frames[i].joints, inputs[i].contact);
        }
      }
      update_ground();
      if (ground_) {
        for (const auto& [id, track] : tracks_)
          results[id] = fit::fit_sequence(track.inputs, options_);
      }
    }
    for (const auto& [id, result] : results) {
      const Track& track = tracks_.at(id);
      for (std::size_t i = 0; i < result.frames.size(); ++i)
        place(id, track.first_frame + static_cast<std::int64_t>(i), result.frames[i],
              track.inputs[i].contact);
    }
  }

  void update_ground() {
    if (ground_calibrated_ || ground_mode_ == "off") return;
    // Re-estimated as samples come in, until the estimate rests on plenty of them.
    if (ground_ && estimator_->contacts() >= 1000) return;
    if (const auto estimate = estimator_->estimate()) {
      const auto& p = estimate->plane;
      set_ground({glm::vec3(p.normal), static_cast<float>(p.offset)},
                 estimate->normal_from_contacts ? "estimated from the feet (plane of contacts)"
                                                : "estimated from the feet (upright bodies)");
    }
  }

  void set_ground(const GroundPlane& plane, std::string source) {
    ground_ = plane;
    ground_source_ = std::move(source);
    ground_calibrated_ = ground_source_ == "calibrated";
    options_.ground = fit::GroundPlane{glm::dvec3(plane.normal), plane.offset};
    for (auto& [id, track] : tracks_) {
      if (track.live) track.live->set_ground(options_.ground);
    }
  }

  std::string ground_text() const {
    return ", floor " + ground_source_ + ": camera " + std::to_string(ground_->offset) +
           " m above it";
  }

  // Sends every pending frame up to and including `last`, in order.
  void emit(Context& ctx, std::int64_t last) {
    while (!pending_.empty() && first_pending_ <= last) {
      People3D out;
      out.header = pending_.front().header;
      out.people = std::move(pending_.front().people);
      if (ground_) out.has_ground = true, out.ground = *ground_;
      ctx.send("out", std::move(out));
      pending_.pop_front();
      ++first_pending_;
    }
  }

  std::optional<posedb::Database> db_;
  std::optional<fit::ContactDetector> contacts_;
  NodeCamera camera_;
  fit::FitOptions options_;
  bool off_ = false, full_ = false;
  bool use_contact_ = true;
  std::string ground_mode_;
  int max_missed_ = 10;
  std::optional<fit::GroundEstimator> estimator_;
  std::optional<GroundPlane> ground_;
  std::string ground_source_;
  bool ground_calibrated_ = false;
  std::map<int, Track> tracks_;
  std::deque<PendingFrame> pending_;
  std::int64_t next_frame_ = 0, first_pending_ = 0, fitted_ = 0;
};

MOCAP_REGISTER_NODE("recon.fit", FitNode)

}  // namespace mocap::nodes
