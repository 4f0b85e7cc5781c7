#pragma once
// Foot contact from the retrieved motion: a retrieved pose is a database frame of a mocap clip,
// so its ankles' height over the clip's lowest ankle and their speed within the clip (the
// neighbouring clip frame) are known. An ankle low and slow there is taken to be in contact.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "posedb/database.hpp"
#include "recon/sequence_reconstruction.hpp"

namespace mocap::fit {

struct ContactOptions {
  double max_speed_mps = 0.3;  // ankle speed in the world
  double max_height_m = 0.06;  // ankle height over the clip's lowest ankle
};

class ContactDetector {
 public:
  ContactDetector(const posedb::Database& db, ContactOptions options = {});
  // Right and left ankle (fit::kFeet order) of database frame `frame`.
  std::array<bool, 2> contact(std::uint32_t frame) const;
  // The same for every valid pose of a reconstruction (false for invalid ones).
  std::vector<std::array<bool, 2>> contacts(std::span<const recon::Pose3D> poses) const;

 private:
  const posedb::Database& db_;
  ContactOptions options_;
  std::vector<float> clip_floor_;  // per clip: lowest ankle height
};

}  // namespace mocap::fit
