#include "motion/asf_amc.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "motion/bvh.hpp"
#include "motion/pose_sequence.hpp"
#include "support/errors.hpp"

namespace mocap::motion {
namespace {

using test::error_of;

// ---- An independent evaluation of the ASF equations (plain 3x3 matrices, no glm) ----
//
// A bone's global rotation is R_parent · C · M · C⁻¹, C from `axis` (rotations applied in the
// order the axis letters name), M from the dof values (applied in the order the dofs are listed);
// a bone starts where its parent ends and ends at start + R · direction · length.

struct Vec {
  double x = 0, y = 0, z = 0;
};
struct Mat {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
};

Mat mul(const Mat& a, const Mat& b) {
  Mat r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
    }
  }
  return r;
}

Mat transpose(const Mat& a) {
  Mat r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[j][i];
  }
  return r;
}

Vec apply(const Mat& a, const Vec& v) {
  return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
          a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
          a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}

// Right-handed rotation by `degrees` about axis 'x', 'y' or 'z', written out element by element.
Mat rotation(char axis, double degrees) {
  const double r = degrees * std::numbers::pi / 180.0, c = std::cos(r), s = std::sin(r);
  // The two axes other than the rotation axis, in right-handed order (x: y,z; y: z,x; z: x,y).
  const int i = (axis - 'x' + 1) % 3, j = (axis - 'x' + 2) % 3;
  Mat a;
  a.m[i][i] = c;
  a.m[i][j] = -s;
  a.m[j][i] = s;
  a.m[j][j] = c;
  return a;
}

// `axes` names the rotations in the order they are applied: "xyz" gives Rz·Ry·Rx.
Mat rotations(const std::string& axes, const std::vector<double>& degrees) {
  Mat r;
  for (size_t i = 0; i < axes.size(); ++i) r = mul(rotation(axes[i], degrees[i]), r);
  return r;
}

// ---- The test skeleton: root + 5 bones, every axis non-trivial, dofs in different orders ----

struct TestBone {
  std::string name;
  int parent;  // index into kBones, -1 = root
  Vec direction;
  double length;
  std::vector<double> axis;  // degrees about x, y, z
  std::string axis_order;    // lower-case, as the letters are applied
  std::string dofs;          // rotation axes in AMC order; empty = no dof
};

const std::vector<TestBone> kBones = {
    {"hip", -1, {0, -1, 0}, 2.0, {0, 0, 30}, "xyz", ""},
    {"thigh", 0, {0.6, -0.8, 0}, 5.0, {10, -20, 30}, "xyz", "xyz"},
    {"shin", 1, {0, -1, 0}, 4.0, {45, 0, 0}, "zyx", "zx"},
    {"spine", -1, {0, 1, 0}, 3.0, {0, 90, 0}, "yzx", "yzx"},
    {"arm", 3, {1, 0, 0}, 2.5, {-30, 15, 60}, "xzy", "x"},
};

// The same skeleton as Acclaim writes it, with comments, parentheses, limits over several lines,
// a root order with the rotations reversed (Softimage style) and dofs in upper and lower case.
const char* kAsf = R"(# AST/ASF file for tests
:version 1.10
:name TEST
:units
  mass 1.0
  length 0.45
  angle deg
:documentation
   Hand-written: a root and five bones, every bone with a non-trivial axis.
   Documentation is free text up to the next keyword.
:root
   order TX TY TZ RZ RY RX
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name hip
     direction 0 -1 0
     length 2
     axis 0 0 30  XYZ
  end
  begin
     id 2
     name thigh
     direction 0.6 -0.8 0
     length 5
     axis 10 -20 30  XYZ
    dof rx ry rz
    limits (-160.0 20.0)
           (-70.0 70.0)
           (-inf inf)
  end
  begin
     id 3
     name shin
     direction 0 -1 0
     length 4
     axis 45 0 0  ZYX
    dof RZ RX
    limits (-10 170) (-5 5)
  end
  begin
     id 4
     name spine
     direction 0 1 0
     length 3
     axis 0 90 0 YZX
    dof ry rz rx
  end
  begin
     id 5
     name arm
     direction 1 0 0
     length 2.5
     axis -30 15 60 XZY
    dof rx
  end
:hierarchy
  begin
    root hip spine
    hip thigh
    thigh shin
    spine arm
  end
)";

// Root values (TX TY TZ RZ RY RX) and bone values (in dof order) for three frames.
struct TestFrame {
  std::vector<double> root;
  std::vector<std::vector<double>> bones;  // per kBones entry
};

