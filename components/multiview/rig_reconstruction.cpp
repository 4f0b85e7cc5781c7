#include "multiview/rig_reconstruction.hpp"

#include <cmath>
#include <sstream>

#include <glm/geometric.hpp>

#include "core/input_error.hpp"
#include "core/keypoint_layout.hpp"

namespace mocap::multiview {

ViewGeometry from_camera(const camera::Camera& camera) {
  const std::array<double, 9> k = camera.matrix();  // row-major
  glm::dmat3 K(1.0);                                // GLM: K[col][row]
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) K[c][r] = k[static_cast<std::size_t>(3 * r + c)];
  }
  return ViewGeometry::from_krt(K, camera.rotation, camera.translation, camera.width,
                                camera.height);
}

GroundPlane rig_floor(const camera::Rig& rig, std::string* how) {
  if (rig.floor) {
    if (how) *how = "the rig's floor";
    return *rig.floor;
  }
  const glm::dvec3 up = camera::cameras_up(rig).value_or(glm::dvec3(0.0, 0.0, 1.0));
  int axis = 2;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(up[a]) > std::abs(up[axis])) axis = a;
  }
  GroundPlane floor;
  floor.normal = glm::dvec3(0.0);
  floor.normal[axis] = up[axis] < 0 ? -1.0 : 1.0;
  floor.offset = 0.0;
  if (how) {
    *how = std::string("no floor in the rig: the plane through the world origin, up along ") +
           (up[axis] < 0 ? "-" : "+") + "xyz"[axis] + " (the cameras' mean up)";
  }
  return floor;
}

std::string RigReconstructionCounts::describe(const camera::Rig& rig) const {
  std::ostringstream out;
  out << sets << " frame sets (" << partial_sets << " partial";
  for (std::size_t c = 0; c < missing.size() && c < rig.cameras.size(); ++c) {
    if (missing[c] > 0) out << ", " << rig.cameras[c].name << " missing in " << missing[c];
  }
  out << "), " << people << " person-frames, " << single_view_dropped
      << " single-view detections dropped, " << tentative << " unconfirmed, " << outside
      << " outside the volume";
  return out.str();
}

RigReconstruction::RigReconstruction(camera::Rig rig, std::string rig_name,
                                     ReconstructionOptions options)
    : rig_(std::move(rig)), rig_name_(std::move(rig_name)), options_(options) {
  if (const std::string problem = camera::rig_problem(rig_); !problem.empty())
    throw InputError(rig_name_, problem);
  if (rig_.cameras.size() > static_cast<std::size_t>(kMaxViews))
    throw InputError(rig_name_, std::to_string(rig_.cameras.size()) + " cameras; at most " +
                                    std::to_string(kMaxViews) + " are supported");
  floor_ = rig_floor(rig_);
  counts_.missing.assign(rig_.cameras.size(), 0);
  present_.assign(rig_.cameras.size(), 0);
}

RigReconstruction::~RigReconstruction() = default;

std::size_t RigReconstruction::camera_index(const std::string& name) const {
  const std::optional<std::size_t> index = rig_.index_of(name);
  if (!index) {
    std::string names;
    for (const camera::Camera& c : rig_.cameras) names += (names.empty() ? "" : ", ") + c.name;
    throw InputError(rig_name_, "no camera '" + name + "' in the rig (its cameras: " + names +
                                    "); name each view's camera as the rig does");
  }
  return *index;
}

void RigReconstruction::start(LayoutId keypoints) {
  layout_ = keypoints;
  std::vector<ViewGeometry> views;
  for (const camera::Camera& c : rig_.cameras) views.push_back(from_camera(c));
  keypoint_set_ = KeypointSet::of(layout(keypoints));
  reconstructor_ =
      std::make_unique<MultiViewReconstructor>(std::move(views), keypoint_set_, options_);
}

