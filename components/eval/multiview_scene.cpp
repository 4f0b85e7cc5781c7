#include "eval/multiview_scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace mocap::eval {

namespace {

// Radius of a limb or the torso for occlusion, metres.
constexpr float kBodyRadius = 0.12f;
// Bones plus the sides of the torso: what hides what is behind a person.
constexpr std::array<std::array<int, 2>, 16> kOccluders = {{
    {0, 1},
    {1, 14},
    {2, 1},
    {3, 2},
    {4, 3},
    {5, 1},
    {6, 5},
    {7, 6},
    {8, 14},
    {9, 8},
    {10, 9},
    {11, 14},
    {12, 11},
    {13, 12},
    {2, 8},
    {5, 11},
}};

glm::dmat3 look_at(const glm::dvec3& from, const glm::dvec3& target) {
  const glm::dvec3 forward = glm::normalize(target - from);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0.0, 1.0, 0.0)));
  const glm::dvec3 down = glm::cross(forward, right);
  glm::dmat3 r;  // rows: right, down, forward (GLM: r[column][row])
  for (int c = 0; c < 3; ++c) {
    r[c][0] = right[c];
    r[c][1] = down[c];
    r[c][2] = forward[c];
  }
  return r;
}

float box_height(const SceneDetection& d) {
  float top = std::numeric_limits<float>::max(), bottom = -top;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (!(d.xyc[3 * j + 2] > 0.0f)) continue;
    top = std::min(top, d.xyc[3 * j + 1]);
    bottom = std::max(bottom, d.xyc[3 * j + 1]);
  }
  return bottom > top ? bottom - top : 0.0f;
}

glm::vec2 centre_of(const SceneDetection& d) {
  glm::vec2 sum(0.0f);
  int n = 0;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (!(d.xyc[3 * j + 2] > 0.0f)) continue;
    sum += glm::vec2(d.xyc[3 * j], d.xyc[3 * j + 1]);
    ++n;
  }
  return n > 0 ? sum / static_cast<float>(n) : sum;
}

}  // namespace

std::vector<camera::Camera> ring_rig(int count, double radius_m, double height_m,
                                     double height_step_m, const glm::dvec3& target,
                                     const Image& image) {
  if (count <= 0) throw std::invalid_argument("ring_rig: needs at least one camera");
  const double focal = 0.5 * image.width /
                       std::tan(glm::radians(static_cast<double>(image.horizontal_fov_deg)) / 2.0);
  std::vector<camera::Camera> out;
  for (int i = 0; i < count; ++i) {
    const double a = 2.0 * std::numbers::pi * i / count;
    const glm::dvec3 centre(target.x + radius_m * std::cos(a),
                            height_m + (i % 2 == 1 ? height_step_m : 0.0),
                            target.z + radius_m * std::sin(a));
    camera::Camera c;
    c.name = (i + 1 < 10 ? "cam_0" : "cam_") + std::to_string(i + 1);
    c.width = image.width;
    c.height = image.height;
    c.fx = c.fy = focal;
    c.cx = 0.5 * image.width;
    c.cy = 0.5 * image.height;
    c.rotation = look_at(centre, target);
    c.translation = -(c.rotation * centre);
    out.push_back(c);
  }
  return out;
}

std::optional<Body> ScenePerson::at(int frame) const {
  if (motion == nullptr || (frame >= leave && frame < back)) return std::nullopt;
  const std::size_t m = static_cast<std::size_t>(first_frame + frame);
  if (first_frame + frame < 0 || m >= motion->world.size()) return std::nullopt;
  const glm::vec3 origin = motion->world[static_cast<std::size_t>(first_frame)][index(Joint::root)];
  const float c = std::cos(glm::radians(yaw_deg)), s = std::sin(glm::radians(yaw_deg));
  Body body;
  for (int j = 0; j < kBodyJoints; ++j) {
    const glm::vec3 p = motion->world[m][j] - glm::vec3(origin.x, 0.0f, origin.z);
    body[j] = glm::vec3(c * p.x + s * p.z + place.x, p.y, -s * p.x + c * p.z + place.y);
  }
  return body;
}

