#pragma once
// The HumanEva-I protocol as published methods report it (../shared/docs/EVALUATION.md): the
// ground-truth 2D of the Validate split in (cameras C1–C3, with the virtual protocol's noise
// levels), PA-MPJPE per subject (S1–S3) and action (Walk, Jog, Box) against the 3D truth in the
// camera's frame, plus MPJPE and acceleration error.
//
// Joints: every Body15 joint is one HumanEva-15 joint (core/keypoint_layout.cpp), none is
// derived or dropped. HumanEva's pelvis (torsoDistal) is not the mid-hip point the CMU database
// calls root, and its head is headDistal: with the CMU database that is part of the error, the
// honest cross-dataset case (issue 11 corrects layouts).
//
// Frame rate: HumanEva is 60 Hz, the database 24 fps. The 2D input and the 3D truth are both
// resampled to the database rate by linear interpolation (motion::resample_points, the rule of
// the database builder), so the temporal selector sees frames as far apart as the database's,
// noise is added per evaluated frame, and the acceleration error is in mm/frame² at that rate.

#include <array>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "eval/virtual_protocol.hpp"
#include "io/humaneva.hpp"
#include "posedb/builder.hpp"
#include "recon/sequence_reconstruction.hpp"

namespace mocap::eval {

// An action as the published tables name it and as the data names it.
struct HumanEvaAction {
  std::string_view label;
  std::string_view data_name;
};
inline constexpr std::array<HumanEvaAction, 3> kHumanEvaActions = {
    {{"Walk", "Walking"}, {"Jog", "Jog"}, {"Box", "Box"}}};
inline constexpr std::array<std::string_view, 3> kHumanEvaSubjects = {"S1", "S2", "S3"};

// HumanEva's world has Z up, the project's y up: a rotation by −90° about X, (X, Y, Z) →
// (X, Z, −Y). A rotation, not a mirror, so a subject facing +Z keeps the left on +X.
glm::mat3 humaneva_world_to_y_up();

// One line per Body15 joint: the HumanEva-15 joint it is, and how HumanEva made that joint.
std::vector<std::string> humaneva_joint_correspondence();

// The chunks of `split` for the given actions (data names) as position-only motion for the
// database builder: Body15 joints, y up, 60 Hz.
std::vector<posedb::BodySequence> humaneva_body_sequences(
    const io::humaneva::Dataset& dataset, io::humaneva::Split split,
    const std::vector<std::string_view>& actions);

// Subject -> the rig of its cameras C1..C3 (io::humaneva::load_cameras).
using HumanEvaCameras = std::map<std::string, camera::Rig>;

// One Validate chunk seen by one camera, at the evaluation rate.
struct HumanEvaSequence {
  std::string subject;                // "S1"
  std::string action;                 // label: "Walk", "Jog", "Box"
  std::string chunk;                  // as in the data: "Walking 1 chunk0"
  camera::Camera camera;              // "C1": the (approximate, fitted) pinhole and its pose
  std::vector<recon::BodyXyc> input;  // ground-truth 2D, pixels, confidence 1, no noise
  std::vector<Body> truth_camera;     // camera frame (x right, y down, z forward), metres
};

// Every Validate chunk of the evaluated subjects and actions through every camera, resampled
// from 60 Hz to `fps`. Throws InputError when a subject has no cameras.
// `split` Train gives the same for the Train chunks (for choosing settings on Train only).
std::vector<HumanEvaSequence> humaneva_validation_sequences(
    const io::humaneva::Dataset& dataset, const HumanEvaCameras& cameras, double fps,
    io::humaneva::Split split = io::humaneva::Split::validate);

// The sequence's 2D input with the condition's noise, from the random stream `seed` starts:
// what evaluate_sequence reconstructs, and what the multi-view protocol (humaneva_multiview.hpp)
// gives each camera, so both see the same 2D.
std::vector<recon::BodyXyc> noisy_input(const HumanEvaSequence& sequence,
                                        const Condition& condition, std::uint64_t seed);

// Adds the condition's noise to the input (noisy_input), reconstructs it and scores it against
// the truth.
// With `map_back` and `mapped`, the reconstruction is also scored after moving its canonical
// joints to where the layout puts them (recon::apply_layout_offsets_3d, direction -1): the
// truth is in HumanEva-15's own definition (thorax, pelvis, headDistal), not the canonical one.
Scores evaluate_sequence(recon::Matcher& matcher, const recon::FrameBones& bones,
                         const HumanEvaSequence& sequence, const Condition& condition,
                         const recon::SequenceOptions& options, std::uint64_t seed,
                         const recon::LayoutOffsets* map_back = nullptr, Scores* mapped = nullptr);

// Scores per (subject, action) cell, as the published tables.
class HumanEvaTable {
 public:
  void add(const HumanEvaSequence& sequence, const Scores& scores);
  // Empty Scores when nothing was added for the cell.
  Scores cell(std::string_view subject, std::string_view action) const;
  Scores all() const;  // every frame of every cell
  // The unweighted mean of the cells' PA-MPJPE, the "average" column of the published tables.
  double mean_cell_pa_mpjpe() const;

 private:
  std::map<std::pair<std::string, std::string>, Scores> cells_;
};

}  // namespace mocap::eval
