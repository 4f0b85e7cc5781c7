// recon.smooth_1euro: the 1-Euro filter (Casiez et al. 2012) on every person's joint positions,
// online, no delay. The paper's settings are the defaults (beta 0.4, fc_min 1 Hz).

#include <map>

#include "graph/registry.hpp"
#include "recon/one_euro_filter.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class Smooth1EuroNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Smooths each person's 3D joints with the 1-Euro filter (online)");
    c.input<People3D>("in");
    c.output<People3D>("out");
    c.param<double>("beta", 0.4, "cutoff slope: higher follows fast motion with less lag",
                    {0.0, 100.0});
    c.param<double>("min_cutoff", 1.0, "cutoff at rest (Hz): lower removes more jitter",
                    {0.001, 1000.0});
    c.param<double>("d_cutoff", 1.0, "cutoff of the speed estimate (Hz)", {0.001, 1000.0});
  }
  void open(Context& ctx) override {
    params_.beta = ctx.param<double>("beta");
    params_.min_cutoff = ctx.param<double>("min_cutoff");
    params_.d_cutoff = ctx.param<double>("d_cutoff");
  }
  void process(Context& ctx) override {
    People3D out = ctx.input<People3D>("in");
    const double t = static_cast<double>(out.header.capture_ns) * 1e-9;
    for (Person3D& person : out.people) {
      auto [it, fresh] = filters_.try_emplace(person.id);
      Filters& f = it->second;
      if (fresh) f.joints.fill(recon::OneEuroFilterVec3(params_));
      // A person back after a gap starts afresh rather than being pulled from where it was.
      if (!fresh && out.header.frame - f.last_frame > 1) {
        for (auto& j : f.joints) j.reset();
      }
      f.last_frame = out.header.frame;
      for (int j = 0; j < kBodyJoints; ++j)
        person.positions[j] = f.joints[j].filter(t, person.positions[j]);
    }
    ctx.send("out", std::move(out));
  }

 private:
  struct Filters {
    std::array<recon::OneEuroFilterVec3, kBodyJoints> joints;
    std::int64_t last_frame = 0;
  };
  recon::OneEuroParams params_;
  std::map<int, Filters> filters_;
};

MOCAP_REGISTER_NODE("recon.smooth_1euro", Smooth1EuroNode)

}  // namespace mocap::nodes