const std::vector<TestFrame> kFrames = {
    {{0, 0, 0, 0, 0, 0}, {{}, {0, 0, 0}, {0, 0}, {0, 0, 0}, {0}}},
    {{1.5, 17.2, -3.25, 10, -20, 35}, {{}, {-40, 12, 7.5}, {25, -4}, {3, -8, 11}, {-65}}},
    {{-2, 16.5, 4, -170, 80, 5}, {{}, {20, -33, -61}, {-80, 2.5}, {-15, 22, 1}, {120}}},
};

std::string amc_text() {
  std::ostringstream out;
  out << "#!OML:ASF test.asf\n:FULLY-SPECIFIED\n:DEGREES\n";
  for (size_t f = 0; f < kFrames.size(); ++f) {
    out << f + 1 << "\n";
    out << "root";
    for (double v : kFrames[f].root) out << ' ' << v;
    out << "\n";
    // Bones in reverse file order: the AMC names every line, order does not matter.
    for (size_t b = kBones.size(); b-- > 0;) {
      if (kBones[b].dofs.empty()) continue;
      out << kBones[b].name;
      for (double v : kFrames[f].bones[b]) out << ' ' << v;
      out << "\r\n";  // CRLF on some lines
    }
  }
  return out.str();
}

// Bone start and end points of one frame from the ASF equations.
struct BonePoints {
  std::vector<Vec> start, end;
};

BonePoints expected_points(const TestFrame& frame) {
  const Vec root_position{frame.root[0], frame.root[1], frame.root[2]};
  // Order RZ RY RX: about the global axes, Z first.
  const Mat root_rotation = rotations("zyx", {frame.root[3], frame.root[4], frame.root[5]});
  BonePoints p;
  std::vector<Mat> global(kBones.size());
  for (size_t b = 0; b < kBones.size(); ++b) {
    const TestBone& bone = kBones[b];
    const Mat c = rotations(
        bone.axis_order, {bone.axis[bone.axis_order[0] - 'x'], bone.axis[bone.axis_order[1] - 'x'],
                          bone.axis[bone.axis_order[2] - 'x']});
    const Mat m = rotations(bone.dofs, frame.bones[b]);
    const Mat parent = bone.parent < 0 ? root_rotation : global[bone.parent];
    global[b] = mul(parent, mul(c, mul(m, transpose(c))));
    const Vec start = bone.parent < 0 ? root_position : p.end[bone.parent];
    const Vec d = apply(global[b], {bone.direction.x * bone.length, bone.direction.y * bone.length,
                                    bone.direction.z * bone.length});
    p.start.push_back(start);
    p.end.push_back({start.x + d.x, start.y + d.y, start.z + d.z});
  }
  return p;
}

void expect_near(const glm::vec3& got, const Vec& want, const std::string& what) {
  EXPECT_NEAR(got.x, want.x, 1e-4) << what;
  EXPECT_NEAR(got.y, want.y, 1e-4) << what;
  EXPECT_NEAR(got.z, want.z, 1e-4) << what;
}

// Checks a clip's forward kinematics against the ASF equations, frame by frame.
void expect_matches_asf_equations(const Clip& clip) {
  ASSERT_EQ(clip.frame_count, static_cast<int>(kFrames.size()));
  const PoseSequence poses = to_poses(clip);
  GlobalPose g;
  for (size_t f = 0; f < kFrames.size(); ++f) {
    forward_kinematics(poses, static_cast<int>(f), g);
    const BonePoints want = expected_points(kFrames[f]);
    const std::string at = "frame " + std::to_string(f) + " ";
    expect_near(g.position[clip.skeleton.find("root")], want.start[0], at + "root");
    for (size_t b = 0; b < kBones.size(); ++b) {
      const int joint = clip.skeleton.find(kBones[b].name);
      ASSERT_GE(joint, 0) << kBones[b].name;
      expect_near(g.position[joint], want.start[b], at + kBones[b].name);
      const int end = clip.skeleton.find(kBones[b].name + "_End");
      if (end >= 0) expect_near(g.position[end], want.end[b], at + kBones[b].name + "_End");
    }
  }
}

Clip test_clip() { return parse_amc(parse_asf(kAsf, "test.asf"), amc_text(), "test.amc"); }

// The message of the InputError that `f` throws ("" when it throws none).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// ---- Parsing ----

