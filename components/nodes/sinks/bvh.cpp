// sink.bvh: one BVH file per tracked person, on the mocap skeleton of the database clip their
// poses come from (root turned by the matched view), valid on disk after every frame even if the
// run is killed. Policy and file layout: recon/people_bvh_writer.hpp.

#include <iostream>
#include <memory>

#include "graph/registry.hpp"
#include "posedb/database.hpp"
#include "recon/people_bvh_writer.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class BvhSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Writes <dir>/<prefix><id>.bvh per person (database skeleton rotations, root turned by "
        "the matched view); a person's missed frames repeat their last pose");
    c.input<People3D>("in", "reconstructed people with database provenance");
    c.required_param<std::string>("dir", "output folder (created when missing)");
    c.required_param<std::string>("db", "the pose database the people were matched against");
    c.param<std::string>("prefix", "person_", "file name before the person id");
    c.param<bool>("smooth", true, "smooth the joint rotations with the 1-Euro filter");
    c.param<double>("beta", 0.4, "1-Euro cutoff slope for the rotations", {0.0, 100.0});
    c.param<double>("min_cutoff", 1.0, "1-Euro cutoff at rest (Hz) for the rotations",
                    {0.001, 1000.0});
    c.param<int>("min_frames", 12,
                 "frames a person must have before their file is made (shorter ids: no file)",
                 {1, 1000000});
    c.param<double>("fps", 30.0, "input frame rate, written as the BVH frame time",
                    {0.001, 10000.0});
  }

  void open(Context& ctx) override {
    db_ = std::make_unique<posedb::Database>(posedb::Database::open(ctx.param<std::string>("db")));
    recon::PeopleBvhOptions options;
    options.dir = ctx.param<std::string>("dir");
    options.prefix = ctx.param<std::string>("prefix");
    options.fps = ctx.param<double>("fps");
    options.min_frames = ctx.param<int>("min_frames");
    options.smooth_rotations = ctx.param<bool>("smooth");
    options.smoothing.beta = ctx.param<double>("beta");
    options.smoothing.min_cutoff = ctx.param<double>("min_cutoff");
    writer_ = std::make_unique<recon::PeopleBvhWriter>(*db_, std::move(options));
  }

  void process(Context& ctx) override { writer_->write(ctx.input<People3D>("in")); }

  void close(Context& ctx) override {
    if (!writer_) return;
    writer_->close();
    std::cerr << "sink.bvh '" << ctx.node_name() << "': " << writer_->summary().describe() << "\n";
  }

 private:
  std::unique_ptr<posedb::Database> db_;
  std::unique_ptr<recon::PeopleBvhWriter> writer_;
};

MOCAP_REGISTER_NODE("sink.bvh", BvhSink)

}  // namespace mocap::nodes
