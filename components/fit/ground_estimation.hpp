#pragma once
// The floor from the people in view (issue 7: "the ground plane ... estimated from the feet of the
// people in view over time"), for a static camera without a calibrated ground.
//
// The floor's normal is the direction in which the floor contacts do not spread: the contact
// ankles lie on the floor (they spread along it, by the strides and the walk), and the line
// through the hips is level on average (it spans the floor's other direction even when a person
// walks along one line). The normal is the least-spread direction of both together; the mean
// direction from the root (mid-hips) to the neck tells up from down (and is the normal itself when
// the contacts are too few to span the floor: it leans a few degrees with a walking person). The
// height: a contact ankle is `clearance` above the floor, so the median height of the contact
// ankles along the normal places the plane.

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "fit/skeleton_fit.hpp"

namespace mocap::fit {

struct GroundEstimationOptions {
  double ankle_clearance_m = 0.07;  // the ankle joint's height over the sole
  std::size_t min_bodies = 15;      // bodies before an estimate (the upright cue)
  std::size_t min_contacts = 20;    // contact ankles before an estimate (the height)
  double hip_line_weight_m = 0.3;   // a hip direction counts as a spread of this many metres
  double max_tilt_from_upright_deg = 30.0;  // a normal further from the upright cue is refused
  std::size_t max_samples = 4000;           // oldest samples dropped beyond this (bounded memory)
};

struct GroundEstimate {
  GroundPlane plane;                  // camera frame (the fit's world for a static camera)
  bool normal_from_contacts = false;  // contacts and hip lines (else the upright cue alone)
  std::size_t bodies = 0, contacts = 0;
};

class GroundEstimator {
 public:
  explicit GroundEstimator(GroundEstimationOptions options = {});

  // One fitted body (absolute joints, camera frame, metres) and which ankles (kFeet order) are in
  // contact with the floor in that frame.
  void add(const Body& joints, std::array<bool, 2> contact);

  // nullopt until there are enough bodies and contacts.
  std::optional<GroundEstimate> estimate() const;

  std::size_t bodies() const { return ups_.size(); }
  std::size_t contacts() const { return ankles_.size(); }

 private:
  GroundEstimationOptions options_;
  std::vector<glm::dvec3> ups_;     // unit root -> neck directions
  std::vector<glm::dvec3> ankles_;  // contact ankle positions
  std::vector<glm::dvec3> hips_;    // unit right hip -> left hip directions
  std::size_t next_up_ = 0, next_ankle_ = 0, next_hip_ = 0;  // ring positions once full
};

}  // namespace mocap::fit
