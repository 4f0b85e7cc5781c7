// recon.matcher: the k nearest database projections of every normalised person, through the
// database's clusters (or an exact scan). Missing joints are left out of the distance.

#include <optional>

#include "graph/registry.hpp"
#include "posedb/database.hpp"
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
  }
  void open(Context& ctx) override {
    db_.emplace(posedb::Database::open(ctx.param<std::string>("db")));
    recon::MatchOptions options;
    options.k = ctx.param<int>("k");
    options.probe = ctx.param<int>("probe");
    options.exact = ctx.param<bool>("exact");
    matcher_.emplace(*db_, options);
  }
  void process(Context& ctx) override {
    PoseMatches out = ctx.input<PoseMatches>("in");
    for (PersonMatch& person : out.people) {
      person.candidates.clear();
      if (!person.normalized_ok) continue;
      posedb::PoseVector query;
      std::copy(person.normalized.begin(), person.normalized.end(), query.begin());
      matcher_->search(query, person.candidates);
    }
    ctx.send("out", std::move(out));
  }

 private:
  std::optional<posedb::Database> db_;
  std::optional<recon::Matcher> matcher_;
};

MOCAP_REGISTER_NODE("recon.matcher", MatcherNode)

}  // namespace mocap::nodes
