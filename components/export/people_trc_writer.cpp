#include "export/people_trc_writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <sstream>
#include <system_error>

#include "core/body15.hpp"
#include "core/input_error.hpp"

namespace mocap::exporting {
namespace {

constexpr std::string_view kIdField = "{id}";

// Pose2Sim's marker names for the joints that are the same point, in Joint order.
constexpr std::array<std::string_view, kBodyJoints> kTrcNames = {
    "Head", "Neck",  "RShoulder", "RElbow", "RWrist", "LShoulder", "LElbow", "LWrist",
    "RHip", "RKnee", "RAnkle",    "LHip",   "LKnee",  "LAnkle",    "Hip"};

glm::vec3 to_trc_axes(const glm::vec3& p, WorldUp up) {
  return up == WorldUp::z ? glm::vec3(p.y, p.z, p.x) : p;
}

}  // namespace

const std::vector<std::string>& trc_marker_names() {
  static const std::vector<std::string> names(kTrcNames.begin(), kTrcNames.end());
  return names;
}

std::string PeopleTrcSummary::describe() const {
  std::ostringstream s;
  s << files << " TRC file(s), " << rows << " rows (" << empty_rows
    << " of frames people were missing in)";
  if (untracked > 0) s << ", " << untracked << " people without an id not written";
  if (out_of_order > 0) s << ", " << out_of_order << " out-of-order frames skipped";
  return s.str();
}

PeopleTrcWriter::PeopleTrcWriter(PeopleTrcOptions options) : options_(std::move(options)) {
  if (options_.path_pattern.find(kIdField) == std::string::npos)
    throw InputError(options_.path_pattern,
                     "the TRC path needs \"{id}\" where each person's id goes (one file per "
                     "person), e.g. out/person_{id}.trc");
  const std::filesystem::path folder = std::filesystem::path(path_for(0)).parent_path();
  std::error_code error;
  if (!folder.empty()) std::filesystem::create_directories(folder, error);
  if (error) throw InputError(folder.string(), "cannot create the TRC folder: " + error.message());
}

std::string PeopleTrcWriter::path_for(int id) const {
  std::string path = options_.path_pattern;
  for (auto at = path.find(kIdField); at != std::string::npos; at = path.find(kIdField, at))
    path.replace(at, kIdField.size(), std::to_string(id));
  return path;
}

PeopleTrcWriter::Person& PeopleTrcWriter::person(int id, std::int64_t frame) {
  auto it = people_.find(id);
  if (it != people_.end()) return it->second;
  limit_open_files(options_.max_open_files - 1);
  io::TrcLayout layout;
  layout.rate = options_.fps;
  layout.markers = trc_marker_names();
  layout.first_frame = frame + 1;
  ++summary_.files;
  return people_
      .emplace(id, Person{io::TrcStreamWriter(path_for(id), std::move(layout)), frame - 1})
      .first->second;
}

// Suspends the files whose people were seen longest ago until at most `keep` are open.
void PeopleTrcWriter::limit_open_files(int keep) {
  std::vector<Person*> open;
  for (auto& [id, p] : people_)
    if (p.file.is_open()) open.push_back(&p);
  if (static_cast<int>(open.size()) <= keep) return;
  std::sort(open.begin(), open.end(),
            [](const Person* a, const Person* b) { return a->last_frame < b->last_frame; });
  for (std::size_t i = 0; i + static_cast<std::size_t>(std::max(keep, 0)) < open.size(); ++i)
    open[i]->file.suspend();
}

void PeopleTrcWriter::write(const People3D& people) {
  if (!people.frame.is_world() && !people.people.empty())
    throw InputError("camera " + people.frame.camera,
                     "TRC files hold people in a rig's world frame (a multi-view "
                     "reconstruction); these are in the camera's own frame");
  const std::int64_t frame = std::max<std::int64_t>(people.header.frame, 0);
  std::array<glm::vec3, kBodyJoints> markers{};
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  for (const Person3D& p : people.people) {
    if (p.id < 0) {
      ++summary_.untracked;
      continue;
    }
    Person& who = person(p.id, frame);
    if (frame <= who.last_frame) {
      ++summary_.out_of_order;
      continue;
    }
    markers.fill(glm::vec3(nan));
    for (std::int64_t gap = who.last_frame + 1; gap < frame; ++gap) {
      who.file.append(markers);
      ++summary_.empty_rows;
      ++summary_.rows;
    }
    const auto joints = joints_in_frame(p);
    for (int j = 0; j < kBodyJoints; ++j)
      markers[static_cast<std::size_t>(j)] =
          to_trc_axes(joints[static_cast<std::size_t>(j)], options_.world_up);
    who.file.append(markers);
    who.last_frame = frame;
    ++summary_.rows;
  }
  limit_open_files(options_.max_open_files);
}

void PeopleTrcWriter::close() {
  std::exception_ptr first;
  for (auto& [id, p] : people_) {
    try {
      p.file.close();
    } catch (...) {
      if (!first) first = std::current_exception();
    }
  }
  if (first) std::rethrow_exception(first);
}

}  // namespace mocap::exporting