TEST(AsfAmc, ParsesTheSkeleton) {
  const AsfSkeleton s = parse_asf(kAsf, "test.asf");
  EXPECT_EQ(s.name, "TEST");
  EXPECT_DOUBLE_EQ(s.length_unit, 0.45);
  EXPECT_TRUE(s.angles_in_degrees);
  ASSERT_EQ(s.bones.size(), 5u);
  // Parents first, children in hierarchy order: hip thigh shin spine arm.
  EXPECT_EQ(s.bones[2].name, "shin");
  EXPECT_EQ(s.bones[2].parent, 1);
  EXPECT_EQ(s.bones[3].parent, -1);
  EXPECT_EQ(s.bones[2].axis_order, (AsfAxisOrder{2, 1, 0}));
  EXPECT_EQ(s.bones[2].dofs, (std::vector<AsfDof>{AsfDof::rz, AsfDof::rx}));
  ASSERT_EQ(s.bones[1].limits.size(), 3u);
  EXPECT_DOUBLE_EQ(s.bones[1].limits[0].first, -160.0);
  EXPECT_TRUE(std::isinf(s.bones[1].limits[2].second));
  EXPECT_EQ(s.root.order.size(), 6u);
  EXPECT_EQ(s.root.order[3], AsfDof::rz);
}

TEST(AsfAmc, SkeletonHasJointsChannelsAndEndSites) {
  const Skeleton k = to_skeleton(parse_asf(kAsf, "test.asf"));
  // root, hip, thigh, shin, shin_End, spine, arm, arm_End
  ASSERT_EQ(k.joint_count(), 8);
  EXPECT_EQ(k.joints[0].channels.size(), 6u);
  EXPECT_TRUE(k.joints[k.find("hip")].channels.empty());   // no dof, no channels
  EXPECT_EQ(k.joints[k.find("arm")].channels.size(), 3u);  // one dof, still three channels
  EXPECT_TRUE(k.joints[k.find("shin_End")].end_site);
  EXPECT_EQ(k.find("hip_End"), -1);  // hip has a child
  EXPECT_EQ(k.channel_count, 6 + 3 * 4);
  // The thigh starts where the hip ends: 2 units below the root, in the rest frame.
  EXPECT_EQ(k.joints[k.find("thigh")].offset, glm::vec3(0, -2, 0));
  EXPECT_EQ(k.joints[k.find("spine")].offset, glm::vec3(0, 0, 0));
  for (int j = 1; j < k.joint_count(); ++j) EXPECT_LT(k.joints[j].parent, j);
}

// ---- Forward kinematics against numbers worked out by hand ----

const char* kTinyAsf = R"(:units
  length 1
  angle deg
:root
  order TX TY TZ RX RY RZ
  axis XYZ
  position 0 0 0
  orientation 0 0 0
:bonedata
  begin
    name b
    direction 1 0 0
    length 2
    axis 0 0 90 XYZ
    dof rx
  end
  begin
    name c
    direction 0 1 0
    length 1
    axis 0 0 0 XYZ
    dof rz
  end
:hierarchy
  begin
    root b
    b c
  end
)";

TEST(AsfAmc, BoneRotationIsTheDofRotationInTheAxisFrame) {
  const AsfSkeleton s = parse_asf(kTinyAsf, "tiny.asf");
  const Clip clip = parse_amc(s, "1\nroot 1 2 3 0 0 0\nb 90\nc 90\n", "tiny.amc");
  GlobalPose g;
  forward_kinematics(to_poses(clip), 0, g);
  const Skeleton& k = clip.skeleton;
  // b: C = Rz(90) turns the local x axis onto global y, so rx 90 is a quarter turn about +y:
  // the bone (2 along +x) swings to 2 along -z. b starts at the root (1, 2, 3), so c starts at
  // (1, 2, 1). c: rz 90 turns its +y direction to -x, then b's turn about y takes -x to +z.
  expect_near(g.position[k.find("b")], {1, 2, 3}, "b");
  expect_near(g.position[k.find("c")], {1, 2, 1}, "c");
  expect_near(g.position[k.find("c_End")], {1, 2, 2}, "c_End");
}

