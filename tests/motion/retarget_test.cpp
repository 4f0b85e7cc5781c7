// Retargeting on the shared mocap: CMU cgspeed clips onto the 43-joint Daz rig and onto their own
// rig, checked with forward kinematics; bad rigs and maps give errors naming the file.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "motion/bvh.hpp"
#include "motion/pose_sequence.hpp"
#include "motion/retarget.hpp"
#include "support/files.hpp"
#include "support/shared_data.hpp"

namespace mocap::motion {
namespace {

using test::shared_data;

const std::string kDazRig = "mocap/cmu_daz/07_01.bvh";
constexpr double kCmuMetres = (1.0 / 0.45) * 2.54 / 100.0;

std::string data(const std::string& relative) { return (shared_data() / relative).string(); }

RetargetResult onto_daz(const Clip& source, RetargetOptions options = {}) {
  options.target_source = data(kDazRig);
  return retarget(source, read_rig(data(kDazRig)), options);
}

// Bone pairs named independently of the library's matching: Daz bone <- cmu31 bone.
struct NamedBone {
  const char *target_from, *target_to, *source_from, *source_to;
};
const NamedBone kDazBones[] = {
    {"abdomen", "chest", "Spine", "Spine1"},
    {"neck", "head", "Neck1", "Head"},
    {"lShldr", "lForeArm", "LeftArm", "LeftForeArm"},
    {"lForeArm", "lHand", "LeftForeArm", "LeftHand"},
    {"rShldr", "rForeArm", "RightArm", "RightForeArm"},
    {"rForeArm", "rHand", "RightForeArm", "RightHand"},
    {"lCollar", "lShldr", "LeftShoulder", "LeftArm"},
    {"rCollar", "rShldr", "RightShoulder", "RightArm"},
    {"lThigh", "lShin", "LeftUpLeg", "LeftLeg"},
    {"lShin", "lFoot", "LeftLeg", "LeftFoot"},
    {"rThigh", "rShin", "RightUpLeg", "RightLeg"},
    {"rShin", "rFoot", "RightLeg", "RightFoot"},
};

double angle_degrees(glm::vec3 a, glm::vec3 b) {
  const glm::dvec3 u = glm::normalize(glm::dvec3(a)), v = glm::normalize(glm::dvec3(b));
  return glm::degrees(std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v)));
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The lowest point (joints and End Sites) of every frame.
std::vector<double> lowest_points(const Clip& clip) {
  const PoseSequence poses = to_poses(clip);
  GlobalPose g;
  std::vector<double> out;
  for (int f = 0; f < poses.frame_count; ++f) {
    forward_kinematics(poses, f, g);
    double lowest = 1e30;
    for (const glm::vec3& p : g.position) lowest = std::min(lowest, double(p.y));
    out.push_back(lowest);
  }
  return out;
}

class RetargetOntoDaz : public ::testing::TestWithParam<const char*> {};

TEST_P(RetargetOntoDaz, BoneDirectionsMatchTheSourceEveryFrameAndTheRigKeepsItsBones) {
  const std::string clip_name = std::string("mocap/cmu31/") + GetParam() + ".bvh";
  MOCAP_REQUIRE_SHARED(clip_name);
  MOCAP_REQUIRE_SHARED(kDazRig);
  const Clip source = read_bvh(data(clip_name));
  const Skeleton rig = read_rig(data(kDazRig));
  const RetargetResult result = onto_daz(source);

  // The rig's own hierarchy, offsets and channels, the source's frames.
  const Skeleton& out = result.clip.skeleton;
  ASSERT_EQ(out.joint_count(), rig.joint_count());
  for (int j = 0; j < rig.joint_count(); ++j) {
    EXPECT_EQ(out.joints[j].name, rig.joints[j].name);
    EXPECT_EQ(out.joints[j].parent, rig.joints[j].parent);
    EXPECT_EQ(out.joints[j].offset, rig.joints[j].offset) << rig.joints[j].name;
    EXPECT_EQ(out.joints[j].channels, rig.joints[j].channels) << rig.joints[j].name;
  }
  EXPECT_EQ(out.channel_count, 132);
  EXPECT_EQ(result.clip.frame_count, source.frame_count);
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  EXPECT_EQ(result.matches.size(), 21u);  // 15 body joints + spine, chest, collars, index fingers

  // Forward kinematics of both: each bone points the same way in every frame.
  const PoseSequence a = to_poses(source), b = to_poses(result.clip);
  GlobalPose ga, gb;
  std::vector<double> errors;
  for (int f = 0; f < a.frame_count; ++f) {
    forward_kinematics(a, f, ga);
    forward_kinematics(b, f, gb);
    for (const NamedBone& bone : kDazBones) {
      const int t0 = out.find(bone.target_from), t1 = out.find(bone.target_to);
      const int s0 = source.skeleton.find(bone.source_from);
      const int s1 = source.skeleton.find(bone.source_to);
      ASSERT_TRUE(t0 >= 0 && t1 >= 0 && s0 >= 0 && s1 >= 0) << bone.target_from;
      const double e =
          angle_degrees(ga.position[s1] - ga.position[s0], gb.position[t1] - gb.position[t0]);
      errors.push_back(e);
      ASSERT_LT(e, 2.0) << "frame " << f << " bone " << bone.target_from << "->" << bone.target_to;
      // Bone lengths are the rig's own.
      ASSERT_NEAR(glm::length(gb.position[t1] - gb.position[t0]),
                  glm::length(out.joints[t1].offset), 1e-3);
    }
  }
  std::printf(
      "[ retarget ] %s onto Daz: %zu bone-frames, direction error median %.4f, max %.4f deg\n",
      GetParam(), errors.size(), median(errors), *std::max_element(errors.begin(), errors.end()));

  // The root: hip height ratio; a ground at y = 0 stays near y = 0 (lowest point, cm).
  EXPECT_NEAR(result.scale, result.target_hip_height / result.source_hip_height, 1e-6);
  EXPECT_GT(result.scale, 4.0f);  // CMU units (5.6 cm) onto centimetres
  EXPECT_LT(result.scale, 6.0f);
  std::vector<double> src_low = lowest_points(source), out_low = lowest_points(result.clip);
  for (double& v : src_low) v *= result.scale;
  const double src_ground = median(src_low), out_ground = median(out_low);
  std::printf("[ retarget ] %s lowest point per frame, median: source %.2f, Daz %.2f (Daz cm)\n",
              GetParam(), src_ground, out_ground);
  EXPECT_NEAR(out_ground, src_ground, 5.0);

  // The written file reads back with our reader, the same values.
  test::TempDir dir;
  write_bvh(result.clip, dir.file("out.bvh"));
  const Clip back = read_bvh(dir.file("out.bvh"));
  ASSERT_EQ(back.frame_count, result.clip.frame_count);
  ASSERT_EQ(back.skeleton.channel_count, 132);
  EXPECT_EQ(back.values, result.clip.values);
  EXPECT_NEAR(back.frame_time, source.frame_time, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Cmu31Clips, RetargetOntoDaz,
                         ::testing::Values("07_01", "05_01", "02_04", "09_01"));

TEST(Retarget, OntoItsOwnRigReproducesTheJointPositions) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/86_01.bvh");
  const std::string path = data("mocap/cmu31/86_01.bvh");
  const Clip source = read_bvh(path);
  RetargetOptions options;
  options.target_source = path;
  const RetargetResult result = retarget(source, read_rig(path), options);
  EXPECT_NEAR(result.scale, 1.0f, 1e-6f);
  EXPECT_TRUE(result.unmapped_target.empty());
  const PoseSequence a = to_poses(source), b = to_poses(result.clip);
  GlobalPose ga, gb;
  double worst = 0.0;
  for (int f = 0; f < a.frame_count; ++f) {
    forward_kinematics(a, f, ga);
    forward_kinematics(b, f, gb);
    for (std::size_t j = 0; j < ga.position.size(); ++j)
      worst = std::max(worst, double(glm::length(ga.position[j] - gb.position[j])) * kCmuMetres);
  }
  std::printf("[ retarget ] 86_01 onto itself: worst joint error %.2e m\n", worst);
  EXPECT_LT(worst, 1e-3);
}

TEST(Retarget, AMapFileRetargetsARigWithUnknownNames) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  MOCAP_REQUIRE_SHARED(kDazRig);
  const Clip source = read_bvh(data("mocap/cmu31/07_01.bvh"));
  const Skeleton daz = read_rig(data(kDazRig));
  const RetargetResult automatic = onto_daz(source);
  // The same rig with every joint renamed: nothing maps by name, the map file says it all.
  Skeleton renamed = daz;
  for (SkeletonJoint& j : renamed.joints) j.name = "bone_" + j.name;
  test::TempDir dir;
  std::string map_text = "# cmu31 -> renamed Daz\n";
  for (const JointMatch& m : automatic.matches) {
    map_text += source.skeleton.joints[m.source].name + "  bone_" + daz.joints[m.target].name +
                "  # " + m.how + "\n";
  }
  test::write_file(dir.file("daz.map"), map_text);
  RetargetOptions options;
  options.target_source = "renamed.bvh";
  options.map = read_joint_map(dir.file("daz.map"));
  options.scale = automatic.scale;
  const RetargetResult mapped = retarget(source, renamed, options);
  EXPECT_EQ(mapped.matches.size(), automatic.matches.size());
  ASSERT_EQ(mapped.clip.values.size(), automatic.clip.values.size());
  for (std::size_t i = 0; i < mapped.clip.values.size(); ++i)
    ASSERT_NEAR(mapped.clip.values[i], automatic.clip.values[i], 1e-3) << "value " << i;
  // Without the map: too few joints, and the message says what to do.
  options.map.reset();
  try {
    (void)retarget(source, renamed, options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("renamed.bvh"), std::string::npos) << e.what();
  }
}

