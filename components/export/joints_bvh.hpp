#pragma once
// One BVH file per person from their 15 joint positions (no pose database): the multi-view
// reconstruction's people in the rig's world. The skeleton is the humanoid of humanoid.hpp (19
// bones: hips, spine, chest, neck, head, collars, arms, legs) with the bone lengths of the
// person's first frame; each frame's local rotations are the humanoid's swings (no twist about a
// limb), the root translation is where the person is in the world.
//
// The world is turned so that the file is y-up with the floor at y = 0 (BVH's convention): the
// message's floor (People3D::ground, e.g. a z-up Pose2Sim world's z = 0) is rotated onto the
// x-z plane by the smallest rotation taking its normal to +y, and moved to height 0. Metres.
//
// <dir>/<prefix><id>.bvh, written as the run goes (motion::BvhStreamWriter: valid on disk after
// every frame). A person missing for some frames and coming back repeats their last pose over the
// gap, so frame k of a file is input frame (first appearance + k).

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "motion/bvh_stream_writer.hpp"

namespace mocap::exporting {

struct JointsBvhOptions {
  std::string dir;  // created when missing
  std::string prefix = "person_";
  double fps = 30.0;
};

// The 15 joints of a placed person in the BVH's world (y up, floor at y = 0), from a message whose
// `ground` (when has_ground) is its floor; without one the message's frame is taken as y-down
// (a camera's).
std::array<glm::vec3, kBodyJoints> level_joints(const People3D& people, const Person3D& person);

class JointsBvhWriter {
 public:
  // Creates `options.dir`; throws InputError naming it when that fails.
  explicit JointsBvhWriter(JointsBvhOptions options);

  // Appends input frame `people.header.frame` for every person in it. Throws InputError naming the
  // file on a write error.
  void write(const People3D& people);
  void close();  // idempotent; throws the first error

  std::string path_for(int id) const;
  std::int64_t files() const { return static_cast<std::int64_t>(people_.size()); }

 private:
  struct Person {
    motion::BvhStreamWriter writer;
    std::int64_t last_frame = 0;
    std::vector<float> last_values;
  };

  JointsBvhOptions options_;
  std::map<int, Person> people_;
};

}  // namespace mocap::exporting
