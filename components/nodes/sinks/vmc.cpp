// sink.vmc: the live link. Every People3D message becomes one VMC bundle (OSC over UDP) per
// person sent: root and humanoid bone rotations in Unity's axes (export/humanoid.hpp,
// export/vmc_sender.hpp), at the rate the messages come in (the capture rate).
// docs/live-link.md: receiving it in Blender (VMC4B) and Unity (EVMC4U).

#include <algorithm>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "export/humanoid.hpp"
#include "export/vmc_sender.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

namespace {

// The extent of a person's detected keypoints (the larger of width and height, pixels); the 3D
// body's when there are none.
float size_of(const Person3D& p) {
  float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
  int n = 0;
  for (const Keypoint2D& k : p.keypoints) {
    if (!(k.confidence > 0.0f)) continue;
    x0 = std::min(x0, k.x), y0 = std::min(y0, k.y), x1 = std::max(x1, k.x), y1 = std::max(y1, k.y);
    ++n;
  }
  if (n >= 2) return std::max(x1 - x0, y1 - y0);
  float extent = 0.0f;
  for (const glm::vec3& v : p.positions) extent = std::max(extent, std::abs(v.y));
  return extent;
}

}  // namespace

class VmcSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Sends people live over the VMC protocol (OSC/UDP): per frame a bundle with /VMC/Ext/OK, "
        "/VMC/Ext/T, /VMC/Ext/Root/Pos and /VMC/Ext/Bone/Pos for 19 Unity humanoid bones, "
        "Unity axes (left-handed, Y up)");
    c.input<People3D>("in", "reconstructed people (3D joints, placed or not)");
    c.param<std::string>("host", "127.0.0.1", "receiver address (name or IP)");
    c.param<int>("port", exporting::kVmcDefaultPort, "receiver UDP port (VMC's default 39539)",
                 {1, 65535});
    c.param<std::string>("person", "first",
                         "who is sent: first (the earliest id still in view), largest (the "
                         "biggest in the image), or a person id");
    c.param<bool>("all_people", false,
                  "send everybody, each person to their own port from port on (kept while they "
                  "are seen, given to a new person after release_s)");
    c.param<int>("max_people", 8, "with all_people: ports port .. port + max_people - 1",
                 {1, 1000});
    c.param<double>("release_s", 1.0,
                    "with all_people: a port whose person has not been seen for this long is "
                    "given to the next new person",
                    {0.0, 1e6});
    c.param<double>("fps", 30.0, "frame rate for /VMC/Ext/T when messages carry no capture time",
                    {0.001, 10000.0});
  }

  void open(Context& ctx) override {
    host_ = ctx.param<std::string>("host");
    port_ = ctx.param<int>("port");
    all_ = ctx.param<bool>("all_people");
    max_people_ = ctx.param<int>("max_people");
    fps_ = ctx.param<double>("fps");
    release_s_ = ctx.param<double>("release_s");
    person_ = ctx.param<std::string>("person");
    if (person_ != "first" && person_ != "largest") {
      try {
        std::size_t used = 0;
        fixed_id_ = std::stoi(person_, &used);
        if (used != person_.size()) throw std::invalid_argument(person_);
      } catch (const std::exception&) {
        throw InputError(ctx.node_name(),
                         "person '" + person_ + "' is none of first, largest or a person id");
      }
    }
    if (all_ && port_ + max_people_ - 1 > 65535)
      throw InputError(ctx.node_name(), "port + max_people - 1 is beyond 65535");
    senders_.push_back(std::make_unique<exporting::VmcSender>(host_, port_));
  }

  void process(Context& ctx) override {
    const People3D& people = ctx.input<People3D>("in");
    const double t = time_of(people.header);
    if (all_) {
      for (const Person3D& person : people.people) {
        if (person.id < 0) continue;
        exporting::VmcSender* sender = sender_for(person.id, t);
        if (sender) send(*sender, people, person, t);
      }
      return;
    }
    if (const Person3D* person = choose(people)) send(*senders_[0], people, *person, t);
  }

  void close(Context& ctx) override {
    std::uint64_t bundles = 0, messages = 0, failures = 0;
    for (const auto& s : senders_) {
      bundles += s->bundles_sent(), messages += s->messages_sent(), failures += s->send_failures();
    }
    std::cerr << "sink.vmc '" << ctx.node_name() << "': " << bundles << " bundles, " << messages
              << " messages to " << host_ << ":" << port_;
    if (senders_.size() > 1) std::cerr << " to " << port_ + static_cast<int>(senders_.size()) - 1;
    std::cerr << ", " << failures << " failed sends\n";
  }

 private:
  double time_of(const Header& h) {
    if (!started_) {
      started_ = true;
      first_ns_ = h.capture_ns;
      first_frame_ = h.frame;
    }
    if (h.capture_ns != 0 && first_ns_ != 0)
      return static_cast<double>(h.capture_ns - first_ns_) * 1e-9;
    return static_cast<double>(h.frame - first_frame_) / fps_;
  }

  const Person3D* choose(const People3D& people) {
    const Person3D* best = nullptr;
    if (fixed_id_) {
      for (const Person3D& p : people.people)
        if (p.id == *fixed_id_) best = &p;
      return best;
    }
    if (person_ == "largest") {
      for (const Person3D& p : people.people)
        if (!best || size_of(p) > size_of(*best)) best = &p;
      return best;
    }
    // first: keep the current person while they are in view, else the one seen earliest.
    for (const Person3D& p : people.people) {
      if (p.id < 0) continue;
      first_seen_.emplace(p.id, people.header.frame);
      if (p.id == current_) return &p;
    }
    for (const Person3D& p : people.people) {
      if (p.id < 0) continue;
      if (!best || first_seen_[p.id] < first_seen_[best->id] ||
          (first_seen_[p.id] == first_seen_[best->id] && p.id < best->id))
        best = &p;
    }
    if (best) current_ = best->id;
    return best;
  }

  // The port of a person: theirs while they are seen; a new person takes a port never used or
  // one whose person has been away for release_s; none when every port is busy.
  exporting::VmcSender* sender_for(int id, double t) {
    const auto slot = slots_.find(id);
    if (slot != slots_.end()) {
      slot->second.last_seen = t;
      return senders_[slot->second.port].get();
    }
    int port = static_cast<int>(slots_.size());
    if (port >= max_people_) {
      auto oldest = slots_.end();
      for (auto it = slots_.begin(); it != slots_.end(); ++it)
        if (oldest == slots_.end() || it->second.last_seen < oldest->second.last_seen) oldest = it;
      if (oldest == slots_.end() || t - oldest->second.last_seen < release_s_) return nullptr;
      port = oldest->second.port;
      slots_.erase(oldest);
    }
    slots_.emplace(id, Slot{port, t});
    while (static_cast<int>(senders_.size()) <= port)
      senders_.push_back(
          std::make_unique<exporting::VmcSender>(host_, port_ + static_cast<int>(senders_.size())));
    return senders_[port].get();
  }

  void send(exporting::VmcSender& sender, const People3D& people, const Person3D& person,
            double t) {
    const std::array<glm::vec3, kBodyJoints> world = exporting::world_joints(people, person);
    sender.send(exporting::humanoid_pose(world), t);
  }

  std::string host_, person_;
  int port_ = exporting::kVmcDefaultPort;
  bool all_ = false;
  int max_people_ = 8;
  double fps_ = 30.0;
  std::optional<int> fixed_id_;
  int current_ = -1;
  std::map<int, std::int64_t> first_seen_;  // id -> first frame
  struct Slot {
    int port = 0;  // offset from port_
    double last_seen = 0.0;
  };
  std::map<int, Slot> slots_;  // id -> its port (all_people)
  double release_s_ = 1.0;
  std::vector<std::unique_ptr<exporting::VmcSender>> senders_;
  bool started_ = false;
  std::int64_t first_ns_ = 0, first_frame_ = 0;
};

MOCAP_REGISTER_NODE("sink.vmc", VmcSink)

}  // namespace mocap::nodes