TEST(AsfAmc, RadiansFromTheAsfOrTheAmcHeader) {
  const std::string rad_asf = replaced(replaced(kTinyAsf, "angle deg", "angle rad"),
                                       "axis 0 0 90 XYZ", "axis 0 0 1.5707963267948966 XYZ");
  const AsfSkeleton s = parse_asf(rad_asf, "rad.asf");
  EXPECT_NEAR(s.bones[0].axis.z, 90.0, 1e-9);  // stored in degrees
  const std::string frame = "1\nroot 1 2 3 0 0 0\nb 1.5707963267948966\nc 1.5707963267948966\n";
  for (const std::string& amc : {frame, ":RADIANS\n" + frame}) {
    GlobalPose g;
    forward_kinematics(to_poses(parse_amc(s, amc, "rad.amc")), 0, g);
    expect_near(g.position.back(), {1, 2, 2}, "c_End");
  }
  // An AMC that says :DEGREES overrides the ASF's radians.
  GlobalPose g;
  forward_kinematics(to_poses(parse_amc(s, ":DEGREES\n1\nroot 1 2 3 0 0 0\nb 90\nc 90\n", "d.amc")),
                     0, g);
  expect_near(g.position.back(), {1, 2, 2}, "c_End");
}

TEST(AsfAmc, TranslationDofsMoveTheBoneAlongItsAxes) {
  const std::string asf = replaced(kTinyAsf, "dof rx", "dof tx rx");
  const Clip clip =
      parse_amc(parse_asf(asf, "t.asf"), "1\nroot 0 0 0 0 0 0\nb 0.5 0\nc 0\n", "t.amc");
  GlobalPose g;
  forward_kinematics(to_poses(clip), 0, g);
  // tx 0.5 along b's local x, which C = Rz(90) points along global +y.
  expect_near(g.position[clip.skeleton.find("b")], {0, 0.5, 0}, "b");
  expect_near(g.position[clip.skeleton.find("c")], {2, 0.5, 0}, "c");
}

TEST(AsfAmc, RootPresetIsAFixedOffsetOfTheMotion) {
  // Reader's reading of the preset (CMU files leave it at zero): T(position)·O·T(t)·M.
  const std::string asf = replaced(replaced(kTinyAsf, "position 0 0 0", "position 1 0 0"),
                                   "orientation 0 0 0", "orientation 0 0 90");
  const Clip clip = parse_amc(parse_asf(asf, "p.asf"), "1\nroot 1 0 0 0 0 0\nb 0\nc 0\n", "p.amc");
  GlobalPose g;
  forward_kinematics(to_poses(clip), 0, g);
  expect_near(g.position[0], {1, 1, 0}, "root");                     // (1,0,0) + Rz(90)·(1,0,0)
  expect_near(g.position[clip.skeleton.find("c")], {1, 3, 0}, "c");  // b (2 along x) turned to +y
}

// ---- Forward kinematics against the ASF equations evaluated independently ----

TEST(AsfAmc, ForwardKinematicsFollowsTheAsfEquations) { expect_matches_asf_equations(test_clip()); }

TEST(AsfAmc, BvhRoundTripKeepsTheMotion) {
  const Clip clip = test_clip();
  std::ostringstream bvh;
  write_bvh(clip, bvh);
  const Clip back = parse_bvh(bvh.str(), "written.bvh");
  EXPECT_EQ(back.skeleton.joint_count(), clip.skeleton.joint_count());
  EXPECT_EQ(back.skeleton.channel_count, clip.skeleton.channel_count);
  EXPECT_NEAR(back.fps(), kCmuFps, 1e-4);  // BVH keeps the frame time as a float
  expect_matches_asf_equations(back);
}

TEST(AsfAmc, ReadsFilesInAsfUnits) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("asf-amc-test-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(dir);
  const std::string asf = (dir / "t.asf").string(), amc = (dir / "t_01.amc").string();
  std::ofstream(asf) << kAsf;
  std::ofstream(amc) << amc_text();
  const Clip clip = read_asf_amc(asf, amc, 60.0);
  EXPECT_EQ(clip.source, amc);
  EXPECT_NEAR(clip.fps(), 60.0, 1e-9);
  expect_matches_asf_equations(clip);
  EXPECT_THROW(read_asf_amc(asf, (dir / "missing.amc").string()), InputError);
  EXPECT_THROW(read_asf((dir / "missing.asf").string()), InputError);
  std::filesystem::remove_all(dir);
  EXPECT_NEAR(kCmuMetresPerUnit, 0.056444, 1e-6);
}

// ---- Errors: file and line, never a crash ----