TEST(Retarget, AMapNamingAnUnknownJointIsAnErrorNamingTheFileAndLine) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  MOCAP_REQUIRE_SHARED(kDazRig);
  const Clip source = read_bvh(data("mocap/cmu31/07_01.bvh"));
  test::TempDir dir;
  test::write_file(dir.file("bad.map"), "LeftArm lShldr\n\nLeftElbow lForeArm\n");
  RetargetOptions options;
  options.map = read_joint_map(dir.file("bad.map"));
  try {
    (void)onto_daz(source, options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir.file("bad.map") + ":3"), std::string::npos) << what;
    EXPECT_NE(what.find("LeftElbow"), std::string::npos) << what;
  }
  test::write_file(dir.file("target.map"), "LeftArm lUpperArm\n");
  options.map = read_joint_map(dir.file("target.map"));
  try {
    (void)onto_daz(source, options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lUpperArm"), std::string::npos) << e.what();
  }
  test::write_file(dir.file("words.map"), "LeftArm lShldr extra\n");
  EXPECT_THROW((void)read_joint_map(dir.file("words.map")), InputError);
  test::write_file(dir.file("empty.map"), "# nothing\n");
  EXPECT_THROW((void)read_joint_map(dir.file("empty.map")), InputError);
  EXPECT_THROW((void)read_joint_map(dir.file("absent.map")), InputError);
}

