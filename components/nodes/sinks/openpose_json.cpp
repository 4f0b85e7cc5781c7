// sink.openpose_json: every People2D as an OpenPose `*_keypoints.json` file, one per frame (named
// by its frame number, empty frames too), so that detections are kept and read again by
// everything that reads OpenPose JSON (`mocap calibrate rig --from-people`, `mocap reconstruct`,
// source.openpose_json). Each file is written whole (io/openpose_json.hpp).

#include <filesystem>
#include <iostream>

#include "graph/registry.hpp"
#include "io/openpose_json.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class OpenPoseJsonSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Writes each frame's 2D people as an OpenPose JSON file (DIR/STEM_<frame, 12 "
        "digits>_keypoints.json), frames without people included");
    c.input<People2D>("in", "2D people (any layout: written in its keypoint order)");
    c.required_param<std::string>("dir", "the folder (created when absent)");
    c.param<std::string>("stem", "frame", "the files' name before the frame number");
  }

  void open(Context& ctx) override {
    dir_ = ctx.param<std::string>("dir");
    stem_ = ctx.param<std::string>("stem");
    std::filesystem::create_directories(dir_);
  }

  void process(Context& ctx) override {
    const People2D& people = ctx.input<People2D>("in");
    io::write_openpose_file(io::openpose_file_name(dir_, stem_, ctx.current("in").header().frame),
                            people);
    ++frames_;
  }

  void close(Context& ctx) override {
    std::cerr << "sink.openpose_json '" << ctx.node_name() << "': " << frames_ << " frames in "
              << dir_.string() << "\n";
  }

 private:
  std::filesystem::path dir_;
  std::string stem_;
  long long frames_ = 0;
};

MOCAP_REGISTER_NODE("sink.openpose_json", OpenPoseJsonSink)

}  // namespace mocap::nodes
