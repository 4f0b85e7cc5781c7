// sink.bvh_joints: one BVH file per person from their 15 joint positions, on a humanoid skeleton
// with the person's bone lengths, y up with the floor at y = 0 (export/joints_bvh.hpp): the
// multi-view reconstruction's people, who come with no pose database.

#include <iostream>
#include <memory>

#include "export/joints_bvh.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class JointsBvhSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Writes <dir>/<prefix><id>.bvh per person from the 15 joints (humanoid skeleton, y up, "
        "the message's floor at y = 0, metres); missed frames repeat the last pose");
    c.input<People3D>("in", "placed people (e.g. multiview.reconstruct's, in the rig's world)");
    c.required_param<std::string>("dir", "output folder (created when missing)");
    c.param<std::string>("prefix", "person_", "file name before the person id");
    c.param<double>("fps", 30.0, "input frame rate, written as the BVH frame time",
                    {0.001, 10000.0});
  }

  void open(Context& ctx) override {
    exporting::JointsBvhOptions options;
    options.dir = ctx.param<std::string>("dir");
    options.prefix = ctx.param<std::string>("prefix");
    options.fps = ctx.param<double>("fps");
    writer_ = std::make_unique<exporting::JointsBvhWriter>(std::move(options));
  }

  void process(Context& ctx) override { writer_->write(ctx.input<People3D>("in")); }

  void close(Context& ctx) override {
    if (!writer_) return;
    writer_->close();
    std::cerr << "sink.bvh_joints '" << ctx.node_name() << "': " << writer_->files()
              << " file(s)\n";
  }

 private:
  std::unique_ptr<exporting::JointsBvhWriter> writer_;
};

MOCAP_REGISTER_NODE("sink.bvh_joints", JointsBvhSink)

}  // namespace mocap::nodes
