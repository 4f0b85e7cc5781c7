#include "recon/sequence_reconstruction.hpp"

#include "posedb/view_set.hpp"
#include "recon/savitzky_golay.hpp"
#include "recon/view_refinement.hpp"

namespace mocap::recon {

std::string_view selection_name(Selection s) {
  switch (s) {
    case Selection::nearest:
      return "nearest";
    case Selection::greedy:
      return "greedy";
    case Selection::path:
      return "path";
  }
  return "?";
}

std::string_view smoothing_name(Smoothing s) {
  switch (s) {
    case Smoothing::none:
      return "none";
    case Smoothing::one_euro:
      return "1euro";
    case Smoothing::savitzky_golay:
      return "savgol";
  }
  return "?";
}

Pose3D pose_in_camera(const posedb::Database& db, const Candidate& chosen) {
  return pose_in_camera(db, chosen, db.views()[chosen.view]);
}

Pose3D pose_in_camera(const posedb::Database& db, const Candidate& chosen,
                      const posedb::View& view) {
  Pose3D pose;
  pose.valid = true;
  pose.chosen = chosen;
  const camera::Camera camera = posedb::view_camera(view, db.build_info().views.root_height_m);
  // The view's rotation was made in float (view_set.cpp): this is that rotation exactly.
  pose.body_to_camera = glm::quat_cast(glm::mat3(camera.rotation));
  const auto j = db.joints(chosen.frame);
  for (int b = 0; b < kBodyJoints; ++b) {
    pose.joints[b] = pose.body_to_camera * glm::vec3(j[3 * b], j[3 * b + 1], j[3 * b + 2]);
  }
  return pose;
}

Pose3D refined_pose_in_camera(const posedb::Database& db, const Candidate& chosen,
                              const posedb::PoseVector& query) {
  const auto j = db.joints(chosen.frame);
  std::array<glm::vec3, kBodyJoints> body;
  for (int b = 0; b < kBodyJoints; ++b) body[b] = {j[3 * b], j[3 * b + 1], j[3 * b + 2]};
  const posedb::View view =
      refine_view(body, query, db.views()[chosen.view], db.build_info().views.root_height_m,
                  db.build_info().scaling);
  return pose_in_camera(db, chosen, view);
}

void turn_onto_ray(Pose3D& pose, const camera::Camera& camera, glm::vec2 root_pixel) {
  const glm::quat turn = ray_alignment(camera, root_pixel);
  for (auto& joint : pose.joints) joint = turn * joint;
  pose.body_to_camera = turn * pose.body_to_camera;
}

namespace {

template <class Filter>
void for_each_run(std::vector<Pose3D>& poses, Filter&& filter) {
  std::size_t start = 0;
  while (start < poses.size()) {
    while (start < poses.size() && !poses[start].valid) ++start;
    std::size_t end = start;
    while (end < poses.size() && poses[end].valid) ++end;
    if (end > start) filter(start, end);
    start = end;
  }
}

}  // namespace

void smooth_sequence(std::vector<Pose3D>& poses, const SequenceOptions& options) {
  if (options.smoothing == Smoothing::none) return;
  if (options.smoothing == Smoothing::one_euro) {
    for_each_run(poses, [&](std::size_t start, std::size_t end) {
      std::array<OneEuroFilterVec3, kBodyJoints> filters;
      filters.fill(OneEuroFilterVec3(options.one_euro));
      for (std::size_t t = start; t < end; ++t) {
        const double seconds = static_cast<double>(t) / options.fps;
        for (int j = 0; j < kBodyJoints; ++j)
          poses[t].joints[j] = filters[j].filter(seconds, poses[t].joints[j]);
      }
    });
    return;
  }
  const SavitzkyGolay sg(options.sg_order, options.sg_window);
  for_each_run(poses, [&](std::size_t start, std::size_t end) {
    std::vector<glm::vec3> track(end - start);
    for (int j = 0; j < kBodyJoints; ++j) {
      for (std::size_t t = start; t < end; ++t) track[t - start] = poses[t].joints[j];
      const auto smoothed = sg.smooth(track);
      for (std::size_t t = start; t < end; ++t) poses[t].joints[j] = smoothed[t - start];
    }
  });
}

std::vector<Pose3D> reconstruct_sequence(Matcher& matcher, const FrameBones& bones,
                                         std::span<const BodyXyc> input,
                                         const SequenceOptions& options) {
  // The keypoints moved onto the canonical joints, for the matcher unless it takes the layout
  // itself (Matcher::set_layout: it needs them as they are), and for the view refinement and
  // the ray alignment in any case.
  const LayoutOffsets* correction = options.layout_offsets ? &*options.layout_offsets
                                    : matcher.layout()     ? &*matcher.layout()
                                                           : nullptr;
  std::vector<BodyXyc> corrected;
  if (correction) {
    corrected.assign(input.begin(), input.end());
    for (BodyXyc& frame : corrected) apply_layout_offsets(*correction, frame);
  }
  const std::span<const BodyXyc> frames = correction ? std::span<const BodyXyc>(corrected) : input;
  const std::span<const BodyXyc> to_match = matcher.layout() ? input : frames;
  std::vector<std::vector<Candidate>> candidates(frames.size());
  for (std::size_t t = 0; t < frames.size(); ++t) matcher.match(to_match[t], candidates[t]);

  std::vector<Pose3D> poses(frames.size());
  const posedb::Database& db = matcher.database();
  if (options.selection == Selection::path) {
    const auto path = best_path(candidates, bones, options.path);
    for (std::size_t t = 0; t < frames.size(); ++t) {
      if (!candidates[t].empty()) poses[t] = pose_in_camera(db, candidates[t][path[t]]);
    }
  } else {
    TemporalSelector selector(bones, options.greedy);
    for (std::size_t t = 0; t < frames.size(); ++t) {
      if (candidates[t].empty()) {
        selector.reset();  // a gap: the next frames start a new history
        continue;
      }
      const std::size_t pick =
          options.selection == Selection::nearest ? 0 : selector.select(candidates[t]);
      poses[t] = pose_in_camera(db, candidates[t][pick]);
    }
  }
  if (options.refine_view) {
    for (std::size_t t = 0; t < frames.size(); ++t) {
      posedb::PoseVector query;
      if (poses[t].valid &&
          normalize_body(frames[t], db.build_info().scaling, matcher.options().scaler, query)) {
        poses[t] = refined_pose_in_camera(db, poses[t].chosen, query);
      }
    }
  }
  if (options.camera.has_intrinsics()) {
    for (std::size_t t = 0; t < frames.size(); ++t) {
      if (!poses[t].valid) continue;
      const glm::vec2 root(frames[t][3 * index(Joint::root)],
                           frames[t][3 * index(Joint::root) + 1]);
      const glm::quat turn = ray_alignment(options.camera, root);
      for (auto& joint : poses[t].joints) joint = turn * joint;
      poses[t].body_to_camera = turn * poses[t].body_to_camera;
    }
  }
  smooth_sequence(poses, options);
  return poses;
}

}  // namespace mocap::recon
