#include "recon/people_bvh_writer.hpp"

#include <cmath>
#include <exception>
#include <filesystem>
#include <stdexcept>

#include "core/input_error.hpp"

namespace mocap::recon {

std::string PeopleBvhSummary::describe() const {
  return std::to_string(files) + " files, " + std::to_string(frames) + " frames (" +
         std::to_string(held_over_gaps) + " held over gaps), " + std::to_string(skeleton_mismatch) +
         " skeleton_mismatch, " + std::to_string(no_provenance) + " without provenance, " +
         std::to_string(no_skeleton) + " without skeleton, " + std::to_string(short_tracks) +
         " short tracks without a file";
}

PeopleBvhWriter::PeopleBvhWriter(const posedb::Database& db, PeopleBvhOptions options)
    : db_(db), options_(std::move(options)) {
  if (options_.dir.empty() && !options_.in_memory)
    throw InputError("dir", "no output folder given");
  if (!(options_.fps > 0.0) || !std::isfinite(options_.fps))
    throw std::invalid_argument("PeopleBvhWriter: fps must be positive");
  if (options_.max_open_files < 1)
    throw std::invalid_argument("PeopleBvhWriter: max_open_files must be at least 1");
  if (options_.min_frames < 1)
    throw std::invalid_argument("PeopleBvhWriter: min_frames must be at least 1");
  if (options_.in_memory) return;
  std::error_code ec;
  std::filesystem::create_directories(options_.dir, ec);
  if (ec) throw InputError(options_.dir, "cannot create the output folder: " + ec.message());
}

std::string PeopleBvhWriter::path_for(int id) const {
  return (std::filesystem::path(options_.dir) / (options_.prefix + std::to_string(id) + ".bvh"))
      .string();
}

void PeopleBvhWriter::write(const People3D& people) {
  const std::int64_t frame = people.header.frame;
  for (const Person3D& person : people.people) {
    if (person.id < 0) continue;  // not tracked: no identity to give a file
    const auto track = tracks_.find(person.id);
    const std::optional<BvhPlacement> placement = bvh_placement(people, person);
    if (track == tracks_.end()) {
      start(person, frame, placement);
    } else {
      append(track->second, person, frame, placement);
    }
  }
}

void PeopleBvhWriter::start(const Person3D& person, std::int64_t frame,
                            const std::optional<BvhPlacement>& placement) {
  const std::optional<DatabasePose> pose = database_pose_of(db_, person);
  if (!pose) {
    ++summary_.no_provenance;
    return;
  }
  const motion::Skeleton& skeleton = source_skeleton(db_, pose->frame);
  if (skeleton.joints.empty()) {
    ++summary_.no_skeleton;  // position-only motion; a later pose may come from a real clip
    return;
  }
  BvhFrameMaker maker(skeleton, db_.clips()[db_.frames()[pose->frame].clip].source);
  if (options_.smooth_rotations) maker.enable_smoothing(options_.smoothing);
  std::vector<float> values;
  maker.channels(db_, *pose, seconds(frame), values, placement);
  Track& track =
      tracks_
          .emplace(
              person.id,
              Track{std::nullopt, skeleton, std::move(maker), std::move(values), {}, frame, frame})
          .first->second;
  emit(person.id, track);
}

// Writes track.values as the track's next frame: into its file, or held until it has min_frames.
void PeopleBvhWriter::emit(int id, Track& track) {
  if (track.file) {
    if (track.file->is_suspended()) keep_open_files_bounded(id);
    track.file->append(track.values);
    ++summary_.frames;
    return;
  }
  track.pending.push_back(track.values);
  if (options_.in_memory || static_cast<int>(track.pending.size()) < options_.min_frames) return;
  keep_open_files_bounded(id);
  track.file.emplace(path_for(id), track.skeleton, 1.0 / options_.fps);
  ++summary_.files;
  for (const std::vector<float>& values : track.pending) track.file->append(values);
  summary_.frames += static_cast<std::int64_t>(track.pending.size());
  track.pending = {};
}

double PeopleBvhWriter::seconds(std::int64_t frame) const {
  return static_cast<double>(frame) / options_.fps;
}

void PeopleBvhWriter::append(Track& track, const Person3D& person, std::int64_t frame,
                             const std::optional<BvhPlacement>& placement) {
  if (frame == track.last_frame) return;  // the same id twice in one frame: the first one counts
  for (std::int64_t missed = track.last_frame + 1; missed < frame; ++missed) {
    emit(person.id, track);
    ++summary_.held_over_gaps;
  }
  // When this pose cannot be written on the file's skeleton, the previous one is held.
  if (const std::optional<DatabasePose> pose = database_pose_of(db_, person); !pose) {
    ++summary_.no_provenance;
  } else if (!same_hierarchy(source_skeleton(db_, pose->frame), track.maker.skeleton())) {
    ++summary_.skeleton_mismatch;
  } else {
    track.maker.channels(db_, *pose, seconds(frame), track.values, placement);
  }
  emit(person.id, track);
  track.last_frame = frame;
}

// Suspends the open file whose person was seen longest ago when the limit is reached.
void PeopleBvhWriter::keep_open_files_bounded(int arriving_id) {
  int open = 0;
  Track* oldest = nullptr;
  for (auto& [id, track] : tracks_) {
    if (!track.file || !track.file->is_open() || id == arriving_id) continue;
    ++open;
    if (!oldest || track.last_frame < oldest->last_frame) oldest = &track;
  }
  if (open >= options_.max_open_files && oldest) oldest->file->suspend();
}

std::vector<PersonClip> PeopleBvhWriter::take_clips() {
  std::vector<PersonClip> out;
  for (auto& [id, track] : tracks_) {
    if (track.pending.empty()) continue;
    PersonClip& person = out.emplace_back();
    person.id = id;
    person.first_frame = track.first_frame;
    motion::Clip& clip = person.clip;
    clip.source = "person " + std::to_string(id);
    clip.skeleton = track.skeleton;
    clip.skeleton.assign_channel_slots();
    clip.frame_time = 1.0 / options_.fps;
    clip.frame_count = static_cast<int>(track.pending.size());
    for (const std::vector<float>& values : track.pending)
      clip.values.insert(clip.values.end(), values.begin(), values.end());
    track.pending = {};
  }
  return out;
}

void PeopleBvhWriter::close() {
  std::exception_ptr first_error;
  for (auto& [id, track] : tracks_) {
    if (options_.in_memory) {
      const auto frames = static_cast<std::int64_t>(track.pending.size());
      if (frames == 0) continue;
      if (frames < options_.min_frames) {
        ++summary_.short_tracks;
        track.pending = {};
      } else if (!track.counted) {
        track.counted = true;
        ++summary_.files;
        summary_.frames += frames;
      }
      continue;
    }
    if (!track.file) {
      if (!track.pending.empty()) ++summary_.short_tracks;
      track.pending = {};
      continue;
    }
    try {
      track.file->close();
    } catch (...) {
      if (!first_error) first_error = std::current_exception();
    }
  }
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace mocap::recon
