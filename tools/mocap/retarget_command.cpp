// `mocap retarget IN.bvh --rig TARGET.bvh --out OUT.bvh`: a motion put onto another skeleton
// (motion/retarget.hpp, docs/retargeting.md).

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "motion/bvh.hpp"
#include "motion/retarget.hpp"
#include "output_files.hpp"

namespace mocap::cli {
namespace {

float percentile(std::vector<float> v, double q) {
  if (v.empty()) return 0.0f;
  const auto k = static_cast<std::ptrdiff_t>(std::floor(q * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

}  // namespace

int retarget_command(int argc, char** argv) {
  Args args(
      "mocap retarget IN.bvh --rig TARGET.bvh --out OUT.bvh [--map FILE] [--scale auto|S]",
      "Puts the motion of IN.bvh (any skeleton: our reconstructions, cgspeed CMU, Daz, Bandai, "
      "common rig names) onto the skeleton of TARGET.bvh, taken in its rest pose (its OFFSETs "
      "with zero rotations; its motion is ignored). Joints correspond by role through the "
      "skeleton families (pelvis, spine, chest, neck, head, collars, arms, hands, index fingers, "
      "legs, feet, toes), then by identical names, then by --map. Each mapped joint takes the "
      "source joint's world-space orientation change from rest, aligned so that the bones point "
      "like the source's; unmapped joints keep their rest rotation. The root moves by the "
      "source's root translation times the scale (default: ratio of the hip heights in rest), so "
      "a ground at y = 0 stays there. OUT.bvh has the rig's hierarchy, channel and rotation "
      "orders, and IN.bvh's frames and frame time.");
  args.positional("IN.bvh", "the motion to retarget")
      .option("rig", "TARGET.bvh", "the target skeleton (BVH; a bare HIERARCHY is enough)")
      .option("out", "OUT.bvh", "the retargeted motion (written through a temporary file)")
      .option("map", "FILE",
              "explicit joint pairs, lines 'source_joint target_joint' ('#' comments); they "
              "override the automatic matches (needed for rigs with unknown joint names)")
      .option("scale", "auto|S", "target units per source unit for the root translation", "auto",
              Range::positive().or_word("auto"));
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("rig")) throw InputError("mocap retarget", "--rig TARGET.bvh is required");
  if (!args.has("out")) throw InputError("mocap retarget", "--out OUT.bvh is required");

  const std::string in_path = args.positionals().at(0);
  const std::string rig_path = args.get("rig");
  refuse_output_over_inputs({"--out", args.get("out")},
                            {{"IN.bvh", in_path}, {"--rig", rig_path}, {"--map", args.get("map")}});
  const motion::Clip source = motion::read_bvh(in_path);
  if (source.frame_count == 0) throw InputError(in_path, "the motion has no frames");
  const motion::Skeleton rig = motion::read_rig(rig_path);

  motion::RetargetOptions options;
  options.target_source = rig_path;
  if (args.has("map")) options.map = motion::read_joint_map(args.get("map"));
  if (const std::string scale = args.get("scale"); scale != "auto")
    options.scale = static_cast<float>(args.number("scale"));

  const motion::RetargetResult result = motion::retarget(source, rig, options);
  motion::write_bvh(result.clip, args.get("out"));

  std::ostringstream report;
  report << std::fixed << std::setprecision(3);
  int rig_joints = 0;
  for (const auto& j : rig.joints) rig_joints += j.end_site ? 0 : 1;
  int source_joints = 0;
  for (const auto& j : source.skeleton.joints) source_joints += j.end_site ? 0 : 1;
  report << "retargeted " << in_path << " (" << source_joints << " joints, " << source.frame_count
         << " frames at " << std::setprecision(2) << source.fps() << " fps) onto " << rig_path
         << " -> " << args.get("out") << "\n";
  report << "  joints mapped: " << result.matches.size() << " of " << rig_joints << "\n";
  for (const motion::JointMatch& m : result.matches) {
    report << "    " << std::left << std::setw(16) << rig.joints[m.target].name << " <- "
           << std::setw(16) << source.skeleton.joints[m.source].name << " (" << m.how << ")\n";
  }
  report << "  unmapped (rest rotation): " << result.unmapped_target.size();
  for (std::size_t i = 0; i < result.unmapped_target.size(); ++i)
    report << (i ? ", " : " ") << rig.joints[result.unmapped_target[i]].name;
  report << "\n" << std::setprecision(4);
  report << "  scale: " << result.scale << " target units per source unit ("
         << (result.scale_is_auto ? "auto: hip height " : "given; hip height ")
         << result.target_hip_height << " / " << result.source_hip_height << ")\n";
  const std::vector<float> errors = motion::bone_direction_errors(source, result);
  report << std::setprecision(3) << "  bone directions vs the source (" << result.bones.size()
         << " bones x " << source.frame_count << " frames): median " << percentile(errors, 0.5)
         << " deg, max "
         << (errors.empty() ? 0.0f : *std::max_element(errors.begin(), errors.end())) << " deg\n";
  for (const std::string& warning : result.warnings) report << "  warning: " << warning << "\n";
  std::cout << report.str();
  return 0;
}

}  // namespace mocap::cli