namespace {

// The smallest horizontal root distance between `person` and any of `placed` over the frames,
// or -1 when `person` leaves the room.
float clearance(const ScenePerson& person, const std::vector<ScenePerson>& placed, int frames,
                float room_half) {
  float nearest = std::numeric_limits<float>::max();
  for (int f = 0; f < frames; ++f) {
    const auto body = person.at(f);
    if (!body) continue;
    const glm::vec3 root = (*body)[index(Joint::root)];
    if (std::abs(root.x) > room_half || std::abs(root.z) > room_half) return -1.0f;
    for (const ScenePerson& other : placed) {
      const auto o = other.at(f);
      if (!o) continue;
      const glm::vec3 d = (*o)[index(Joint::root)] - root;
      nearest = std::min(nearest, std::hypot(d.x, d.z));
    }
  }
  return nearest;
}

}  // namespace

bool spread_people(std::vector<ScenePerson>& people, int frames, float room_half_m,
                   float min_distance_m, std::uint64_t seed) {
  std::vector<std::pair<glm::vec2, float>> candidates;
  for (float x = -room_half_m; x <= room_half_m + 1e-3f; x += 0.25f) {
    for (float z = -room_half_m; z <= room_half_m + 1e-3f; z += 0.25f) {
      for (int yaw = 0; yaw < 360; yaw += 45)
        candidates.push_back({{x, z}, static_cast<float>(yaw)});
    }
  }
  std::mt19937_64 rng(seed);
  bool all = true;
  std::vector<ScenePerson> placed;
  for (ScenePerson& person : people) {
    std::shuffle(candidates.begin(), candidates.end(), rng);
    float best = -2.0f;
    ScenePerson chosen = person;
    for (const auto& [place, yaw] : candidates) {
      ScenePerson trial = person;
      trial.place = place;
      trial.yaw_deg = yaw;
      const float c = clearance(trial, placed, frames, room_half_m);
      if (c > best) {
        best = c;
        chosen = trial;
      }
      if (c >= min_distance_m) break;
    }
    all = all && best >= min_distance_m;
    person = chosen;
    placed.push_back(person);
  }
  return all;
}

SceneRenderer::SceneRenderer(std::vector<camera::Camera> cameras, std::uint64_t seed)
    : cameras_(std::move(cameras)), rng_(seed), bystanders_(cameras_.size()) {
  for (SceneDetection& b : bystanders_) b.person = -2;  // not made yet
}

SceneRenderer::Projected SceneRenderer::project(const camera::Camera& camera,
                                                const Body& body) const {
  Projected p;
  for (int j = 0; j < kBodyJoints; ++j) {
    const glm::dvec3 c = camera.to_camera(glm::dvec3(body[j]));
    p.depth[j] = static_cast<float>(c.z);
    if (!(c.z > 0.1)) continue;
    const glm::dvec3 n = c / c.z;
    const glm::dvec2 h(camera.fx * n.x + camera.cx, camera.fy * n.y + camera.cy);
    p.pixel[j] = glm::vec2(h);
    p.in_view[j] = h.x >= 0.0 && h.x < camera.width && h.y >= 0.0 && h.y < camera.height;
  }
  return p;
}

bool SceneRenderer::hidden(const camera::Camera& camera, const Projected& who, int joint,
                           const std::vector<Projected>& others, std::size_t self) const {
  const glm::vec2 u = who.pixel[joint];
  const float focal = static_cast<float>(camera.fx);
  for (std::size_t o = 0; o < others.size(); ++o) {
    if (o == self) continue;
    const Projected& q = others[o];
    for (const auto& [a, b] : kOccluders) {
      if (!(q.depth[a] > 0.1f) || !(q.depth[b] > 0.1f)) continue;
      const glm::vec2 ab = q.pixel[b] - q.pixel[a];
      const float len2 = glm::dot(ab, ab);
      const float s =
          len2 > 0.0f ? std::clamp(glm::dot(u - q.pixel[a], ab) / len2, 0.0f, 1.0f) : 0.0f;
      const float depth = q.depth[a] + s * (q.depth[b] - q.depth[a]);
      if (depth > who.depth[joint] - 0.05f) continue;  // not in front of the joint
      if (glm::distance(u, q.pixel[a] + s * ab) < kBodyRadius * focal / depth) return true;
    }
  }
  return false;
}

