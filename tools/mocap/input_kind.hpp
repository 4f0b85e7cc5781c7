#pragma once
// What an input path given to a command is: a folder of OpenPose JSON (numbered *.json files), a
// camera (a V4L2 device, a stream URL, or `aravis:ID` for a GigE / USB3 Vision camera), or
// anything else source.video reads (a video file, a folder of images). One classifier for
// `mocap reconstruct`, `reconstruct --calibration` and `calibrate rig --from-people`.

#include <string>
#include <string_view>

namespace mocap::cli {

enum class InputKind { openpose_json, video, camera };

// The prefix of a GigE / USB3 Vision camera: `aravis:` then the id `mocap camera list` shows.
constexpr std::string_view kAravisPrefix = "aravis:";

// Throws InputError naming `path` when it is a folder of neither JSON nor images, or a file that
// does not exist.
InputKind input_kind(const std::string& path);

}  // namespace mocap::cli
