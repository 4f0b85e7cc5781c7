// sink.trc: one TRC marker file per tracked person (OpenSim, Pose2Sim), the 15 body joints in the
// rig's world frame, valid on disk after every frame even if the run is killed. Markers, axes and
// frame numbering: export/people_trc_writer.hpp; the file format: io/trc_writer.hpp.

#include <iostream>
#include <memory>

#include "export/people_trc_writer.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TrcSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Writes one TRC marker file per person (the 15 body joints in the rig's world, metres, "
        "Y up as OpenSim wants); frames a person is missing in are empty rows");
    c.input<People3D>("in", "people in the world frame (a multi-view reconstruction)");
    c.required_param<std::string>(
        "path", "file of each person, \"{id}\" replaced by the id (e.g. out/person_{id}.trc)");
    c.param_choice("world_up", "z", {"z", "y"},
                   "the world's up axis: z (Pose2Sim, anipose, Caliscope rigs; turned to Y up as "
                   "Pose2Sim does) or y (written as it is)");
    c.param<double>("fps", 30.0, "input frame rate (DataRate; Time = Frame# / fps)",
                    {0.001, 10000.0});
  }

  void open(Context& ctx) override {
    exporting::PeopleTrcOptions options;
    options.path_pattern = ctx.param<std::string>("path");
    options.fps = ctx.param<double>("fps");
    options.world_up =
        ctx.param<std::string>("world_up") == "y" ? exporting::WorldUp::y : exporting::WorldUp::z;
    writer_ = std::make_unique<exporting::PeopleTrcWriter>(std::move(options));
  }

  void process(Context& ctx) override { writer_->write(ctx.input<People3D>("in")); }

  void close(Context& ctx) override {
    if (!writer_) return;
    writer_->close();
    std::cerr << "sink.trc '" << ctx.node_name() << "': " << writer_->summary().describe() << "\n";
  }

 private:
  std::unique_ptr<exporting::PeopleTrcWriter> writer_;
};

MOCAP_REGISTER_NODE("sink.trc", TrcSink)

}  // namespace mocap::nodes
