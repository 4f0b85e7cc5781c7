// sink.vmc: the live link. Every People3D message becomes one VMC bundle (OSC over UDP) per
// person sent: root and humanoid bone rotations in Unity's axes (export/humanoid.hpp,
// export/vmc_sender.hpp), at the rate the messages come in (the capture rate). Who is sent, and
// on which port, is export/vmc_people.hpp.
// docs/live-link.md: receiving it in Blender (VMC4B) and Unity (EVMC4U).

#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/input_error.hpp"
#include "export/humanoid.hpp"
#include "export/vmc_people.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

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
    port_ = ctx.param<int>("port");
    const int max_people = ctx.param<int>("max_people");
    all_ = ctx.param<bool>("all_people");
    try {
      choice_.emplace(ctx.param<std::string>("person"));
    } catch (const std::invalid_argument& e) {
      throw InputError(ctx.node_name(), e.what());
    }
    if (all_ && port_ + max_people - 1 > 65535)
      throw InputError(ctx.node_name(), "port + max_people - 1 is beyond 65535");
    clock_.emplace(ctx.param<double>("fps"));
    ports_.emplace(ctx.param<std::string>("host"), port_, max_people,
                   ctx.param<double>("release_s"));
    target_ = ctx.param<std::string>("host") + ":" + std::to_string(port_);
  }

  void process(Context& ctx) override {
    const People3D& people = ctx.input<People3D>("in");
    const double t = clock_->seconds(people.header);
    if (!all_) {
      if (const Person3D* person = choice_->choose(people))
        send(ports_->first_port(), people, *person, t);
      return;
    }
    for (const Person3D& person : people.people) {
      if (person.id < 0) continue;
      if (exporting::VmcSender* sender = ports_->sender_for(person.id, t))
        send(*sender, people, person, t);
    }
  }

  void close(Context& ctx) override {
    const exporting::VmcPorts::Totals sent = ports_->totals();
    std::cerr << "sink.vmc '" << ctx.node_name() << "': " << sent.bundles << " bundles, "
              << sent.messages << " messages to " << target_;
    if (ports_->ports_open() > 1) std::cerr << " to " << port_ + ports_->ports_open() - 1;
    std::cerr << ", " << sent.failures << " failed sends\n";
  }

 private:
  static void send(exporting::VmcSender& sender, const People3D& people, const Person3D& person,
                   double t) {
    sender.send(exporting::humanoid_pose(exporting::world_joints(people, person)), t);
  }

  bool all_ = false;
  int port_ = exporting::kVmcDefaultPort;
  std::string target_;
  std::optional<exporting::VmcPersonChoice> choice_;
  std::optional<exporting::VmcClock> clock_;
  std::optional<exporting::VmcPorts> ports_;
};

MOCAP_REGISTER_NODE("sink.vmc", VmcSink)

}  // namespace mocap::nodes
