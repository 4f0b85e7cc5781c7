#pragma once
// Internal to mocap_fit: turning FrameInputs into a window's constants and starting values, and
// a window's solution back into FittedFrames; shared by the full-sequence, windowed and live
// fitters (skeleton_fit.cpp, windowed_fit.cpp). Not part of the library's interface.

#include <optional>
#include <span>

#include <glm/vec3.hpp>

#include "fit/skeleton_fit.hpp"
#include "fit/window_problem.hpp"

namespace mocap::fit::detail {

Bones to_bones(const BoneLengths& b);
BoneLengths from_bones(const Bones& b);
bool usable(const BoneLengths& b);  // every bone positive and finite

// The frame has a retrieved pose (finite): it is observed.
bool observed(const FrameInput& in);

// The camera that saw the frame: its moving camera, else the options' static one.
const camera::Camera& camera_of(const FrameInput& in, const FitOptions& options);

// The constants of a frame; `reference` supplies the bone directions when the frame has no
// retrieved pose of its own.
FrameData frame_data(const FrameInput& in, const Body& reference, const FitOptions& options);

// The body of a solved frame (absolute joints) or an invalid frame.
FittedFrame output(const FrameVars& v, const FrameData& d, const Bones& bones, bool valid);

// options.bones when usable, else the per-bone median of the observed frames' retrieved poses.
BoneLengths initial_bones(std::span<const FrameInput> frames, const FitOptions& options);

// The closed-form root translation of an observed frame (its retrieved pose rebuilt with
// `bones`); nullopt when the keypoints cannot give one or it lies behind the camera.
std::optional<glm::dvec3> start_translation(const FrameInput& in, const BoneLengths& bones,
                                            const FitOptions& options);

// Adds one solve to the statistics.
void count(FitStats& stats, const WindowSummary& solve);

}  // namespace mocap::fit::detail