TEST(AsfAmc, FrameErrorsNameFileAndLine) {
  const AsfSkeleton s = parse_asf(kTinyAsf, "tiny.asf");
  const auto amc_error = [&](const std::string& text) {
    return error_of([&] { parse_amc(s, text, "bad.amc"); });
  };
  EXPECT_NE(
      amc_error("1\nroot 0 0 0 0 0 0\nb 1\n2\nroot 0 0 0 0 0 0\nb 1\nc 1\n").find("bad.amc:1:"),
      std::string::npos);  // frame 1 lacks c
  EXPECT_NE(amc_error("1\nroot 0 0 0 0 0 0\nb 1 2\nc 1\n").find("bad.amc:3: bone 'b' has 2 values"),
            std::string::npos);
  EXPECT_NE(amc_error("1\nroot 0 0 0 0 0\nb 1\nc 1\n").find("bad.amc:2:"), std::string::npos);
  EXPECT_NE(amc_error("1\nroot 0 0 0 0 0 0\nb 1\nx 1\nc 1\n").find("bad.amc:4: unknown bone 'x'"),
            std::string::npos);
  EXPECT_NE(amc_error("1\nroot 0 0 0 0 0 0\nb 1\nb 1\nc 1\n").find("bad.amc:4:"),
            std::string::npos);
  EXPECT_NE(amc_error("1\nroot 0 0 0 0 0 0\nb 1\nc 1\n3\nroot 0 0 0 0 0 0\nb 1\nc 1\n")
                .find("bad.amc:5:"),
            std::string::npos);  // frame 2 skipped
  EXPECT_NE(amc_error(":DEGREES\nroot 0 0 0 0 0 0\n").find("bad.amc:2: expected a frame number"),
            std::string::npos);
  EXPECT_NE(amc_error("1\nroot 0 0 0 0 0 zero\nb 1\nc 1\n").find("bad.amc:2:"), std::string::npos);
  EXPECT_NE(amc_error("1\nroot 0 0 0 0 0 1e300\nb 1\nc 1\n").find("out of range"),
            std::string::npos);
  EXPECT_NE(amc_error("1\nroot 0 0 0 0 0 nan\nb 1\nc 1\n").find("bad.amc:2:"), std::string::npos);
  EXPECT_NE(amc_error("# only a comment\n:FULLY-SPECIFIED\n").find("no frames"), std::string::npos);
  EXPECT_NE(amc_error("5000000000\nroot 0 0 0 0 0 0\nb 1\nc 1\n").find("bad.amc:1: implausible"),
            std::string::npos);
  // A skeleton without a single dof has nothing to animate.
  const AsfSkeleton still =
      parse_asf(replaced(replaced(replaced(kTinyAsf, "dof rx", ""), "dof rz", ""),
                         "order TX TY TZ RX RY RZ", "order"),
                "still.asf");
  EXPECT_NE(
      error_of([&] { parse_amc(still, "1\n2\n", "still.amc"); }).find("no degrees of freedom"),
      std::string::npos);
}

TEST(AsfAmc, SkeletonErrorsNameFileAndLine) {
  const auto asf_error = [](const std::string& text) {
    return error_of([&] { parse_asf(text, "bad.asf"); });
  };
  EXPECT_NE(asf_error(replaced(kTinyAsf, "dof rx", "dof rx rq")).find("bad.asf:15: unknown degree"),
            std::string::npos);
  EXPECT_NE(asf_error(replaced(kTinyAsf, "dof rx", "dof l")).find("not supported"),
            std::string::npos);
  EXPECT_NE(asf_error(replaced(kTinyAsf, "    b c\n", "    c b\n")).find("two parents"),
            std::string::npos);
  EXPECT_NE(
      asf_error(replaced(kTinyAsf, "    b c\n", "    b x\n")).find("bad.asf:27: unknown bone 'x'"),
      std::string::npos);
  EXPECT_NE(
      asf_error(replaced(kTinyAsf, "    b c\n", "")).find("bad.asf:17: bone 'c' is not connected"),
      std::string::npos);
  // A cycle that never reaches the root.
  EXPECT_NE(asf_error(replaced(kTinyAsf, "    root b\n    b c\n", "    root\n    b c\n    c b\n"))
                .find("not connected"),
            std::string::npos);
  EXPECT_NE(
      asf_error(replaced(kTinyAsf, "    length 2\n", "")).find("needs 'direction' and 'length'"),
      std::string::npos);
  EXPECT_NE(asf_error(replaced(kTinyAsf, "name c", "name b")).find("second bone called 'b'"),
            std::string::npos);
  EXPECT_NE(asf_error(replaced(kTinyAsf, "axis 0 0 90 XYZ", "axis 0 0 90 XYY")).find("axis order"),
            std::string::npos);
  EXPECT_NE(asf_error(replaced(kTinyAsf, "  end\n:hierarchy", ":hierarchy")).find("no 'end'"),
            std::string::npos);
  EXPECT_NE(asf_error(replaced(kAsf, "(-inf inf)", "")).find("limit pairs"), std::string::npos);
  const std::string cut =
      std::string(kTinyAsf).substr(0, std::string(kTinyAsf).find("    length 1"));
  EXPECT_NE(asf_error(cut).find("bad.asf:19: file ends inside a bone"), std::string::npos);
}

