#pragma once
// Motion clips (a BVH skeleton and its frames) as glTF 2.0 binary files (GLB), written with
// tinygltf (docs/export.md).
//
// What a file holds, per figure (a clip; several figures may share a file):
// - a node per joint of the skeleton (End Sites excluded: they carry no rotation), named as the
//   joint (prefixed "<figure>:" when a file holds several figures), parents as in the BVH, the
//   rest translation = the BVH OFFSET in metres, rest rotation identity (the BVH's rest pose);
// - a skin over those joints with inverse bind matrices of that rest pose, and a skinned stick
//   mesh (an octahedron per bone, End Sites included, bound to the bone's parent joint) so that
//   viewers show the figure;
// - in the file's one animation: a rotation channel per joint with rotation channels, a
//   translation channel per joint with position channels (the root), one key per frame at the
//   clip's frame times (LINEAR interpolation; successive quaternions kept in one hemisphere).
// Axes: BVH and glTF are both right-handed with +Y up, so only the units change: file units times
// the figure's metres_per_unit.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "motion/skeleton.hpp"

namespace mocap::exporting {

struct GltfFigure {
  std::string name;  // names the figure's nodes, skin and mesh (e.g. "person_3")
  const motion::Clip* clip = nullptr;
  float metres_per_unit = 0.0f;  // 0: metres_per_unit_of(clip->skeleton)
  double start_seconds = 0.0;    // time of the first key (figures starting later in a shared file)
};

struct GltfOptions {
  bool mesh = true;  // the skinned stick figure; false: joints, skin and animation only
};

struct GltfSummary {
  int figures = 0;
  int joint_nodes = 0;  // over all figures
  int samplers = 0;     // animation samplers (= channels)
  int frames = 0;       // keys per channel of the longest figure
  std::size_t bytes = 0;
};

// Metres per file unit of a skeleton: its family's (motion::map_to_body: CMU cgspeed 0.056444,
// Daz and Bandai 0.01, others guessed from the leg length); 0.01 (centimetres) when the skeleton
// maps onto no body.
float metres_per_unit_of(const motion::Skeleton& skeleton, const std::string& source);

// The GLB bytes of `figures` in one file, one animation for all. Throws std::invalid_argument for
// no figures, a null clip, a clip without joints or frames, or a non-positive frame time.
std::vector<std::uint8_t> make_glb(std::span<const GltfFigure> figures,
                                   const GltfOptions& options = {}, GltfSummary* summary = nullptr);

// make_glb written to `path` through a temporary file renamed into place; throws
// mocap::InputError naming the path when it cannot be written.
GltfSummary write_glb(std::span<const GltfFigure> figures, const std::string& path,
                      const GltfOptions& options = {});

}  // namespace mocap::exporting
