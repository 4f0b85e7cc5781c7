#pragma once
// The detector nodes' output: found people as a COCO-17 People2D in frame pixels, untracked, in
// the image of the frame's camera.

#include <string>
#include <vector>

#include "core/messages.hpp"
#include "detect/movenet_decoder.hpp"

namespace mocap::nodes {

inline People2D to_people2d(const std::vector<detect::MovenetPerson>& found,
                            const std::string& camera) {
  People2D out;
  out.camera = camera;
  out.layout = LayoutId::coco17;
  for (const detect::MovenetPerson& p : found) {
    Person2D person;
    person.box = p.box;
    person.joints.assign(p.keypoints.begin(), p.keypoints.end());
    out.people.push_back(std::move(person));
  }
  return out;
}

}  // namespace mocap::nodes
