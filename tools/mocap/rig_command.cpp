// `mocap rig info RIG` and `mocap rig convert IN OUT`: what a rig file (docs/cameras.md: the
// Pose2Sim/anipose TOML layout or OpenCV YAML) holds, and the same rig in the other format.

#include <iostream>

#include "camera/rig_file.hpp"
#include "camera/rig_report.hpp"
#include "cli_args.hpp"
#include "commands.hpp"

namespace mocap::cli {
namespace {

int info(int argc, char** argv) {
  Args args("mocap rig info RIG",
            "Prints a rig's cameras (name, image size, focal lengths, principal point, "
            "distortion), where they\nare in the world and where they look, the baselines and "
            "the angles between their optical axes\nfor every pair, and the floor (with each "
            "camera's height and tilt above it). RIG: a .toml\n(Pose2Sim, anipose, Caliscope, "
            "FreeMoCap) or OpenCV .yml rig file, or the single-camera file\nof `mocap calibrate "
            "intrinsics`.");
  args.positional("RIG", "the rig file");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const std::string file = args.positionals().at(0);
  const camera::Rig rig = camera::read_rig(file);
  std::cout << file << ": " << camera::rig_report(rig);
  return 0;
}

int convert(int argc, char** argv) {
  Args args("mocap rig convert IN OUT",
            "Reads a rig file and writes the same rig in the format OUT's extension names: .toml "
            "(the\nPose2Sim/anipose layout, our floor in [metadata.floor]) or .yml/.yaml (OpenCV "
            "YAML, a `cameras`\nlist). IN may be either, or the single-camera file of `mocap "
            "calibrate intrinsics`.");
  args.positional("IN", "the rig file to read").positional("OUT", "the rig file to write");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const std::string in = args.positionals().at(0), out = args.positionals().at(1);
  camera::rig_format_for_writing(out);  // a bad extension fails before anything is read
  const camera::Rig rig = camera::read_rig(in);
  camera::write_rig(out, rig);
  if (camera::read_rig(out) != rig) {
    // Not expected: the formats keep every number (shortest round-trip text, %.16e).
    std::cerr << "mocap rig convert: warning: " << out << " does not read back exactly as " << in
              << "\n";
  }
  std::cout << "wrote " << out << ": " << rig.cameras.size() << " camera(s)"
            << (rig.floor ? ", the floor" : "") << "\n";
  return 0;
}

}  // namespace

int rig_command(int argc, char** argv) {
  static constexpr Subcommand kSubcommands[] = {
      {"info", "a rig's cameras, positions, baselines, angles and floor", info},
      {"convert", "a rig file in the other format (TOML <-> OpenCV YAML)", convert},
  };
  return run_subcommand("rig", kSubcommands, argc, argv);
}

}  // namespace mocap::cli
