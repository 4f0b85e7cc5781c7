#include "eval/layout_calibration.hpp"

#include <charconv>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "core/input_error.hpp"
#include "io/read_file.hpp"

namespace mocap::eval {

namespace {

using recon::OffsetBasis;
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

bool finite(const glm::vec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

glm::vec3 mid(const glm::vec3& a, const glm::vec3& b) { return 0.5f * (a + b); }

glm::vec3 unit(const glm::vec3& v) {
  const float n = glm::length(v);
  return n > 0.0f ? v / n : glm::vec3(kNan);
}

constexpr int kRs = index(Joint::right_shoulder), kLs = index(Joint::left_shoulder);
constexpr int kRh = index(Joint::right_hip), kLh = index(Joint::left_hip);

// Neck, head and root of the canonical body from its shoulder and hip centres.
void canonical_axial_joints(Joints3& r) {
  const glm::vec3 shoulders = mid(r[kRs], r[kLs]);
  const glm::vec3 hips = mid(r[kRh], r[kLh]);
  const glm::vec3 up = unit(shoulders - hips);
  r[index(Joint::neck)] = shoulders + kCanonicalNeckAboveShoulders * up;
  r[index(Joint::head)] = shoulders + kCanonicalHeadAboveShoulders * up;
  r[index(Joint::root)] = hips;
}

class Markers {
 public:
  Markers(const io::TrcFile& trc) : trc_(trc) {}
  glm::vec3 get(std::size_t frame, std::string_view name) const {
    const auto m = trc_.marker(name);
    if (!m) throw InputError(trc_.path, "no marker '" + std::string(name) + "'");
    return trc_.frames[frame][*m];
  }
  glm::vec3 mid(std::size_t frame, std::string_view a, std::string_view b) const {
    return eval::mid(get(frame, a), get(frame, b));
  }

 private:
  const io::TrcFile& trc_;
};

// Body frame of a reference body: up (hips to shoulders), left, forward.
bool body_frame(const Joints3& r, glm::vec3& up, glm::vec3& left, glm::vec3& forward) {
  for (int k : {kRs, kLs, kRh, kLh})
    if (!finite(r[k])) return false;
  up = unit(mid(r[kRs], r[kLs]) - mid(r[kRh], r[kLh]));
  const glm::vec3 l = r[kLs] - r[kRs];
  left = unit(l - glm::dot(l, up) * up);
  forward = glm::cross(left, up);
  return finite(up) && finite(left);
}

// The model's vectors for joint j from the layout keypoints: false when one is missing.
bool model_vectors(OffsetBasis basis, int j, const Joints3& k, glm::vec3& v1, glm::vec3& v2,
                   glm::vec3& v3) {
  if (basis == OffsetBasis::bone) {
    const int parent = kJointParent[j];
    if (parent < 0 || !finite(k[j]) || !finite(k[parent])) return false;
    v1 = k[j] - k[parent];
    v2 = v3 = glm::vec3(0.0f);
    return true;
  }
  for (int q : {kRs, kLs, kRh, kLh})
    if (!finite(k[q])) return false;
  v1 = mid(k[kRs], k[kLs]) - mid(k[kRh], k[kLh]);
  v2 = basis == OffsetBasis::shoulders ? k[kLs] - k[kRs] : k[kLh] - k[kRh];
  const float n = glm::length(v2);
  v3 = n > 0.0f ? glm::cross(v2, v1) / n : glm::vec3(0.0f);
  return true;
}

double det3(const std::array<std::array<double, 3>, 3>& m) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// Cramer's rule for the 3x3 normal equations.
std::array<double, 3> solve3(const std::array<std::array<double, 3>, 3>& m,
                             const std::array<double, 3>& r) {
  const double d = det3(m);
  std::array<double, 3> x{};
  if (std::abs(d) < 1e-300) return x;
  for (int c = 0; c < 3; ++c) {
    auto mc = m;
    for (int row = 0; row < 3; ++row) mc[row][c] = r[row];
    x[c] = det3(mc) / d;
  }
  return x;
}

}  // namespace

std::vector<CalibrationFrame> pose2sim_frames(const io::TrcFile& trc, LayoutId layout) {
  if (layout == LayoutId::humaneva15)
    throw InputError(trc.path, "Pose2Sim has BODY_25B keypoints, not HumanEva-15");
  const Markers m(trc);
  std::vector<CalibrationFrame> out;
  for (std::size_t f = 0; f < trc.frames.size(); ++f) {
    CalibrationFrame c;
    Joints3& k = c.keypoints;
    k[index(Joint::right_shoulder)] = m.get(f, "RShoulder");
    k[index(Joint::right_elbow)] = m.get(f, "RElbow");
    k[index(Joint::right_wrist)] = m.get(f, "RWrist");
    k[index(Joint::left_shoulder)] = m.get(f, "LShoulder");
    k[index(Joint::left_elbow)] = m.get(f, "LElbow");
    k[index(Joint::left_wrist)] = m.get(f, "LWrist");
    k[index(Joint::right_hip)] = m.get(f, "RHip");
    k[index(Joint::right_knee)] = m.get(f, "RKnee");
    k[index(Joint::right_ankle)] = m.get(f, "RAnkle");
    k[index(Joint::left_hip)] = m.get(f, "LHip");
    k[index(Joint::left_knee)] = m.get(f, "LKnee");
    k[index(Joint::left_ankle)] = m.get(f, "LAnkle");
    k[index(Joint::root)] = m.mid(f, "RHip", "LHip");
    if (layout == LayoutId::body25b) {
      k[index(Joint::head)] = m.get(f, "Head");  // BODY_25B HeadTop
      k[index(Joint::neck)] = m.get(f, "Neck");  // BODY_25B UpperNeck
    } else {
      k[index(Joint::head)] = glm::vec3(kNan);  // ear midpoint: no ears in 3D here
      k[index(Joint::neck)] = m.mid(f, "RShoulder", "LShoulder");  // OpenPose Neck / COCO mid
    }
    Joints3& r = c.reference;
    const glm::vec3 acromion_r = m.get(f, "r_shoulder_study");
    const glm::vec3 acromion_l = m.get(f, "L_shoulder_study");
    const glm::vec3 rhjc = m.get(f, "RHJC_study"), lhjc = m.get(f, "LHJC_study");
    const glm::vec3 up_acromion = unit(mid(acromion_r, acromion_l) - mid(rhjc, lhjc));
    const float drop = kAcromionToShoulderCentre * glm::length(acromion_r - acromion_l);
    r[kRs] = acromion_r - drop * up_acromion;
    r[kLs] = acromion_l - drop * up_acromion;
    r[kRh] = rhjc;
    r[kLh] = lhjc;
    r[index(Joint::right_elbow)] = m.mid(f, "r_lelbow_study", "r_melbow_study");
    r[index(Joint::right_wrist)] = m.mid(f, "r_lwrist_study", "r_mwrist_study");
    r[index(Joint::left_elbow)] = m.mid(f, "L_lelbow_study", "L_melbow_study");
    r[index(Joint::left_wrist)] = m.mid(f, "L_lwrist_study", "L_mwrist_study");
    r[index(Joint::right_knee)] = m.mid(f, "r_knee_study", "r_mknee_study");
    r[index(Joint::right_ankle)] = m.mid(f, "r_ankle_study", "r_mankle_study");
    r[index(Joint::left_knee)] = m.mid(f, "L_knee_study", "L_mknee_study");
    r[index(Joint::left_ankle)] = m.mid(f, "L_ankle_study", "L_mankle_study");
    canonical_axial_joints(r);
    out.push_back(c);
  }
  return out;
}

std::vector<CalibrationFrame> humaneva_frames(const io::humaneva::Dataset& data,
                                              io::humaneva::Split split) {
  std::vector<CalibrationFrame> out;
  for (const io::humaneva::Chunk* chunk : data.select(split)) {
    for (const io::humaneva::Pose3& pose : chunk->positions_3d) {
      CalibrationFrame c;
      c.keypoints = io::humaneva::to_body15(pose);
      c.reference = c.keypoints;
      canonical_axial_joints(c.reference);
      out.push_back(c);
    }
  }
  return out;
}

std::array<OffsetBasis, kBodyJoints> default_bases(LayoutId layout) {
  std::array<OffsetBasis, kBodyJoints> b;
  b.fill(layout == LayoutId::humaneva15 ? OffsetBasis::none : OffsetBasis::bone);
  for (Joint j : {Joint::head, Joint::neck}) b[index(j)] = OffsetBasis::shoulders;
  b[index(Joint::root)] = OffsetBasis::hips;
  if (layout != LayoutId::humaneva15) {
    b[kRs] = b[kLs] = OffsetBasis::shoulders;
    b[kRh] = b[kLh] = OffsetBasis::hips;
  }
  return b;
}

LayoutFit fit_layout_offsets(LayoutId layout, std::span<const CalibrationFrame> frames,
                             const std::array<OffsetBasis, kBodyJoints>& bases) {
  LayoutFit fit;
  fit.offsets.layout = layout;
  fit.offsets.source = "fitted";
  for (int j = 0; j < kBodyJoints; ++j) {
    const OffsetBasis basis = bases[j];
    if (basis == OffsetBasis::none) continue;
    // Normal equations of min |d - a v1 - b v2 - c v3|^2.
    std::array<std::array<double, 3>, 3> m{};
    std::array<double, 3> r{};
    double len1 = 0, len2 = 0, len3 = 0;
    int n = 0;
    for (const CalibrationFrame& c : frames) {
      glm::vec3 v1, v2, v3;
      if (!finite(c.keypoints[j]) || !finite(c.reference[j]) ||
          !model_vectors(basis, j, c.keypoints, v1, v2, v3))
        continue;
      const glm::dvec3 d(c.reference[j] - c.keypoints[j]);
      const std::array<glm::dvec3, 3> v = {glm::dvec3(v1), glm::dvec3(v2), glm::dvec3(v3)};
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) m[a][b] += glm::dot(v[a], v[b]);
        r[a] += glm::dot(d, v[a]);
      }
      len1 += glm::length(v[0]);
      len2 += glm::length(v[1]);
      len3 += glm::length(v[2]);
      ++n;
    }
    if (n == 0) {
      fit.notes += std::string(kJointNames[j]) +
                   ": not estimated (no frame has this layout's keypoint and the reference in "
                   "3D)\n";
      continue;
    }
    recon::JointOffset& o = fit.offsets.joints[j];
    o.basis = basis;
    if (basis == OffsetBasis::bone) {
      o.along = m[0][0] > 0 ? static_cast<float>(r[0] / m[0][0]) : 0.0f;
    } else {
      const auto x = solve3(m, r);
      o.along = static_cast<float>(x[0]);
      o.lateral = static_cast<float>(x[1]);
      o.forward = static_cast<float>(x[2]);
    }
    fit.joints[j].along_mm = 1000.0 * o.along * len1 / n;
    fit.joints[j].lateral_mm = 1000.0 * o.lateral * len2 / n;
    fit.joints[j].forward_mm = 1000.0 * o.forward * len3 / n;
  }
  // Before and after, in 3D: with the 2D-applicable part only (what the scaler does) and with
  // the forward part too (what mapping back in 3D does).
  const auto full = evaluate_offsets_3d(fit.offsets, frames);
  recon::LayoutOffsets in_plane = fit.offsets;
  for (auto& o : in_plane.joints) o.forward = 0.0f;
  const auto plane = evaluate_offsets_3d(in_plane, frames);
  for (int j = 0; j < kBodyJoints; ++j) {
    JointFit f = plane[j];
    f.along_mm = fit.joints[j].along_mm;
    f.lateral_mm = fit.joints[j].lateral_mm;
    f.forward_mm = fit.joints[j].forward_mm;
    f.after_3d_mm = full[j].after_mm;
    fit.joints[j] = f;
  }
  return fit;
}

