#include "recon/layout_offsets.hpp"

#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/input_error.hpp"

namespace mocap::recon {
namespace {

LayoutOffsets example() {
  LayoutOffsets o;
  o.layout = LayoutId::coco17;
  o.joints[index(Joint::neck)] = {OffsetBasis::shoulders, 0.05f, -0.01f, 0.03f};
  o.joints[index(Joint::right_shoulder)] = {OffsetBasis::shoulders, 0.02f, 0.04f, 0.0f};
  o.joints[index(Joint::left_hip)] = {OffsetBasis::hips, -0.05f, -0.09f, -0.08f};
  o.joints[index(Joint::root)] = {OffsetBasis::hips, -0.04f, 0.0f, 0.1f};
  o.joints[index(Joint::right_elbow)] = {OffsetBasis::bone, 0.1f, 0.0f, 0.0f};
  return o;
}

std::string message_of(std::string_view text) {
  try {
    parse_layout_offsets(text, "offsets.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(LayoutOffsetsFile, RoundTrip) {
  const LayoutOffsets o = example();
  const std::string text = format_layout_offsets(o, "a header\nof two lines");
  EXPECT_EQ(text.rfind("# a header\n# of two lines\nformat: ", 0), 0u) << text;
  const LayoutOffsets back = parse_layout_offsets(text, "x.yaml");
  EXPECT_EQ(back.layout, LayoutId::coco17);
  EXPECT_EQ(back.source, "x.yaml");
  for (int j = 0; j < kBodyJoints; ++j) {
    EXPECT_EQ(back.joints[j].basis, o.joints[j].basis) << kJointNames[j];
    EXPECT_NEAR(back.joints[j].along, o.joints[j].along, 1e-4) << kJointNames[j];
    EXPECT_NEAR(back.joints[j].lateral, o.joints[j].lateral, 1e-4) << kJointNames[j];
    EXPECT_NEAR(back.joints[j].forward, o.joints[j].forward, 1e-4) << kJointNames[j];
  }
}

TEST(LayoutOffsetsFile, GarbageAndTruncationNameTheFileAndLine) {
  const std::string good = format_layout_offsets(example(), "");
  // Truncated in the middle of a joint line and after a few joints.
  const std::string cut_line = good.substr(0, good.find("right_elbow") + 20);
  EXPECT_NE(message_of(cut_line).find("offsets.yaml:"), std::string::npos) << message_of(cut_line);
  const std::string cut = good.substr(0, good.find("  left_wrist"));
  const std::string m = message_of(cut);
  EXPECT_NE(m.find("offsets.yaml:"), std::string::npos) << m;
  EXPECT_NE(m.find("left_wrist"), std::string::npos) << m;
  EXPECT_NE(m.find("truncated"), std::string::npos) << m;
  // Binary garbage, empty, random text.
  std::string binary = "format: mocap-layout-offsets/1\nlayout: COCO-17\n\x01\x02\xff\xfe";
  EXPECT_NE(message_of(binary).find("offsets.yaml:3:"), std::string::npos) << message_of(binary);
  EXPECT_NE(message_of("").find("offsets.yaml"), std::string::npos);
  EXPECT_NE(message_of("hello world").find("offsets.yaml:1:"), std::string::npos);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    std::string noise = good;
    for (int k = 0; k < 5; ++k) noise[rng() % noise.size()] = static_cast<char>(rng() % 256);
    try {
      parse_layout_offsets(noise, "offsets.yaml");  // may still be valid
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("offsets.yaml"), std::string::npos) << e.what();
    }
  }
}

TEST(LayoutOffsetsFile, RejectsWrongContentWithItsLine) {
  const std::string head = "format: mocap-layout-offsets/1\nlayout: BODY_25B\njoints:\n";
  EXPECT_NE(message_of(head + "  elbow: {basis: none}\n").find(":4: unknown joint 'elbow'"),
            std::string::npos);
  EXPECT_NE(message_of(head + "  head: {basis: none}\n  head: {basis: none}\n").find(":5:"),
            std::string::npos);
  EXPECT_NE(message_of(head + "  head: {basis: shoulders, along: x1, lateral: 0}\n")
                .find(":4: 'along' is not a number"),
            std::string::npos);
  EXPECT_NE(message_of(head + "  head: {basis: shoulders, along: 30, lateral: 0}\n").find("beyond"),
            std::string::npos);
  EXPECT_NE(message_of(head + "  head: {basis: sideways, along: 0.1}\n").find("unknown basis"),
            std::string::npos);
  EXPECT_NE(
      message_of(head + "  head: {basis: bone, along: 0.1, lateral: 0.2}\n").find("'lateral' only"),
      std::string::npos);
  EXPECT_NE(
      message_of("format: mocap-layout-offsets/1\nlayout: COCO-99\n").find(":2: unknown layout"),
      std::string::npos);
  EXPECT_NE(message_of("layout: BODY_25B\n").find(":1: the first entry must be"),
            std::string::npos);
}

TEST(LayoutOffsetsFile, LoadNamesAMissingFile) {
  try {
    load_layout_offsets("/nonexistent/dir/body25b.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/body25b.yaml"), std::string::npos);
  }
}

// The repository's calibration files (tests run from the repository root) are valid and each is
// for the layout its name says.
TEST(LayoutOffsetsFile, ShippedFilesLoad) {
  int found = 0;
  for (const KeypointLayout& l : all_layouts()) {
    const std::filesystem::path file =
        std::filesystem::path("calibration/layouts") / layout_offsets_file_name(l.id);
    if (!std::filesystem::exists(file)) continue;
    ++found;
    const LayoutOffsets o = load_layout_offsets(file);
    EXPECT_EQ(o.layout, l.id) << file;
    const auto resolved = resolve_layout_offsets(file.string(), l.id);
    ASSERT_TRUE(resolved.has_value());
  }
  EXPECT_GE(found, 2) << "calibration/layouts/*.yaml not found from "
                      << std::filesystem::current_path();
  EXPECT_FALSE(resolve_layout_offsets("off", LayoutId::body25b).has_value());
  EXPECT_THROW(resolve_layout_offsets("calibration/layouts/body25b.yaml", LayoutId::humaneva15),
               InputError);
}

std::array<glm::vec3, kBodyJoints> standing_body() {
  std::array<glm::vec3, kBodyJoints> b;
  b[index(Joint::root)] = {0.0f, 1.0f, 0.0f};
  b[index(Joint::right_hip)] = {-0.09f, 1.0f, 0.01f};
  b[index(Joint::left_hip)] = {0.09f, 1.0f, -0.01f};
  b[index(Joint::right_shoulder)] = {-0.18f, 1.5f, 0.02f};
  b[index(Joint::left_shoulder)] = {0.18f, 1.5f, 0.0f};
  b[index(Joint::neck)] = {0.0f, 1.53f, 0.0f};
  b[index(Joint::head)] = {0.0f, 1.72f, 0.03f};
  b[index(Joint::right_elbow)] = {-0.25f, 1.22f, 0.05f};
  b[index(Joint::right_wrist)] = {-0.3f, 0.98f, 0.15f};
  b[index(Joint::left_elbow)] = {0.25f, 1.22f, 0.0f};
  b[index(Joint::left_wrist)] = {0.3f, 0.98f, 0.1f};
  b[index(Joint::right_knee)] = {-0.1f, 0.55f, 0.05f};
  b[index(Joint::right_ankle)] = {-0.1f, 0.1f, 0.0f};
  b[index(Joint::left_knee)] = {0.1f, 0.55f, 0.0f};
  b[index(Joint::left_ankle)] = {0.1f, 0.1f, 0.0f};
  return b;
}

// Under orthographic projection the 2D correction is the projection of the 3D one (its in-plane
// part: forward is left out in 2D), whatever the body's rotation.
TEST(LayoutOffsetsApply, TwoDimensionalIsTheProjectionOfThreeDimensional) {
  LayoutOffsets o = example();
  for (auto& j : o.joints) j.forward = 0.0f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> angle(-3.1f, 3.1f);
  for (int trial = 0; trial < 20; ++trial) {
    const glm::quat q =
        glm::angleAxis(angle(rng), glm::normalize(glm::vec3(angle(rng), angle(rng), angle(rng))));
    std::array<glm::vec3, kBodyJoints> body = standing_body();
    for (auto& p : body) p = q * p;
    std::array<float, kBodyJoints * 3> xyc;
    for (int j = 0; j < kBodyJoints; ++j) {
      xyc[3 * j] = 500.0f * body[j].x;  // orthographic, 500 px per metre
      xyc[3 * j + 1] = 500.0f * body[j].y;
      xyc[3 * j + 2] = 0.9f;
    }
    apply_layout_offsets(o, xyc);
    apply_layout_offsets_3d(o, body);
    for (int j = 0; j < kBodyJoints; ++j) {
      EXPECT_NEAR(xyc[3 * j], 500.0f * body[j].x, 1e-3) << kJointNames[j];
      EXPECT_NEAR(xyc[3 * j + 1], 500.0f * body[j].y, 1e-3) << kJointNames[j];
      EXPECT_EQ(xyc[3 * j + 2], 0.9f);
    }
  }
  // And the correction moves something: the neck goes up the trunk by 5 % of it.
  std::array<glm::vec3, kBodyJoints> body = standing_body();
  apply_layout_offsets_3d(o, body);
  EXPECT_NEAR(body[index(Joint::neck)].y - 1.53f, 0.05f * 0.5f, 1e-4);
}

TEST(LayoutOffsetsApply, ForwardIsTowardsTheFrontAndTheInverseUndoesAxialJoints) {
  LayoutOffsets o;  // HumanEva-like: only neck, head and root move; none is a basis joint
  o.layout = LayoutId::humaneva15;
  o.joints[index(Joint::root)] = {OffsetBasis::hips, -0.03f, 0.0f, 0.1f};
  o.joints[index(Joint::neck)] = {OffsetBasis::shoulders, 0.02f, -0.03f, -0.08f};
  const auto body = standing_body();  // faces +z: left is +x, up +y
  auto moved = body;
  apply_layout_offsets_3d(o, moved);
  EXPECT_GT(moved[index(Joint::root)].z, body[index(Joint::root)].z + 0.03f);
  apply_layout_offsets_3d(o, moved, -1.0f);
  for (int j = 0; j < kBodyJoints; ++j)
    EXPECT_NEAR(glm::length(moved[j] - body[j]), 0.0f, 1e-5) << kJointNames[j];
}

TEST(LayoutOffsetsApply, MissingBasisJointLeavesTheJoint) {
  const LayoutOffsets o = example();
  std::array<float, kBodyJoints * 3> xyc;
  const auto body = standing_body();
  for (int j = 0; j < kBodyJoints; ++j) {
    xyc[3 * j] = body[j].x;
    xyc[3 * j + 1] = body[j].y;
    xyc[3 * j + 2] = 1.0f;
  }
  xyc[3 * index(Joint::left_hip) + 2] = 0.0f;  // missing: trunk bases cannot be formed
  const auto before = xyc;
  apply_layout_offsets(o, xyc);
  EXPECT_EQ(xyc[3 * index(Joint::neck)], before[3 * index(Joint::neck)]);
  EXPECT_EQ(xyc[3 * index(Joint::neck) + 1], before[3 * index(Joint::neck) + 1]);
  // The elbow's bone basis needs only the shoulder: it still moves.
  EXPECT_NE(xyc[3 * index(Joint::right_elbow) + 1], before[3 * index(Joint::right_elbow) + 1]);
}

}  // namespace
}  // namespace mocap::recon
