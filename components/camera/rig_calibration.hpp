#pragma once
// Calibrating several cameras together from a board they all film (`mocap calibrate rig`,
// docs/cameras.md "Calibrating a rig from a board"):
//
//   1. the board's corners per camera per frame (the views are in step: frame i of every view was
//      taken at the same instant);
//   2. intrinsics per camera, from its own frames, or given (`RigBoardOptions::intrinsics`);
//   3. the board's pose in every camera that saw it (PnP), then an initial camera graph: relative
//      poses from the frames two cameras share, chained over the spanning tree that keeps the
//      pairs with the most shared frames;
//   4. one bundle adjustment (Ceres, rig_bundle_adjustment.cpp) over all camera poses and board
//      poses (the intrinsics too with `refine_intrinsics`); observations whose error exceeds
//      `outlier_factor` x the median are dropped and the solve repeated;
//   5. the world from the board lying on the floor in `floor_frame`, or in each of `floor_frames`
//      (slid and turned on the floor between them): the floor plane fitted to all their corners
//      in the bundle's frame, origin at the first one's origin and x along its x (both projected
//      onto the plane), z up (away from the floor), metres from the square size.

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "camera/board.hpp"
#include "camera/rig.hpp"

namespace mocap::camera {

// The board as one camera saw it in one frame.
struct BoardObservation {
  std::vector<std::array<double, 3>> object_mm;  // board frame, millimetres, z = 0
  std::vector<std::array<double, 2>> pixels;     // distorted image pixels
};

// What was found in one camera's view (a video or a folder of images).
struct CameraBoardViews {
  std::string name;    // the camera's name in the rig
  std::string source;  // the video or folder, for messages
  int width = 0, height = 0;
  int frames = 0;  // frames in the view (every one counted, whatever the step)
  int tried = 0;   // frames searched for the board
  std::vector<std::optional<BoardObservation>> boards;  // per frame; empty where not found
};

struct RigBoardOptions {
  BoardSpec board;
  int step = 1;         // search every step-th frame of each view
  int min_corners = 6;  // ChArUco: fewer corners in a view -> not found there
  // Intrinsics (matrix, distortion, size) per camera by name; extrinsics are ignored. Empty:
  // each camera is calibrated from its own frames (at least min_intrinsic_views of them).
  std::optional<Rig> intrinsics;
  std::string intrinsics_source = "the intrinsics rig";  // its file, for messages
  int min_intrinsic_views = 4;
  // Also adjust fx fy cx cy k1 k2 (p1 p2) in the bundle (`mocap calibrate rig` always does for
  // intrinsics from the cameras' own frames).
  bool refine_intrinsics = false;
  // Tangential distortion (p1 p2): fitted in a camera's own intrinsics and refined in the
  // bundle, or (false) held: at zero in intrinsics from the camera's own frames, at their given
  // value with `intrinsics`. Held by default: on a board 2-3 m away, filling little of each
  // image, p1 p2 trade against the principal point, and it against the camera's rotation
  // (mocap-bench-rig-board: worst angle 0.26-0.37 degrees with them fitted, 0.10-0.15 held;
  // docs/cameras.md).
  bool tangential_distortion = false;
  // Intrinsics from the cameras' own frames with square pixels (fx = fy, as digital sensors
  // have): one focal length less to trade against each camera's distance. false: fx and fy
  // apart. Given intrinsics keep their fx and fy.
  bool square_pixels = true;
  double outlier_factor = 3.0;  // drop observations with error > factor x median, re-solve
  int outlier_rounds = 2;
  // The frame in which the board lies flat on the floor; -1: the first frame in which any
  // camera of the rig sees the board. Ignored when floor_frames is given.
  int floor_frame = -1;
  // Several frames of the board lying flat on the floor, slid and turned between them: the floor
  // plane is fitted to the corners of all of them (one board seen at a grazing angle tilts the
  // whole world; boards spread over the floor fix the plane by their spread), the origin and x
  // axis come from the first. Empty: floor_frame alone.
  std::vector<int> floor_frames;
  double board_thickness_mm = 0.0;  // the floor is this far below the board's face
  // Cameras that share no frame with the others: refused (InputError naming them), or with
  // `drop_unconnected` left out of the rig (RigCalibration::notes says which).
  bool drop_unconnected = false;
  // Progress of long steps: what (e.g. "cam_02: finding the board"), fraction done in [0, 1].
  std::function<void(const std::string& stage, double fraction)> progress;
};

struct CameraCalibrationReport {
  std::string name;
  int frames_with_board = 0;       // frames in which the board was found
  int observations = 0;            // corners used in the final solve
  int dropped = 0;                 // corners dropped as outliers
  double rms_px = 0.0;             // RMS reprojection error over the corners used
  double intrinsics_rms_px = 0.0;  // of its own intrinsic calibration (0 when given)
};

// How one floor frame's board lies on the fitted floor plane.
struct FloorFrameReport {
  int frame = 0;
  int corners = 0;          // distinct board corners seen in it (by any camera)
  double max_off_mm = 0.0;  // its corner farthest from the plane
  double tilt_deg = 0.0;    // between its board's normal and the plane's
};

struct RigCalibration {
  Rig rig;                                       // cameras in view order, world and floor
  std::vector<CameraCalibrationReport> cameras;  // the same order
  int floor_frame = 0;                           // the first floor frame (origin and x axis)
  std::vector<FloorFrameReport> floor_frames;    // every floor frame, floor_frame first
  int frames_used = 0;             // frames with the board in at least one camera of the rig
  double rms_px = 0.0;             // over all corners used
  std::vector<std::string> notes;  // what a user should know (cameras left out, ...)
};

// Reads each view (a video file, or a folder of images in name order) and finds the board in every
// options.step-th frame. Throws InputError naming the view when it cannot be read (no such file, a
// folder without images, a video that does not open, an image that does not decode or whose size
// differs), and when the views have different frame counts (naming each view's count: the views
// must be in step, so nothing is guessed).
std::vector<CameraBoardViews> find_rig_board(const std::vector<std::string>& views,
                                             const std::vector<std::string>& names,
                                             const RigBoardOptions& options);

// Calibrates the rig from the boards found. Throws InputError naming the camera when the board was
// never (or too rarely, without intrinsics) found in it, with the number of frames tried; naming
// the cameras that share no frame with the others (unless drop_unconnected); naming a floor
// frame that no camera saw the board in, or listed twice; naming a camera missing from
// options.intrinsics or whose size differs there. A floor frame whose board lies more than
// kFloorToleranceMm off the fitted plane gets a note (is it on the floor?).
RigCalibration calibrate_rig(const std::vector<CameraBoardViews>& views,
                             const RigBoardOptions& options);

// Both: the rig from the views.
RigCalibration calibrate_rig_from_board(const std::vector<std::string>& views,
                                        const std::vector<std::string>& names,
                                        const RigBoardOptions& options);

// Farther off the floor plane than this, a floor frame's board gets a note. Chosen a priori, not
// on the benchmark: several times the 1-2 mm to which a board's pose is found 2-3 m away, less
// than a board lifted off the floor by a hand.
inline constexpr double kFloorToleranceMm = 10.0;

// Pieces, public for the tests.
namespace rig_calibration_detail {

// A rigid transform x' = R x + t (R as a Rodrigues vector), metres.
struct Pose {
  std::array<double, 3> rotation{};
  std::array<double, 3> translation{};
};

// One corner seen by one camera in one frame.
struct CornerObservation {
  std::size_t camera = 0;
  std::size_t frame = 0;  // index into the board poses
  std::array<double, 3> object_m{};
  std::array<double, 2> pixel{};
  bool active = true;  // false once dropped as an outlier
};

// A free 3D point (a person's joint in one frame, camera/people_calibration) seen by one camera.
struct PointSighting {
  std::size_t camera = 0;
  std::size_t point = 0;  // index into BundleProblem::points
  std::array<double, 2> pixel{};
  double weight = 1.0;  // the residual's scale (a keypoint's confidence)
  bool active = true;   // false once dropped as an outlier
};

// Two points held `length` apart, the length a free parameter shared by every link of the same
// bone (a person's bones keep their length from frame to frame).
struct LengthLink {
  std::size_t a = 0, b = 0;  // indices into BundleProblem::points
  std::size_t length = 0;    // index into BundleProblem::lengths
};

struct BundleProblem {
  std::vector<Camera> cameras;     // intrinsics; pose ignored (see camera_poses)
  std::vector<Pose> camera_poses;  // world -> camera
  std::vector<Pose> board_poses;   // board -> world
  std::vector<CornerObservation> corners;
  // Free points and their sightings (calibration from people; empty for a board).
  std::vector<std::array<double, 3>> points;  // world, metres
  std::vector<PointSighting> sightings;
  std::vector<double> lengths;  // metres
  std::vector<LengthLink> links;
  double link_weight_px_per_m = 0.0;  // a link's residual: weight x (|a - b| - length)
  // The length held (the scale's gauge: the reprojections do not see the scale, the links would
  // shrink the world to nothing); none: lengths.size().
  std::size_t fixed_length = 0;
  double loss_px = 1.0;          // Huber: past this an error grows linearly
  std::size_t fixed_camera = 0;  // its pose is held (the gauge)
  bool refine_intrinsics = false;
  bool refine_tangential = false;  // with refine_intrinsics: p1 p2 too
  bool square_pixels = false;      // with refine_intrinsics: one focal length, fx = fy
};

// Solves in place (Ceres, rig_bundle_adjustment.cpp); returns the reprojection error (px) of each
// active corner, then of each active sighting, in `errors` (corners.size() + sightings.size();
// inactive: NaN).
void bundle_adjust(BundleProblem& problem, std::vector<double>& errors);

// The world from boards lying flat on the floor: `boards` their poses (board -> the bundle's
// frame), `corners` the board points seen in each (board frame, metres, z = 0). The floor plane is
// the least-squares plane through all the corners (each counted once per board), its normal
// turned to the side the first board's face looks at; the origin is the first board's origin and
// x its x axis, both projected onto the plane; z up. Throws std::invalid_argument when the
// corners do not span a plane (fewer than 3, or all on one line).
struct FloorFit {
  Pose world_from_bundle;
  std::vector<double> max_off_m;  // per board: its corner farthest from the plane
  std::vector<double> tilt_deg;   // per board: its normal against the plane's
};
FloorFit fit_floor(const std::vector<Pose>& boards,
                   const std::vector<std::vector<std::array<double, 3>>>& corners);

// One outlier round: deactivates the corners and sightings whose error exceeds
// max(factor x the median error, floor_px); whether any was.
bool drop_outliers(BundleProblem& problem, const std::vector<double>& errors, double factor,
                   double floor_px);

// Each camera's RMS error over its active observations, with their count and the inactive ones.
struct CameraResiduals {
  int observations = 0, dropped = 0;
  double rms_px = 0.0;
};
std::vector<CameraResiduals> camera_residuals(const BundleProblem& problem,
                                              const std::vector<double>& errors);

}  // namespace rig_calibration_detail
}  // namespace mocap::camera
