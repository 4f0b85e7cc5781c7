#pragma once
// The views of `mocap calibrate rig --from-people`: OpenPose JSON folders are read as they are;
// videos and image folders are checked against their cameras (image size, frame rate, length),
// then the people in them are found by a detection strategy (detector_presets.hpp, as `mocap
// reconstruct --detector` names them) in one graph, every view's detections written as OpenPose
// JSON (sink.openpose_json) into a folder per camera that a second run takes as its views.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "input_kind.hpp"
#include "io/openpose_json.hpp"

namespace mocap::cli {

struct PeopleViewsOptions {
  std::string detector;                    // a detector preset's name
  std::filesystem::path keypoints;         // where each detected view's folder goes
  bool force = false;                      // detect again over earlier detections
  std::optional<std::int64_t> max_frames;  // the first N frames of every view
  std::optional<double> folder_fps;        // the frame rate of image folders
  bool quiet = false;                      // no progress
};

struct PeopleView {
  std::string path;  // as given
  InputKind kind = InputKind::openpose_json;
  int width = 0, height = 0;   // videos: their frames' size
  bool image_folder = false;   // a folder of images: no frame rate of its own
  double fps = 0.0;            // videos: their rate (image folders: the one given, else 30)
  std::int64_t frames = -1;    // videos: the frames that will be used (-1: not known)
  std::filesystem::path json;  // the OpenPose JSON folder to read (videos: after detect_people)
};

// What each view is; a video, image folder or stream that cannot be opened (missing, empty,
// garbage) is refused naming it. Opens every video once to read its size, rate and length.
std::vector<PeopleView> open_people_views(const std::vector<std::string>& paths,
                                          const PeopleViewsOptions& options);

// Refused (InputError naming the view and its camera): a video whose size is not its camera's,
// videos of different frame rates (image folders have none of their own), videos of different
// lengths.
void check_people_views(const std::vector<PeopleView>& views,
                        const std::vector<camera::Camera>& cameras);

// OpenPose JSON whose keypoints all lie in the top-left quarter of the camera's image (x below
// half its width and y below half its height, every frame): a note naming the view and the
// extent, since keypoints made at half the size or smaller look like that, and the solve cannot
// tell (it moves the camera away instead: docs/cameras.md); empty otherwise. Half size (1920 ->
// 960) is where the extent tells: keypoints resized by 2/3 or 3/4 still reach where a person
// off-centre would put them.
std::string small_keypoints_note(const PeopleView& view, const io::OpenPoseSequence& json,
                                 const camera::Camera& camera);

// Refused (InputError naming the camera and the file of the farthest keypoint): an OpenPose JSON
// view whose keypoints do not fit inside its camera's image. OpenPose JSON carries no image size,
// so the keypoints' extent is the check: more than 1 % of the view's keypoints (and at least 3)
// beyond 10 % of the image's width or height outside its border means the JSON was made from
// images of another size (a swapped width and height, a resized video) or belongs to another
// camera (the views out of the rig's order). The margin and the share allow what detectors do at
// the border (a joint cut off by the frame placed a little outside it) and a stray detection.
// Videos and image folders are checked by their size (check_people_views).
void check_keypoints_fit(const PeopleView& view, const io::OpenPoseSequence& json,
                         const camera::Camera& camera);

// Runs the detector on every video view (frames of each view counted on a progress bar), writing
// options.keypoints / <camera name> / <camera name>_<frame>_keypoints.json, and sets the views'
// `json`. A camera folder holding detections already is refused unless options.force (then only
// its *_keypoints.json files are removed first). Throws InputError when the run fails.
void detect_people(std::vector<PeopleView>& views, const std::vector<camera::Camera>& cameras,
                   const PeopleViewsOptions& options);

}  // namespace mocap::cli
