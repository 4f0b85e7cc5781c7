// recon.scaler: the pose database's normalisation applied to each person (root-centred, scaled as
// the database was built), the first step of matching. Joints below `min_confidence` are missing.
// With `layout_offsets`, the input layout's keypoints are first moved onto the canonical joint
// centres (recon/layout_offsets.hpp, calibration/layouts/); the corrected joints are what the
// node sends on as `body`.

#include <map>
#include <optional>

#include "graph/registry.hpp"
#include "posedb/database.hpp"
#include "recon/layout_offsets.hpp"
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
    c.param<std::string>("layout_offsets", "off",
                         "move keypoints onto the canonical joints first: off, auto (the input "
                         "layout's file in calibration/layouts/), or a file");
  }
  void open(Context& ctx) override {
    scaling_ = posedb::Database::open(ctx.param<std::string>("db"), false).build_info().scaling;
    options_.min_confidence = ctx.param<float>("min_confidence");
    options_.min_joints = ctx.param<int>("min_joints");
    offsets_setting_ = ctx.param<std::string>("layout_offsets");
    if (offsets_setting_ != "off" && offsets_setting_ != "auto")
      recon::load_layout_offsets(offsets_setting_);  // a bad file fails at start, not mid-stream
  }
  void process(Context& ctx) override {
    const auto& in = ctx.input<People2D>("in");
    const KeypointLayout& lay = layout(in.layout);
    PoseMatches out;
    out.camera = in.camera;
    for (const Person2D& person : in.people) {
      flat_.clear();
      for (const auto& k : person.joints) flat_.insert(flat_.end(), {k.x, k.y, k.confidence});
      std::array<float, kBodyJoints * 3> body;
      to_body15(lay, flat_, body);
      if (const auto* offsets = offsets_for(in.layout)) recon::apply_layout_offsets(*offsets, body);
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
  // The offsets of a layout, loaded the first time it is seen (nullptr: none).
  const recon::LayoutOffsets* offsets_for(LayoutId id) {
    if (offsets_setting_ == "off") return nullptr;
    auto found = offsets_.find(id);
    if (found == offsets_.end())
      found = offsets_.emplace(id, recon::resolve_layout_offsets(offsets_setting_, id)).first;
    return found->second ? &*found->second : nullptr;
  }

  std::string offsets_setting_ = "off";
  std::map<LayoutId, std::optional<recon::LayoutOffsets>> offsets_;
  posedb::Scaling scaling_ = posedb::Scaling::bbox_height;
  recon::ScalerOptions options_;
  std::vector<float> flat_;
};

MOCAP_REGISTER_NODE("recon.scaler", ScalerNode)

}  // namespace mocap::nodes