std::array<JointFit, kBodyJoints> evaluate_offsets_3d(const recon::LayoutOffsets& offsets,
                                                      std::span<const CalibrationFrame> frames) {
  std::array<JointFit, kBodyJoints> out{};
  for (const CalibrationFrame& c : frames) {
    Joints3 corrected = c.keypoints;
    recon::apply_layout_offsets_3d(offsets, corrected);
    glm::vec3 up(0.0f), left(0.0f), forward(0.0f);
    const bool frame_ok = body_frame(c.reference, up, left, forward);
    for (int j = 0; j < kBodyJoints; ++j) {
      if (!finite(c.keypoints[j]) || !finite(c.reference[j])) continue;
      JointFit& f = out[j];
      const glm::vec3 d = c.reference[j] - c.keypoints[j];
      f.before_mm += 1000.0 * glm::length(d);
      f.after_mm += 1000.0 * glm::length(c.reference[j] - corrected[j]);
      if (frame_ok)
        f.mean_offset_mm +=
            1000.0 * glm::dvec3(glm::dot(d, up), glm::dot(d, left), glm::dot(d, forward));
      ++f.frames;
    }
  }
  for (JointFit& f : out) {
    if (f.frames == 0) continue;
    f.before_mm /= f.frames;
    f.after_mm /= f.frames;
    f.mean_offset_mm /= static_cast<double>(f.frames);
  }
  return out;
}