TEST(Retarget, GarbageTruncatedOrEmptyRigsAreErrorsNamingTheFile) {
  MOCAP_REQUIRE_SHARED(kDazRig);
  const std::string daz = test::read_file(data(kDazRig));
  test::TempDir dir;
  std::mt19937 random(7);
  std::string noise(4000, '\0');
  for (char& c : noise) c = static_cast<char>(random() & 0xff);
  const std::vector<std::pair<std::string, std::string>> rigs = {
      {"empty.bvh", ""},
      {"blank.bvh", "  \n\t\n"},
      {"truncated.bvh", daz.substr(0, 700)},
      {"header.bvh", "HIERARCHY\n"},
      {"random.bvh", noise},
      {"one_joint.bvh",
       "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition "
       "Zposition\n}\n"},
  };
  for (const auto& [name, text] : rigs) {
    const std::string path = dir.file(name);
    test::write_file(path, text);
    try {
      (void)read_rig(path);
      ADD_FAILURE() << name << ": expected an InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW((void)read_rig(dir.file("absent.bvh")), InputError);
  // The hierarchy alone is a rig.
  const std::string hierarchy = daz.substr(0, daz.find("MOTION"));
  test::write_file(dir.file("bare.bvh"), hierarchy);
  EXPECT_EQ(read_rig(dir.file("bare.bvh")).joint_count(), read_rig(data(kDazRig)).joint_count());
}

// Bandai's zero-rotation pose has every bone along its local +X: not a standing rest pose, and
// the result says so.
TEST(Retarget, ARestPoseThatIsNotStandingIsReported) {
  const std::string bandai = "mocap/bandai/dataset-1/dataset-1_bye_feminine_001.bvh";
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  MOCAP_REQUIRE_SHARED(bandai);
  RetargetOptions options;
  options.target_source = data(bandai);
  const RetargetResult result =
      retarget(read_bvh(data("mocap/cmu31/07_01.bvh")), read_rig(data(bandai)), options);
  ASSERT_FALSE(result.warnings.empty());
  EXPECT_NE(result.warnings.front().find(data(bandai)), std::string::npos);
}

TEST(Retarget, ExplicitScaleMovesTheRootByThatFactor) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  MOCAP_REQUIRE_SHARED(kDazRig);
  const Clip source = read_bvh(data("mocap/cmu31/07_01.bvh"));
  RetargetOptions options;
  options.scale = 2.0f;
  const RetargetResult result = onto_daz(source, options);
  EXPECT_FALSE(result.scale_is_auto);
  const PoseSequence a = to_poses(source), b = to_poses(result.clip);
  for (int f = 0; f < a.frame_count; f += 50) {
    const glm::vec3 expected = 2.0f * a.translation[a.at(f, 0)];
    const glm::vec3 got = b.translation[b.at(f, 0)];
    EXPECT_NEAR(got.x, expected.x, 1e-3);
    EXPECT_NEAR(got.y, expected.y, 1e-3);
    EXPECT_NEAR(got.z, expected.z, 1e-3);
  }
  options.scale = -1.0f;
  EXPECT_THROW((void)onto_daz(source, options), InputError);
}

// Blender, when installed, imports the output (its BVH importer is the reference most users
// meet). Skips without it.
TEST(Retarget, BlenderImportsTheOutput) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  MOCAP_REQUIRE_SHARED(kDazRig);
  if (std::system("command -v blender > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "blender is not installed";
  const RetargetResult result = onto_daz(read_bvh(data("mocap/cmu31/07_01.bvh")));
  test::TempDir dir;
  write_bvh(result.clip, dir.file("daz.bvh"));
  // Debian's Blender 3.4 importer opens files with mode 'rU', which Python 3.11 refuses: the
  // script drops the 'U' before importing.
  test::write_file(dir.file("import.py"),
                   "import builtins, sys, bpy\n"
                   "_open = builtins.open\n"
                   "builtins.open = lambda f, mode='r', *a, **k: _open(f, mode.replace('U', ''), "
                   "*a, **k)\n"
                   "bpy.ops.import_anim.bvh(filepath=sys.argv[sys.argv.index('--') + 1])\n"
                   "ob = bpy.context.object\n"
                   "print('BONES', len(ob.data.bones))\n"
                   "print('FRAMES', *[int(x) for x in ob.animation_data.action.frame_range])\n");
  const std::string command = "timeout 120 blender -b --factory-startup --python '" +
                              dir.file("import.py") + "' -- '" + dir.file("daz.bvh") + "' > '" +
                              dir.file("blender.log") + "' 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << test::read_file(dir.file("blender.log"));
  const std::string log = test::read_file(dir.file("blender.log"));
  EXPECT_NE(log.find("BONES 43"), std::string::npos) << log;
  EXPECT_NE(log.find("FRAMES 1 " + std::to_string(result.clip.frame_count)), std::string::npos)
      << log;
}

}  // namespace
}  // namespace mocap::motion

