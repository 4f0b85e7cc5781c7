// `mocap export IN.bvh [more.bvh ...] --gltf OUT.glb`: BVH motion as a glTF 2.0 binary file
// (export/gltf_writer.hpp, docs/export.md).

#include <filesystem>
#include <iostream>
#include <vector>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "export/gltf_writer.hpp"
#include "motion/bvh.hpp"
#include "output_files.hpp"

namespace mocap::cli {

int export_command(int argc, char** argv) {
  Args args(
      "mocap export IN.bvh [more.bvh ...] --gltf OUT.glb [--scale auto|S] [--no-mesh]",
      "Writes BVH motion (e.g. the person_<id>.bvh of mocap reconstruct, or any mocap BVH) as "
      "one glTF 2.0 binary file: a node per joint (End Sites excluded) with its rest offset, a "
      "skin and a skinned stick figure, and one animation with a rotation channel per joint and "
      "a translation channel for the root, a key per frame at the file's frame rate (LINEAR). "
      "Several inputs go into the one file, each its own figure, its node names prefixed with "
      "the file's name. Units: metres (--scale auto: the skeleton family's units, CMU cgspeed "
      "0.056444 m, Daz and Bandai cm, others guessed from the leg length); +Y up, right-handed, "
      "as BVH already is. docs/export.md says how to open it in Blender, Unity and three.js.");
  args.positional("IN.bvh", "the motion(s) to export", true)
      .option("gltf", "OUT.glb", "the glTF binary to write (through a temporary file)")
      .option("scale", "auto|S", "metres per BVH unit", "auto", Range::positive().or_word("auto"))
      .flag("no-mesh", "joints, skin and animation only, no stick-figure mesh");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("gltf")) throw InputError("mocap export", "--gltf OUT.glb is required");

  float scale = 0.0f;
  if (args.get("scale") != "auto") scale = static_cast<float>(args.number("scale"));
  std::vector<NamedPath> inputs;
  for (const std::string& path : args.positionals()) inputs.push_back({"IN.bvh", path});
  refuse_output_over_inputs({"--gltf", args.get("gltf")}, inputs);
  std::vector<motion::Clip> clips;
  for (const std::string& path : args.positionals()) {
    clips.push_back(motion::read_bvh(path));
    if (clips.back().frame_count == 0) throw InputError(path, "the motion has no frames");
  }
  std::vector<exporting::GltfFigure> figures;
  for (const motion::Clip& clip : clips)
    figures.push_back({std::filesystem::path(clip.source).stem().string(), &clip, scale});
  exporting::GltfOptions options;
  options.mesh = !args.has("no-mesh");
  const std::string out = args.get("gltf");
  const exporting::GltfSummary summary = exporting::write_glb(figures, out, options);

  for (std::size_t i = 0; i < clips.size(); ++i) {
    const motion::Clip& clip = clips[i];
    const float m =
        scale > 0.0f ? scale : exporting::metres_per_unit_of(clip.skeleton, clip.source);
    std::cout << clip.source << ": " << clip.frame_count << " frames at " << clip.fps() << " fps, "
              << m << " m per unit\n";
  }
  std::cout << "wrote " << out << ": " << summary.figures << " figure(s), " << summary.joint_nodes
            << " joint nodes, " << summary.samplers << " animation channels, " << summary.frames
            << " keys, " << summary.bytes << " bytes\n";
  return 0;
}

}  // namespace mocap::cli