namespace {

// Pixel (x, y) and depth (metres along the optical axis) of a TRC point (Y up) in a camera of the
// Z-up calibration world.
glm::dvec3 project_trc(const camera::Camera& cam, const glm::vec3& trc) {
  const glm::dvec3 world(trc.z, trc.x, trc.y);
  const glm::dvec2 pixel = cam.project_pinhole(world);
  return {pixel.x, pixel.y, cam.to_camera(world).z};
}

}  // namespace

std::array<JointFit, kBodyJoints> evaluate_offsets_2d(const recon::LayoutOffsets& offsets,
                                                      std::span<const CalibrationFrame> frames,
                                                      std::span<const camera::Camera> cameras) {
  std::array<JointFit, kBodyJoints> out{};
  for (const camera::Camera& cam : cameras) {
    for (const CalibrationFrame& c : frames) {
      std::array<float, kBodyJoints * 3> body;
      std::array<glm::dvec3, kBodyJoints> reference;
      for (int j = 0; j < kBodyJoints; ++j) {
        const bool ok = finite(c.keypoints[j]);
        const glm::dvec3 p = ok ? project_trc(cam, c.keypoints[j]) : glm::dvec3(0.0);
        body[3 * j] = ok ? static_cast<float>(p.x) : kNan;
        body[3 * j + 1] = ok ? static_cast<float>(p.y) : kNan;
        body[3 * j + 2] = ok && p.z > 0 ? 1.0f : 0.0f;
        reference[j] = finite(c.reference[j]) ? project_trc(cam, c.reference[j]) : glm::dvec3(kNan);
      }
      std::array<float, kBodyJoints* 3> corrected = body;
      recon::apply_layout_offsets(offsets, corrected);
      for (int j = 0; j < kBodyJoints; ++j) {
        if (body[3 * j + 2] <= 0.0f || !std::isfinite(reference[j].z) || reference[j].z <= 0)
          continue;
        const double mm_per_px = 1000.0 * reference[j].z / cam.fx;
        const glm::dvec2 ref(reference[j].x, reference[j].y);
        JointFit& f = out[j];
        f.before_mm += mm_per_px * glm::length(glm::dvec2(body[3 * j], body[3 * j + 1]) - ref);
        f.after_mm +=
            mm_per_px * glm::length(glm::dvec2(corrected[3 * j], corrected[3 * j + 1]) - ref);
        ++f.frames;
      }
    }
  }
  for (JointFit& f : out) {
    if (f.frames == 0) continue;
    f.before_mm /= f.frames;
    f.after_mm /= f.frames;
  }
  return out;
}

}  // namespace mocap::eval
