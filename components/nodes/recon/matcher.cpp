// recon.matcher: the k nearest database projections of every normalised person, through the
// database's clusters (or an exact scan). Missing joints are left out of the distance.
// With `layout_offsets`, the candidates are re-scored in the input layout's own joint definition
// (Matcher::set_layout, docs/keypoint-layouts.md): the scaler's own `layout_offsets` must then be
// off, since this compares with the keypoints as the detector gave them.

#include <optional>

#include "core/input_error.hpp"
#include "core/keypoint_layout.hpp"
#include "graph/registry.hpp"
#include "posedb/database.hpp"
#include "recon/layout_offsets.hpp"
#include "recon/matcher.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class MatcherNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Finds the k nearest pose-database projections of every person");
    c.input<PoseMatches>("in", "from recon.scaler");
    c.output<PoseMatches>("out", "the same people with their candidates, nearest first");
    c.required_param<std::string>("db", "pose database file");
    c.param<int>("k", 32, "candidates per person", {1, 4096});
    c.param<int>("probe", 16, "clusters scanned per query", {1, 1000000});
    c.param<bool>("exact", false, "scan every projection (slow; for evaluation)");
    c.param<std::string>("layout_offsets", "off",
                         "re-score candidates in the input layout's joint definition: off, a "
                         "layout name (its file in calibration/layouts/, e.g. COCO-17) or a file");
  }
  void open(Context& ctx) override {
    db_.emplace(posedb::Database::open(ctx.param<std::string>("db")));
    recon::MatchOptions options;
    options.k = ctx.param<int>("k");
    options.probe = ctx.param<int>("probe");
    options.exact = ctx.param<bool>("exact");
    matcher_.emplace(*db_, options);
    matcher_->set_layout(layout_offsets(ctx.param<std::string>("layout_offsets")));
  }
  void process(Context& ctx) override {
    PoseMatches out = ctx.input<PoseMatches>("in");
    for (PersonMatch& person : out.people) {
      person.candidates.clear();
      if (!person.normalized_ok) continue;
      if (matcher_->layout()) {
        for (int j = 0; j < kBodyJoints; ++j) {
          body_[3 * j] = person.body[j].x;
          body_[3 * j + 1] = person.body[j].y;
          body_[3 * j + 2] = person.body[j].confidence;
        }
        matcher_->match(body_, person.candidates);
        continue;
      }
      posedb::PoseVector query;
      std::copy(person.normalized.begin(), person.normalized.end(), query.begin());
      matcher_->search(query, person.candidates);
    }
    ctx.send("out", std::move(out));
  }

 private:
  static std::optional<recon::LayoutOffsets> layout_offsets(const std::string& setting) {
    if (setting == "off" || setting.empty()) return std::nullopt;
    if (const KeypointLayout* named = find_layout(setting)) {
      const auto file = recon::find_layout_offsets(named->id);
      if (!file)
        throw InputError(setting, "no offsets file for this layout in calibration/layouts/");
      return recon::load_layout_offsets(*file);
    }
    return recon::load_layout_offsets(setting);
  }

  std::array<float, kBodyJoints * 3> body_{};
  std::optional<posedb::Database> db_;
  std::optional<recon::Matcher> matcher_;
};

MOCAP_REGISTER_NODE("recon.matcher", MatcherNode)

}  // namespace mocap::nodes
