// `mocap`: the command line of the motion-capture tool.

#include <exception>
#include <iostream>
#include <string_view>

#include "commands.hpp"

namespace {

struct Command {
  std::string_view name;
  std::string_view summary;
  int (*run)(int argc, char** argv);
};

constexpr Command kCommands[] = {
    {"reconstruct",
     "3D motion of every person in a video, camera, stream, image folder or OpenPose JSON",
     mocap::cli::reconstruct_command},
    {"db", "build, inspect and query the 2D-projection pose database", mocap::cli::db_command},
    {"run", "run a graph file (nodes wired by YAML), in one or several processes",
     mocap::cli::run_command},
    {"graph", "validate a graph file, inspect node types, export Graphviz",
     mocap::cli::graph_command},
    {"eval", "measure accuracy: virtual-video and HumanEva-I protocols", mocap::cli::eval_command},
    {"camera", "GigE/USB3 Vision cameras (Aravis): list them, grab frames to files",
     mocap::cli::camera_command},
    {"calibrate", "keypoint layout offsets (calibration/layouts/) and camera intrinsics",
     mocap::cli::calibrate_command},
    {"rig", "camera rigs (TOML, OpenCV YAML): what a rig file holds, convert between formats",
     mocap::cli::rig_command},
    {"retarget", "put a BVH motion onto another skeleton (rig given in its rest pose)",
     mocap::cli::retarget_command},
    {"keys", "CURVE key pairs for graph edges and endpoints that cross the network",
     mocap::cli::keys_command},
    {"view", "people in 3D in the browser: a poses.jsonl with a timeline, or a live graph",
     mocap::cli::view_command},
    {"export", "BVH motion as a glTF 2.0 binary (GLB): joints, skin, animation",
     mocap::cli::export_command},
};

void print_usage(std::ostream& out) {
  out << "usage: mocap COMMAND [ARGS...]\n\n"
         "Markerless motion capture: video or 2D keypoints in, 3D motion of every person out.\n\n"
         "commands:\n";
  for (const auto& c : kCommands) {
    out << "  " << c.name << std::string(14 - c.name.size(), ' ') << c.summary << "\n";
  }
  out << "\nRun 'mocap COMMAND --help' for the options of a command.\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_usage(std::cerr);
    return 2;
  }
  const std::string_view name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    print_usage(std::cout);
    return 0;
  }
  if (name == "--version") {
    std::cout << "mocap " MOCAP_VERSION "\n";
    return 0;
  }
  for (const auto& c : kCommands) {
    if (c.name != name) continue;
    try {
      return c.run(argc - 2, argv + 2);
    } catch (const std::exception& e) {
      std::cerr << "mocap " << name << ": error: " << e.what() << "\n";
      return 1;
    }
  }
  std::cerr << "mocap: unknown command '" << name << "'\n\n";
  print_usage(std::cerr);
  return 2;
}
