#pragma once
// Measuring a fit against the virtual protocol's truth (library mocap_fit_eval): the cameras'
// poses, the fitter's inputs from a rendered sequence and a reconstruction, truth foot contact,
// and the absolute-position scores the pose metrics of eval/ do not cover (root translation,
// foot skating during contact, ground penetration).

#include <array>
#include <span>
#include <vector>

#include "eval/virtual_protocol.hpp"
#include "fit/foot_contact.hpp"
#include "fit/skeleton_fit.hpp"

namespace mocap::fit {

// The camera of every frame: `lens`'s intrinsics placed in the world by the same joints in both
// frames (the protocol's cameras follow the person, so each frame has its own pose). Rigid
// Procrustes over the joints.
std::vector<camera::Camera> moving_cameras(const camera::Camera& lens,
                                           std::span<const eval::Body> world,
                                           std::span<const eval::Body> camera);

// One FrameInput per frame: keypoints, the retrieved pose where valid, contacts, the frame's
// moving camera (none: the fit's static camera).
std::vector<FrameInput> make_inputs(std::span<const recon::BodyXyc> keypoints,
                                    std::span<const recon::Pose3D> retrieved,
                                    std::span<const std::array<bool, 2>> contacts,
                                    std::span<const camera::Camera> cameras);

// Contact of the truth's ankles (world, y up): slower than max_speed_mps and within max_height_m
// of the clip's lowest ankle.
std::vector<std::array<bool, 2>> truth_contacts(std::span<const eval::Body> world, double fps,
                                                const ContactOptions& options = {});

// The truth's floor: the lowest ankle height (world y) of the clip.
double ankle_floor(std::span<const eval::Body> world);

// Sums, so results of many sequences add up.
struct PlacementScores {
  double frames = 0;
  double root_error_m = 0;  // Σ |root - true root| (camera frame)
  double skate_m = 0;       // Σ horizontal ankle motion between truth-contact frames
  double skate_steps = 0;
  double below_floor_m = 0;      // Σ max(0, floor - ankle height) over ankle-frames
  double below_floor_count = 0;  // ankle-frames more than 1 cm below the floor
  double ankle_frames = 0;
  void add(const PlacementScores& o);
  double root_error_mm() const { return 1000.0 * root_error_m / frames; }
  double skate_cm() const { return 100.0 * skate_m / skate_steps; }
  double penetration_cm() const { return 100.0 * below_floor_m / ankle_frames; }
  double penetrating_percent() const { return 100.0 * below_floor_count / ankle_frames; }
};

// Scores absolute joints (camera frame; invalid frames skipped) against the truth.
PlacementScores score_placement(std::span<const FittedFrame> fitted,
                                std::span<const eval::Body> truth_camera,
                                std::span<const camera::Camera> cameras,
                                std::span<const std::array<bool, 2>> contacts, double floor_y);

// Fitted frames as the protocol's Pose3D (root-relative joints), for eval::score.
std::vector<recon::Pose3D> as_poses(std::span<const FittedFrame> fitted);

}  // namespace mocap::fit