namespace mocap::motion {
namespace {

// cgspeed's own Daz conversion of the same trials (cmu_daz/) is an independent retarget of the
// same motion onto the same rig. It keeps the rig's rest bends (the Daz forearm points 17 degrees
// forward of the elbow in rest, so its forearms differ from ours by about 20 degrees) and leaves
// the collars still, but trunk, upper arms and legs should point about the same way.
TEST(Retarget, AgreesWithCgspeedsDazConversionOfTheSameTrial) {
  const char* trials[] = {"02_04", "05_01", "07_01", "08_01", "09_01"};
  const std::string agreeing[] = {"abdomen", "lShldr", "rShldr", "lThigh",
                                  "lShin",   "rThigh", "rShin"};
  for (const char* trial : trials) {
    const std::string daz_name = std::string("mocap/cmu_daz/") + trial + ".bvh";
    const std::string cmu_name = std::string("mocap/cmu31/") + trial + ".bvh";
    MOCAP_REQUIRE_SHARED(daz_name);
    MOCAP_REQUIRE_SHARED(cmu_name);
    const Clip reference = read_bvh(data(daz_name));
    const Clip source = read_bvh(data(cmu_name));
    RetargetOptions options;
    options.target_source = data(daz_name);
    const RetargetResult ours = retarget(source, reference.skeleton, options);
    ASSERT_EQ(ours.clip.frame_count, reference.frame_count);
    const PoseSequence a = to_poses(reference), b = to_poses(ours.clip);
    GlobalPose ga, gb;
    std::string line = std::string("[ retarget ] ") + trial +
                       " ours vs cgspeed's Daz file, bone direction median/max deg:";
    for (const NamedBone& bone : kDazBones) {
      const int t0 = reference.skeleton.find(bone.target_from);
      const int t1 = reference.skeleton.find(bone.target_to);
      std::vector<double> e;
      for (int f = 1; f < a.frame_count; ++f) {  // frame 0 is the inserted T-pose
        forward_kinematics(a, f, ga);
        forward_kinematics(b, f, gb);
        e.push_back(
            angle_degrees(ga.position[t1] - ga.position[t0], gb.position[t1] - gb.position[t0]));
      }
      const double m = median(e);
      char text[96];
      std::snprintf(text, sizeof text, " %s %.1f/%.1f", bone.target_from, m,
                    *std::max_element(e.begin(), e.end()));
      line += text;
      if (std::find(std::begin(agreeing), std::end(agreeing), bone.target_from) !=
          std::end(agreeing)) {
        EXPECT_LT(m, 12.0) << trial << " " << bone.target_from;
      }
    }
    std::printf("%s\n", line.c_str());
  }
}

}  // namespace
}  // namespace mocap::motion
