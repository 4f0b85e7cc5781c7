#pragma once
// Acclaim ASF/AMC, the native format of the CMU Graphics Lab Motion Capture Database: an ASF
// skeleton file and AMC motion files that animate it. The reader turns them into the same Clip
// that BVH gives (BVH-style channels, degrees), so everything downstream works unchanged and
// write_bvh() of the result is a valid BVH of the same motion.
//
// Conventions (Acclaim ASF 1.10 as CMU/Vicon use it; column vectors, R·v):
//  * every bone's `direction`, `axis` and the root's `position`/`orientation` are given in the
//    global frame of the rest pose; a bone starts where its parent bone ends (the root's
//    children start at the root) and ends at start + R_global · direction · length;
//  * `axis a b c XYZ` defines the bone's local frame C = Rz(c)·Ry(b)·Rx(a) (the letters name the
//    order in which the rotations are applied; `ZYX` gives Rx(a)·Ry(b)·Rz(c), and so on);
//  * an AMC line's rotation dofs build M the same way, in the order the dofs are listed
//    (`dof rx ry rz` gives M = Rz·Ry·Rx), and the bone's rotation relative to its parent is
//    C·M·C⁻¹; translation dofs move the bone's start by C·t;
//  * the root's `order` lists its AMC values (rotations applied in the order listed, about the
//    global axes); `position` and `orientation` (rotations in the `axis` order) are read as a
//    fixed offset of all of the motion: root transform = T(position)·O·T(t)·M. The spec leaves
//    open which side the preset applies on; CMU files set both to zero, where it cannot matter.
//
// The Clip has a joint per bone, named as the bone, at the bone's start; joints of bones with
// rotation dofs get the channels Zrotation Yrotation Xrotation (Euler angles of C·M·C⁻¹), bones
// with translation dofs also Xposition Yposition Zposition, bones without dofs no channels; a
// bone without children ends in an End Site ("<bone>_End") at its end point. The root has
// position and rotation channels when the AMC animates them. Lengths stay in ASF units.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "motion/skeleton.hpp"

namespace mocap::motion {

// CMU's ASF length unit to metres: the files say `length 0.45` over a base unit of inches,
// so a length in the file times (1/0.45)·2.54/100 = 0.056444 is metres (CMU FAQ).
inline constexpr double kCmuMetresPerUnit = (1.0 / 0.45) * 2.54 / 100.0;
// AMC files do not store a frame rate; CMU captured almost every trial at 120 Hz (a few at 60).
inline constexpr double kCmuFps = 120.0;

// A degree of freedom as ASF names it (`l`, bone stretching, is recognised but not supported).
enum class AsfDof : std::uint8_t { tx, ty, tz, rx, ry, rz };

// An axis-order token such as XYZ: the axes in the order their rotations are applied (0=X).
using AsfAxisOrder = std::array<std::uint8_t, 3>;

struct AsfBone {
  std::string name;
  int id = 0;
  int parent = -1;            // index into AsfSkeleton::bones, -1 = the root
  glm::dvec3 direction{0.0};  // global rest frame
  double length = 0.0;        // file units
  glm::dvec3 axis{0.0};       // degrees
  AsfAxisOrder axis_order{0, 1, 2};
  std::vector<AsfDof> dofs;  // AMC value order
  // One (min, max) pair per dof, degrees or file length units; may be infinite.
  std::vector<std::pair<double, double>> limits;
};

struct AsfRoot {
  std::vector<AsfDof> order;  // AMC value order of the root
  AsfAxisOrder axis_order{0, 1, 2};
  glm::dvec3 position{0.0};     // file units
  glm::dvec3 orientation{0.0};  // degrees
};

struct AsfSkeleton {
  std::string source;  // file path, for messages
  std::string name;
  double mass_unit = 1.0;
  double length_unit = 1.0;       // CMU: 0.45 (see kCmuMetresPerUnit)
  bool angles_in_degrees = true;  // of the AMC values (angles in this struct are always degrees)
  AsfRoot root;
  std::vector<AsfBone> bones;  // parents first, children in :hierarchy order

  int find(std::string_view bone_name) const;  // -1 when absent
};

// The skeleton of the Clips made from `skeleton` (its rest pose: all channels zero).
Skeleton to_skeleton(const AsfSkeleton& skeleton);

// Parses ASF text; `source` names it in messages. Throws InputError (file:line: reason).
AsfSkeleton parse_asf(std::string_view text, const std::string& source);
// Parses AMC text for `skeleton` into a Clip of `fps` frames per second. Frames are numbered
// consecutively and must give every bone that has dofs exactly once, with one value per dof;
// throws InputError otherwise. Input is capped (1000 bones, 1 GiB files, 50 M joint-frames).
Clip parse_amc(const AsfSkeleton& skeleton, std::string_view text, const std::string& source,
               double fps = kCmuFps);

AsfSkeleton read_asf(const std::string& asf_path);
// Reads an ASF/AMC pair into a Clip (lengths in ASF units, angles in degrees).
Clip read_asf_amc(const std::string& asf_path, const std::string& amc_path, double fps = kCmuFps);

}  // namespace mocap::motion