void SceneRenderer::degrade(SceneDetection& d, const SceneDegradation& g) {
  const float h = box_height(d);
  const float sigma = g.noise * h;
  std::array<float, kBodyJoints* 3> clean = d.xyc;
  for (int j = 0; j < kBodyJoints; ++j) {
    float* k = &d.xyc[3 * j];
    if (!(k[2] > 0.0f)) continue;
    k[0] += sigma * gauss_(rng_);
    k[1] += sigma * gauss_(rng_);
    if (uniform_(rng_) < g.dropout) {
      k[0] = k[1] = std::numeric_limits<float>::quiet_NaN();
      k[2] = 0.0f;
      continue;
    }
    if (!(uniform_(rng_) < g.outliers)) continue;
    const int mirror = kJointMirror[j];
    if (uniform_(rng_) < 0.5f && mirror != j && clean[3 * mirror + 2] > 0.0f) {
      k[0] = clean[3 * mirror] + sigma * gauss_(rng_);  // the other side's joint
      k[1] = clean[3 * mirror + 1] + sigma * gauss_(rng_);
    } else {
      const float angle = 2.0f * std::numbers::pi_v<float> * uniform_(rng_);
      const float r = g.jump * h * (0.5f + 0.5f * uniform_(rng_));
      k[0] += r * std::cos(angle);
      k[1] += r * std::sin(angle);
    }
  }
}

SceneDetection SceneRenderer::false_detection(const SceneFrame& frame,
                                              const camera::Camera& camera) {
  std::vector<const SceneDetection*> real;
  for (const auto& view : frame.views) {
    for (const SceneDetection& d : view) {
      if (d.person >= 0) real.push_back(&d);
    }
  }
  SceneDetection out;
  if (real.empty()) {
    out.person = -2;  // nothing to copy
    return out;
  }
  const SceneDetection& model =
      *real[std::min(real.size() - 1, static_cast<std::size_t>(uniform_(rng_) * real.size()))];
  const glm::vec2 from = centre_of(model);
  const glm::vec2 to(uniform_(rng_) * camera.width, uniform_(rng_) * camera.height);
  const float scale = 0.7f + 0.6f * uniform_(rng_);
  out.person = -1;
  for (int j = 0; j < kBodyJoints; ++j) {
    out.xyc[3 * j] = to.x + scale * (model.xyc[3 * j] - from.x);
    out.xyc[3 * j + 1] = to.y + scale * (model.xyc[3 * j + 1] - from.y);
    out.xyc[3 * j + 2] = model.xyc[3 * j + 2];
  }
  return out;
}

SceneFrame SceneRenderer::render(const std::vector<ScenePerson>& people, int frame,
                                 const SceneDegradation& g) {
  SceneFrame out;
  out.views.resize(cameras_.size());
  for (const ScenePerson& p : people) out.truth.push_back(p.at(frame));
  std::vector<Projected> projected;
  std::vector<std::size_t> who;
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    const camera::Camera& camera = cameras_[c];
    projected.clear();
    who.clear();
    for (std::size_t p = 0; p < people.size(); ++p) {
      if (!out.truth[p]) continue;
      projected.push_back(project(camera, *out.truth[p]));
      who.push_back(p);
    }
    for (std::size_t i = 0; i < projected.size(); ++i) {
      SceneDetection d;
      d.person = static_cast<int>(who[i]);
      int visible = 0;
      for (int j = 0; j < kBodyJoints; ++j) {
        const bool seen = projected[i].in_view[j] &&
                          !(g.occlusion && hidden(camera, projected[i], j, projected, i));
        d.xyc[3 * j] = seen ? projected[i].pixel[j].x : std::numeric_limits<float>::quiet_NaN();
        d.xyc[3 * j + 1] = seen ? projected[i].pixel[j].y : std::numeric_limits<float>::quiet_NaN();
        d.xyc[3 * j + 2] = seen ? 0.6f + 0.4f * uniform_(rng_) : 0.0f;
        visible += seen;
      }
      if (visible < g.min_visible) continue;
      degrade(d, g);
      out.views[c].push_back(d);
    }
  }
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    const bool bystander = std::find(g.bystander_views.begin(), g.bystander_views.end(),
                                     static_cast<int>(c)) != g.bystander_views.end();
    if (bystander) {
      SceneDetection& b = bystanders_[c];
      if (b.person == -2) {
        b = false_detection(out, cameras_[c]);
        // Standing still at the left border of this view alone.
        const glm::vec2 shift =
            glm::vec2(0.05f * cameras_[c].width, 0.5f * cameras_[c].height) - centre_of(b);
        for (int j = 0; j < kBodyJoints; ++j) {
          b.xyc[3 * j] += shift.x;
          b.xyc[3 * j + 1] += shift.y;
        }
      }
      if (b.person == -1) {
        SceneDetection now = b;
        SceneDegradation still;
        still.noise = 0.01f;
        degrade(now, still);
        out.views[c].push_back(now);
      }
    }
    if (uniform_(rng_) < g.false_detections) {
      const SceneDetection f = false_detection(out, cameras_[c]);
      if (f.person == -1) out.views[c].push_back(f);
    }
    std::shuffle(out.views[c].begin(), out.views[c].end(), rng_);
  }
  return out;
}