TEST(AsfAmc, EmptyInputIsAnError) {
  EXPECT_THROW(parse_asf("", "empty.asf"), InputError);
  EXPECT_THROW(parse_asf("\n\n# nothing\n", "empty.asf"), InputError);
  const AsfSkeleton s = parse_asf(kAsf, "test.asf");
  EXPECT_THROW(parse_amc(s, "", "empty.amc"), InputError);
  EXPECT_THROW(parse_amc(s, "\r\n\r\n", "empty.amc"), InputError);
}

// Every prefix of a good file either parses (it ends between frames) or is an InputError.
TEST(AsfAmc, TruncatedInputIsAnErrorNotACrash) {
  const AsfSkeleton s = parse_asf(kAsf, "test.asf");
  const std::string amc = amc_text();
  for (size_t n = 0; n < amc.size(); ++n) {
    try {
      const Clip c = parse_amc(s, std::string_view(amc).substr(0, n), "cut.amc");
      EXPECT_LE(c.frame_count, static_cast<int>(kFrames.size()));
    } catch (const InputError&) {
    }
  }
  // Cut in the middle of frame 2: bones are missing.
  EXPECT_THROW(parse_amc(s, amc.substr(0, amc.find("spine", amc.find("\n2\n"))), "cut.amc"),
               InputError);
  const std::string asf = kAsf;
  for (size_t n = 0; n < asf.size(); ++n) {
    try {
      parse_asf(std::string_view(asf).substr(0, n), "cut.asf");
    } catch (const InputError&) {
    }
  }
  EXPECT_THROW(parse_asf(asf.substr(0, asf.find("thigh shin")), "cut.asf"), InputError);
}

TEST(AsfAmc, RandomBytesAreAnError) {
  const AsfSkeleton s = parse_asf(kAsf, "test.asf");
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 300; ++trial) {
    std::string bytes(std::uniform_int_distribution<size_t>(1, 3000)(rng), '\0');
    for (char& c : bytes) c = static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    EXPECT_THROW(parse_asf(bytes, "random.asf"), InputError);
    EXPECT_THROW(parse_amc(s, bytes, "random.amc"), InputError);
  }
}

// Good files with random damage, and random streams of the formats' own words: any outcome but
// a crash, a hang or another exception type is a failure.
TEST(AsfAmc, DamagedInputNeverCrashes) {
  const AsfSkeleton s = parse_asf(kAsf, "test.asf");
  const std::string asf = kAsf, amc = amc_text();
  std::mt19937 rng(777);
  const char* words[] = {":root",     ":bonedata", ":hierarchy", ":units", "begin", "end",   "name",
                         "dof",       "rx",        "limits",     "(",      "1e308", "-inf",  "root",
                         "thigh",     "7",         "\n",         "\n",     "axis",  "1 2 3", "XYZ",
                         "direction", "length",    "order",      "TX",     "#"};
  for (int trial = 0; trial < 2000; ++trial) {
    std::string a = asf, m = amc;
    for (int k = 0; k < 3; ++k) {
      a[std::uniform_int_distribution<size_t>(0, a.size() - 1)(rng)] = static_cast<char>(rng());
      m[std::uniform_int_distribution<size_t>(0, m.size() - 1)(rng)] = static_cast<char>(rng());
    }
    std::string w;
    for (int k = 0; k < 60; ++k) w += std::string(words[rng() % std::size(words)]) + " ";
    for (const std::string* text : {&a, &w}) {
      try {
        parse_asf(*text, "damaged.asf");
      } catch (const InputError&) {
      }
    }
    for (const std::string* text : {&m, &w}) {
      try {
        parse_amc(s, *text, "damaged.amc");
      } catch (const InputError&) {
      }
    }
  }
}

}  // namespace
}  // namespace mocap::motion
