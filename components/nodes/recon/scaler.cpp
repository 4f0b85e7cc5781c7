// recon.scaler: the pose database's normalisation applied to each person (root-centred, scaled as
// the database was built), the first step of matching. Joints below `min_confidence` are missing.

#include <optional>

#include "graph/registry.hpp"
#include "posedb/database.hpp"
#include "recon/matcher.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class ScalerNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Maps each person to the 15 body joints and normalises them as the pose database does");
    c.input<People2D>("in", "tracked 2D people, any layout");
    c.output<PoseMatches>("out", "body joints and normalised pose per person (no candidates yet)");
    c.required_param<std::string>("db", "pose database (its normalisation is applied)");
    c.param<double>("min_confidence", 0.05, "keypoints below are treated as missing", {0.0, 1.0});
    c.param<int>("min_joints", 6, "people with fewer present joints are not matched", {3, 15});
  }
  void open(Context& ctx) override {
    scaling_ = posedb::Database::open(ctx.param<std::string>("db"), false).build_info().scaling;
    options_.min_confidence = ctx.param<float>("min_confidence");
    options_.min_joints = ctx.param<int>("min_joints");
  }
  void process(Context& ctx) override {
    const auto& in = ctx.input<People2D>("in");
    const KeypointLayout& lay = layout(in.layout);
    PoseMatches out;
    for (const Person2D& person : in.people) {
      flat_.clear();
      for (const auto& k : person.joints) flat_.insert(flat_.end(), {k.x, k.y, k.confidence});
      std::array<float, kBodyJoints * 3> body;
      to_body15(lay, flat_, body);
      PersonMatch match;
      match.id = person.id;
      match.box = person.box;
      for (int j = 0; j < kBodyJoints; ++j)
        match.body[j] = {body[3 * j], body[3 * j + 1], body[3 * j + 2]};
      posedb::PoseVector normalized;
      match.normalized_ok = recon::normalize_body(body, scaling_, options_, normalized);
      std::copy(normalized.begin(), normalized.end(), match.normalized.begin());
      out.people.push_back(std::move(match));
    }
    ctx.send("out", std::move(out));
  }

 private:
  posedb::Scaling scaling_ = posedb::Scaling::bbox_height;
  recon::ScalerOptions options_;
  std::vector<float> flat_;
};

MOCAP_REGISTER_NODE("recon.scaler", ScalerNode)

}  // namespace mocap::nodes