void RigReconstruction::add_view(std::size_t camera, const People2D& view) {
  if (*layout_ != view.layout) {
    throw InputError(rig_name_, "camera '" + view.camera + "' sends " +
                                    std::string(layout(view.layout).name) +
                                    " keypoints, the other views " +
                                    std::string(layout(*layout_).name) + ": use one detector");
  }
  const camera::Camera& lens = rig_.cameras[camera];
  const int keypoints = observations_.keypoints();
  for (const Person2D& person : view.people) {
    const std::size_t n = std::min(person.joints.size(), static_cast<std::size_t>(keypoints));
    pixels_.resize(n);
    for (std::size_t k = 0; k < n; ++k) pixels_[k] = {person.joints[k].x, person.joints[k].y};
    lens.undistort_pixels(pixels_);
    const std::span<float> xyc = observations_.add_person(static_cast<int>(camera));
    for (std::size_t k = 0; k < n; ++k) {
      const Keypoint2D& joint = person.joints[k];
      if (!usable_keypoint(joint.x, joint.y, joint.confidence)) continue;
      xyc[3 * k] = pixels_[k][0];
      xyc[3 * k + 1] = pixels_[k][1];
      xyc[3 * k + 2] = joint.confidence;
    }
  }
}

void RigReconstruction::solve(std::span<const People2D* const> views, std::int64_t frame,
                              People3D& out) {
  std::fill(present_.begin(), present_.end(), 0);
  // The keypoint layout is the first view's.
  for (const People2D* view : views) {
    if (view && !layout_) start(view->layout);
  }
  out.frame = CoordinateFrame::world();
  out.people.clear();
  out.has_ground = true;
  out.ground = floor_;
  result_ = nullptr;
  if (!layout_) {  // no view at all yet: nothing to solve
    ++counts_.sets;
    ++counts_.partial_sets;
    for (auto& m : counts_.missing) ++m;
    return;
  }
  observations_.reset(static_cast<int>(rig_.cameras.size()),
                      static_cast<int>(layout(*layout_).keypoints.size()));
  for (const People2D* view : views) {
    if (!view) continue;
    const std::size_t camera = camera_index(view->camera);
    if (present_[camera])
      throw InputError(rig_name_, "two views name camera '" + view->camera +
                                      "': give each view its own camera name");
    present_[camera] = 1;
    add_view(camera, *view);
  }
  ++counts_.sets;
  bool partial = false;
  for (std::size_t c = 0; c < present_.size(); ++c) {
    if (!present_[c]) ++counts_.missing[c], partial = true;
  }
  counts_.partial_sets += partial ? 1 : 0;
  result_ = &reconstructor_->process(observations_, frame);
  emit(*result_, out);
}

void RigReconstruction::emit(const FrameResult& result, People3D& out) {
  counts_.single_view_dropped += static_cast<std::int64_t>(result.single_view.size());
  counts_.tentative += result.tentative_people;
  counts_.outside += result.outside_people;
  for (std::size_t p = 0; p < result.people.size(); ++p) {
    const std::span<const TriangulatedPoint> body = result.body_of(p);
    Person3D person;
    person.id = result.people[p].id;
    // The root (mid-hips) when triangulated, else the mean of the joints that are.
    glm::vec3 root = body[index(Joint::root)].position;
    if (!body[index(Joint::root)].valid()) {
      glm::vec3 sum(0.0f);
      int n = 0;
      for (const TriangulatedPoint& t : body) {
        if (t.valid()) sum += t.position, ++n;
      }
      root = n > 0 ? sum / static_cast<float>(n) : glm::vec3(0.0f);
    }
    for (int j = 0; j < kBodyJoints; ++j) {
      person.positions[j] = body[j].valid() ? body[j].position - root : glm::vec3(std::nanf(""));
    }
    person.root.translation = root;
    person.placed = true;
    out.people.push_back(std::move(person));
  }
  counts_.people += static_cast<std::int64_t>(out.people.size());
}

}  // namespace mocap::multiview
