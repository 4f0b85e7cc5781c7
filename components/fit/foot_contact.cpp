#include "fit/foot_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "fit/skeleton_fit.hpp"

namespace mocap::fit {
namespace {

glm::vec3 ankle_world(const posedb::Database& db, std::uint32_t frame, int ankle) {
  const posedb::FrameRecord& r = db.frames()[frame];
  const auto j = db.joints(frame);
  const glm::quat facing = glm::angleAxis(r.heading_rad, glm::vec3(0, 1, 0));
  return facing * glm::vec3(j[3 * ankle], j[3 * ankle + 1], j[3 * ankle + 2]) +
         glm::vec3(r.root_m[0], r.root_m[1], r.root_m[2]);
}

}  // namespace

ContactDetector::ContactDetector(const posedb::Database& db, ContactOptions options)
    : db_(db), options_(options) {
  clip_floor_.assign(db.clips().size(), std::numeric_limits<float>::max());
  const auto frames = db.frames();
  for (std::uint32_t f = 0; f < frames.size(); ++f) {
    const std::uint32_t clip = frames[f].clip;
    if (clip >= clip_floor_.size()) continue;
    for (int ankle : kFeet)
      clip_floor_[clip] = std::min(clip_floor_[clip], ankle_world(db, f, ankle).y);
  }
}

std::array<bool, 2> ContactDetector::contact(std::uint32_t frame) const {
  const auto frames = db_.frames();
  std::array<bool, 2> out{};
  if (frame >= frames.size()) return out;
  const std::uint32_t clip = frames[frame].clip;
  if (clip >= clip_floor_.size()) return out;
  // The neighbouring frame of the same clip (the next one, else the previous one).
  std::uint32_t other = frame;
  if (frame + 1 < frames.size() && frames[frame + 1].clip == clip)
    other = frame + 1;
  else if (frame > 0 && frames[frame - 1].clip == clip)
    other = frame - 1;
  if (other == frame) return out;
  const double fps = db_.build_info().fps;
  for (int s = 0; s < 2; ++s) {
    const glm::vec3 a = ankle_world(db_, frame, kFeet[s]);
    const glm::vec3 b = ankle_world(db_, other, kFeet[s]);
    const double speed = glm::length(b - a) * fps;
    out[s] = speed < options_.max_speed_mps && a.y - clip_floor_[clip] < options_.max_height_m;
  }
  return out;
}

std::vector<std::array<bool, 2>> ContactDetector::contacts(
    std::span<const recon::Pose3D> poses) const {
  std::vector<std::array<bool, 2>> out(poses.size());
  for (std::size_t t = 0; t < poses.size(); ++t)
    if (poses[t].valid) out[t] = contact(poses[t].chosen.frame);
  return out;
}

}  // namespace mocap::fit
