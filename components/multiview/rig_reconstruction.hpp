#pragma once
// The multi-view reconstruction on a calibrated rig: what the multiview.reconstruct node and
// `mocap reconstruct --calibration` run per frame set. The glue between the camera model
// (camera::Camera, camera::Rig) and the camera-free library (MultiViewReconstructor): views
// matched to the rig's cameras by the People2D `camera` name, each view's keypoints undistorted
// with its camera's lens, one People3D in the rig's world out (ids = track ids, the 15 body
// joints in metres). Its own CMake target (mocap_multiview_rig), so that mocap_multiview stays
// free of camera types.
//
// People seen by one view only are dropped and counted (the monocular path is not wired here).

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "camera/rig.hpp"
#include "core/messages.hpp"
#include "multiview/reconstructor.hpp"

namespace mocap::multiview {

// The view of a camera: its projection of undistorted pixels and its image size.
ViewGeometry from_camera(const camera::Camera& camera);

// The rig's floor in its world: its own ([metadata.floor], ground_normal) when it has one;
// otherwise the plane through the world origin perpendicular to the world axis (±x, ±y, ±z)
// nearest to the cameras' mean "up" (minus their image y axis), which is z for Pose2Sim's and
// Qualisys' z-up worlds whose origin is on the floor. `how` (optional) says which it was.
GroundPlane rig_floor(const camera::Rig& rig, std::string* how = nullptr);

struct RigReconstructionCounts {
  std::int64_t sets = 0;                 // frame sets solved
  std::int64_t partial_sets = 0;         // sets with at least one view missing
  std::vector<std::int64_t> missing;     // per rig camera: sets without its view
  std::int64_t people = 0;               // person-frames sent
  std::int64_t single_view_dropped = 0;  // detections seen by one view only (dropped)
  std::int64_t tentative = 0;            // people of unconfirmed tracks, left out
  std::int64_t outside = 0;              // people outside the capture volume, left out

  std::string describe(const camera::Rig& rig) const;  // one line for logs
};

class RigReconstruction {
 public:
  // Throws mocap::InputError naming `rig_name` when the rig cannot be used (rig_problem()).
  RigReconstruction(camera::Rig rig, std::string rig_name, ReconstructionOptions options = {});
  ~RigReconstruction();
  RigReconstruction(const RigReconstruction&) = delete;
  RigReconstruction& operator=(const RigReconstruction&) = delete;

  // One frame set: the views present (nullptr: missing), any order; each names its camera.
  // `frame` numbers the set (tracks predict by it). Throws mocap::InputError naming the camera
  // when the rig has no camera of that name or two views name the same one, and naming both
  // layouts when a view's keypoint layout differs from the first view's.
  void solve(std::span<const People2D* const> views, std::int64_t frame, People3D& out);

  const camera::Rig& rig() const { return rig_; }
  const GroundPlane& floor() const { return floor_; }
  const RigReconstructionCounts& counts() const { return counts_; }
  // The last set's undistorted keypoints and result (nullptr before the first view came), and
  // how the keypoints make the 15 body joints: what the skeleton fit takes
  // (fit::MultiViewPeopleFitter).
  const FrameObservations& observations() const { return observations_; }
  const FrameResult* last_result() const { return result_; }
  const KeypointSet& keypoint_set() const { return keypoint_set_; }

 private:
  std::size_t camera_index(const std::string& name) const;
  void start(LayoutId keypoints);
  void add_view(std::size_t camera, const People2D& view);
  void emit(const FrameResult& result, People3D& out);

  camera::Rig rig_;
  std::string rig_name_;
  ReconstructionOptions options_;
  GroundPlane floor_;
  std::optional<LayoutId> layout_;
  std::unique_ptr<MultiViewReconstructor> reconstructor_;
  KeypointSet keypoint_set_;
  const FrameResult* result_ = nullptr;
  FrameObservations observations_;
  std::vector<std::array<float, 2>> pixels_;  // one person's keypoints, undistorted in place
  std::vector<char> present_;
  RigReconstructionCounts counts_;
};

}  // namespace mocap::multiview