void SceneRenderer::to_observations(const SceneFrame& frame, multiview::FrameObservations& out) {
  out.reset(static_cast<int>(frame.views.size()), kBodyJoints);
  for (std::size_t v = 0; v < frame.views.size(); ++v) {
    for (const SceneDetection& d : frame.views[v]) out.add_person(static_cast<int>(v), d.xyc);
  }
}

void SceneScorer::add(const SceneFrame& frame, const multiview::FrameResult& result) {
  const std::size_t people = frame.truth.size();
  std::vector<int> views_seen(people, 0);
  for (const auto& view : frame.views) {
    std::vector<char> counted(people, 0);
    for (const SceneDetection& d : view) {
      if (d.person >= 0 && !counted[d.person]) {
        counted[d.person] = 1;
        ++views_seen[d.person];
      }
    }
  }
  for (std::size_t t = 0; t < people; ++t) score_.person_frames += views_seen[t] >= 2;
  if (keep_tracks_) {
    Body none;
    none.fill(glm::vec3(std::numeric_limits<float>::quiet_NaN()));
    for (std::size_t t = 0; t < people && t < tracks_.size(); ++t) {
      tracks_[t].truth.push_back(frame.truth[t]);
      tracks_[t].reconstructed.push_back(none);
    }
  }
  std::vector<char> claimed(people, 0);
  for (std::size_t p = 0; p < result.people.size(); ++p) {
    std::map<int, int> votes;
    const std::span<const int> members = result.detections_of(p);
    for (std::size_t v = 0; v < members.size(); ++v) {
      if (members[v] >= 0) ++votes[frame.views[v][static_cast<std::size_t>(members[v])].person];
    }
    int majority = -1, most = 0;
    for (const auto& [who, count] : votes) {
      if (count > most || (count == most && majority < 0 && who >= 0)) {
        majority = who;
        most = count;
      }
    }
    if (majority < 0) {
      ++score_.false_people;
      ++score_.wrong_associations;
      continue;
    }
    score_.wrong_associations += votes.size() > 1;
    if (claimed[majority]) {
      ++score_.duplicates;
      continue;
    }
    claimed[majority] = 1;
    ++score_.reconstructed;
    const Body& truth = *frame.truth[majority];
    const std::span<const multiview::TriangulatedPoint> body = result.body_of(p);
    for (int j = 0; j < kBodyJoints; ++j) {
      if (!body[j].valid()) continue;
      if (keep_tracks_)
        tracks_[static_cast<std::size_t>(majority)].reconstructed.back()[j] = body[j].position;
      score_.joint_error_sum += glm::distance(body[j].position, truth[j]);
      ++score_.joints;
    }
    const int id = result.people[p].id;
    if (id >= 0) {
      if (last_id_[majority] >= 0 && last_id_[majority] != id) ++score_.id_switches;
      last_id_[majority] = id;
    }
  }
  score_.single_view += static_cast<long>(result.single_view.size());
}

}  // namespace mocap::eval
