#include "io/humaneva.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "npy_fixtures.hpp"
#include "support/shared_data.hpp"

namespace mocap::io::humaneva {
namespace {

using io::test::npy_bytes;
using io::test::PickleWriter;
using io::test::raw_bytes;
using io::test::zip_bytes;

const char* const kFolder = "eval/humaneva_i_videopose3d";

std::filesystem::path folder() { return ::mocap::test::shared_data() / kFolder; }

TEST(HumanEva, FrameRangesOfPrepareDataHumanEva) {
  EXPECT_EQ(frame_range(Split::train, "S1", "Walking")->begin, 590);
  EXPECT_EQ(frame_range(Split::train, "S1", "Walking")->end, 1203);
  EXPECT_EQ(frame_range(Split::validate, "S1", "Walking")->end, 590);
  EXPECT_EQ(frame_range(Split::validate, "S3", "Box")->size(), 507);
  EXPECT_FALSE(frame_range(Split::train, "S4", "Walking").has_value());
  EXPECT_FALSE(frame_range(Split::train, "S1", "Walk").has_value());
  // Validate ends where Train begins, for every subject and action.
  for (const char* s : {"S1", "S2", "S3"}) {
    for (const char* a : {"Walking", "Jog", "ThrowCatch", "Gestures", "Box"}) {
      EXPECT_EQ(frame_range(Split::validate, s, a)->end, frame_range(Split::train, s, a)->begin);
    }
  }
}

TEST(HumanEva, Body15TakesTheHumanEvaJoints) {
  Pose3 pose;
  for (int j = 0; j < kJoints; ++j) pose[j] = glm::vec3(static_cast<float>(j), 0, 0);
  const auto body = to_body15(pose);
  EXPECT_EQ(body[index(Joint::root)].x, 0.0f);           // pelvis
  EXPECT_EQ(body[index(Joint::neck)].x, 1.0f);           // thorax
  EXPECT_EQ(body[index(Joint::head)].x, 14.0f);          // head
  EXPECT_EQ(body[index(Joint::left_shoulder)].x, 2.0f);  // HumanEva lists left first
  EXPECT_EQ(body[index(Joint::right_ankle)].x, 13.0f);
}

// ---- the shared files -------------------------------------------------------------------------

class HumanEvaShared : public ::testing::Test {
 protected:
  void SetUp() override {
    MOCAP_REQUIRE_SHARED(std::string(kFolder) + "/" + std::string(kPositions2dFile));
  }
  // Loaded once for all tests of the suite (the files take a second to read); never modified.
  static const Dataset& data() {
    static const Dataset dataset = load_dataset(folder());
    return dataset;
  }
};

TEST_F(HumanEvaShared, CountsMatchTheReadme) {
  EXPECT_EQ(data().chunks.size(), 77u);
  std::size_t frames = 0;
  std::map<std::string, std::size_t> per_subject;
  std::map<std::string, std::map<std::string, std::size_t>> per_action;
  for (const auto& c : data().chunks) {
    frames += c.frames();
    const std::string subject = std::string(to_string(c.split)) + "/" + c.subject;
    per_subject[subject] += c.frames();
    per_action[subject][c.action] += c.frames();
    for (int k = 0; k < kCameras; ++k) EXPECT_EQ(c.positions_2d[k].size(), c.frames());
  }
  EXPECT_EQ(frames, 9577u);
  const std::map<std::string, std::size_t> readme = {{"Train/S1", 1601},    {"Train/S2", 1754},
                                                     {"Train/S3", 1374},    {"Validate/S1", 1514},
                                                     {"Validate/S2", 1855}, {"Validate/S3", 1479}};
  EXPECT_EQ(per_subject, readme);
  EXPECT_EQ(per_action["Train/S1"]["Walking"], 613u);
  EXPECT_EQ(per_action["Validate/S3"]["Box"], 507u);
  EXPECT_EQ(per_action["Train/S3"].count("ThrowCatch"), 0u);
  EXPECT_EQ(per_action["Validate/S1"].count("ThrowCatch"), 0u);
  EXPECT_EQ(data().select(Split::validate).size(), 42u);
  EXPECT_EQ(data().select(Split::validate, "S2", "ThrowCatch").size(), 7u);
  const auto lengths = [&] {
    std::vector<std::size_t> n;
    for (const auto& c : data().chunks) n.push_back(c.frames());
    return n;
  }();
  EXPECT_EQ(*std::min_element(lengths.begin(), lengths.end()), 2u);
  EXPECT_EQ(*std::max_element(lengths.begin(), lengths.end()), 613u);
}

// Values printed by NumPy 1.24 from the same files.
TEST_F(HumanEvaShared, ValuesMatchNumpy) {
  const auto walking = data().select(Split::train, "S1", "Walking");
  ASSERT_EQ(walking.size(), 1u);
  const Chunk& w = *walking[0];
  EXPECT_EQ(w.key, "Walking 1 chunk0");
  EXPECT_EQ(w.chunk, 0);
  EXPECT_EQ(w.first_frame, 590);
  EXPECT_EQ(w.frames(), 613u);
  EXPECT_FLOAT_EQ(w.positions_3d[0][0].x, 0.87662214f);
  EXPECT_FLOAT_EQ(w.positions_3d[0][0].y, -0.09243166f);
  EXPECT_FLOAT_EQ(w.positions_3d[0][0].z, 0.8248082f);
  double sum = 0.0;
  for (const auto& pose : w.positions_3d) {
    for (const auto& j : pose) sum += static_cast<double>(j.x) + j.y + j.z;
  }
  EXPECT_NEAR(sum, 9044.253362450283, 1e-6);
  const auto jog = data().select(Split::validate, "S2", "Jog");
  ASSERT_EQ(jog.size(), 1u);
  EXPECT_FLOAT_EQ(jog[0]->positions_2d[2][3][4].x, 216.94347f);
  EXPECT_FLOAT_EQ(jog[0]->positions_2d[2][3][4].y, 185.95317f);
  double sum2 = 0.0, sum3 = 0.0;
  for (const auto& c : data().chunks) {
    for (const auto& pose : c.positions_3d) {
      for (const auto& j : pose) sum3 += static_cast<double>(j.x) + j.y + j.z;
    }
    for (const auto& cam : c.positions_2d) {
      for (const auto& pose : cam) {
        for (const auto& j : pose) sum2 += static_cast<double>(j.x) + j.y;
      }
    }
  }
  EXPECT_NEAR(sum3, 131428.26971739792, 1e-5);
  EXPECT_NEAR(sum2, 222051655.9989853, 1e-3);
}

TEST_F(HumanEvaShared, ChunksLieInsideTheirRanges) {
  for (const auto& c : data().chunks) {
    const auto range = frame_range(c.split, c.subject, c.action);
    ASSERT_TRUE(range.has_value());
    EXPECT_EQ(c.range.begin, range->begin);
    EXPECT_LE(static_cast<int>(c.frames()), range->size()) << c.key;
    EXPECT_EQ(c.first_frame.has_value(), c.chunk == 0);
    EXPECT_EQ(c.trial, 1);
  }
}

// README: Z up, metres; pelvis about 0.84 m and head about 1.58 m above the floor (Train/S1
// Walking).
TEST_F(HumanEvaShared, WorldIsZUpInMetres) {
  const Chunk& w = *data().select(Split::train, "S1", "Walking")[0];
  double pelvis = 0.0, head = 0.0;
  for (const auto& pose : w.positions_3d) pelvis += pose[0].z, head += pose[14].z;
  EXPECT_NEAR(pelvis / static_cast<double>(w.frames()), 0.84, 0.01);
  EXPECT_NEAR(head / static_cast<double>(w.frames()), 1.58, 0.01);
  float u_min = 1e9f, u_max = -1e9f;
  for (const auto& c : data().chunks) {
    for (const auto& cam : c.positions_2d) {
      for (const auto& pose : cam) {
        for (const auto& j : pose) u_min = std::min(u_min, j.x), u_max = std::max(u_max, j.x);
      }
    }
  }
  EXPECT_NEAR(u_min, 24.8f, 0.05f);
  EXPECT_NEAR(u_max, 570.5f, 0.05f);
}

// Projecting the 3D truth through the cameras reproduces the 2D truth: median residual about a
// pixel, maximum about 24 px (the lens distortion the pinhole model leaves out; README).
TEST_F(HumanEvaShared, CamerasProjectThe3dTruthOntoThe2dTruth) {
  const auto cameras = load_cameras(folder() / kCamerasFile);
  ASSERT_EQ(cameras.size(), 3u);
  for (const char* subject : {"S1", "S2", "S3"}) {
    for (int k = 0; k < kCameras; ++k) {
      const camera::Camera& cam = cameras.at(subject).cameras.at(k);
      EXPECT_EQ(cam.name, kCameraNames[k]);
      std::vector<double> residuals;
      for (const Chunk* c : data().select(std::nullopt, subject)) {
        for (std::size_t t = 0; t < c->frames(); t += 5) {
          for (int j = 0; j < kJoints; ++j) {
            const glm::dvec3 world(c->positions_3d[t][j]);
            EXPECT_GT(cam.to_camera(world).z, 0.5);
            const glm::dvec2 uv = cam.project(world);
            residuals.push_back(glm::length(uv - glm::dvec2(c->positions_2d[k][t][j])));
          }
        }
      }
      std::sort(residuals.begin(), residuals.end());
      EXPECT_LT(residuals[residuals.size() / 2], 2.0) << subject << " " << cam.name;
      EXPECT_LT(residuals.back(), 30.0) << subject << " " << cam.name;
    }
  }
}

// ---- synthetic archives for the error paths ---------------------------------------------------

// An .npz with one member `member` = {subject: {action: value}}: the value is a float32 array
// (frames, 15, dims), or with `cameras` > 0 a list of that many such arrays (like positions_2d).
struct NpzSpec {
  std::string member = "positions_3d";
  std::string subject = "Train/S1";
  std::string action = "Box 1 chunk0";
  int frames = 3;
  int dims = 3;
  float value = 0.5f;
  int cameras = 0;
};

std::string write_npz(const ::mocap::test::TempDir& dir, const std::string& name,
                      const NpzSpec& s) {
  const auto array = [&](PickleWriter& q) {
    q.ndarray({s.frames, kJoints, s.dims}, "f4", "<", false, [&](PickleWriter& r) {
      r.bin(raw_bytes(
          std::vector<float>(static_cast<std::size_t>(s.frames) * kJoints * s.dims, s.value)));
    });
  };
  PickleWriter w;
  w.proto(3).ndarray({}, "O8", "|", false, [&](PickleWriter& p) {
    p.op(']').mark().op('}').mark().str(s.subject).op('}').mark().str(s.action);
    if (s.cameras == 0) {
      array(p);
    } else {
      p.op(']').mark();
      for (int k = 0; k < s.cameras; ++k) array(p);
      p.op('e');
    }
    p.op('u').op('u').op('e');
  });
  const std::string npz =
      zip_bytes({{s.member + ".npy", npy_bytes("|O", "()", false, w.stop().bytes())}});
  std::ofstream(dir.file(name), std::ios::binary) << npz;
  return dir.file(name);
}

NpzSpec with(void (*change)(NpzSpec&)) {
  NpzSpec s;
  change(s);
  return s;
}

std::string load_error(const std::string& path) {
  try {
    read_positions_3d(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(HumanEvaSynthetic, ReadsAndRejects) {
  ::mocap::test::TempDir dir;
  const Dataset d = read_positions_3d(write_npz(dir, "ok.npz", with([](NpzSpec& s) {
                                                  s.subject = "Validate/S2";
                                                  s.action = "Box 1 chunk4";
                                                })));
  ASSERT_EQ(d.chunks.size(), 1u);
  EXPECT_EQ(d.chunks[0].split, Split::validate);
  EXPECT_EQ(d.chunks[0].subject, "S2");
  EXPECT_EQ(d.chunks[0].action, "Box");
  EXPECT_EQ(d.chunks[0].chunk, 4);
  EXPECT_FALSE(d.chunks[0].first_frame.has_value());
  EXPECT_EQ(d.chunks[0].positions_3d[2][14].z, 0.5f);

  const auto error = [&](const NpzSpec& spec) {
    return load_error(write_npz(dir, "bad.npz", spec));
  };
  EXPECT_NE(error(with([](NpzSpec& s) { s.subject = "Test/S1"; })).find("Train/<S>"),
            std::string::npos);
  EXPECT_NE(error(with([](NpzSpec& s) { s.action = "Box chunk0"; })).find("<Action>"),
            std::string::npos);
  EXPECT_NE(error(with([](NpzSpec& s) { s.subject = "Train/S9"; })).find("frame range"),
            std::string::npos);
  EXPECT_NE(error(with([](NpzSpec& s) { s.dims = 2; })).find("(frames, 15, 3)"), std::string::npos);
  EXPECT_NE(error(with([](NpzSpec& s) { s.value = std::nanf(""); })).find("NaN"),
            std::string::npos);
  EXPECT_NE(error(with([](NpzSpec& s) { s.frames = 500; })).find("more frames"), std::string::npos);
  EXPECT_NE(error(with([](NpzSpec& s) { s.member = "other"; })).find("no array 'positions_3d'"),
            std::string::npos);
  EXPECT_NE(load_error(dir.file("absent.npz")).find("absent.npz"), std::string::npos);
}

std::string attach_error(const ::mocap::test::TempDir& dir, const NpzSpec& spec) {
  Dataset d = read_positions_3d(write_npz(dir, "three.npz", NpzSpec{}));
  try {
    attach_positions_2d(d, write_npz(dir, "two.npz", spec));
  } catch (const InputError& e) {
    return e.what();
  }
  EXPECT_EQ(d.chunks[0].positions_2d[2].size(), 3u);
  return "";
}

TEST(HumanEvaSynthetic, TwoDimensionalTruthMustMatch) {
  ::mocap::test::TempDir dir;
  const auto two_d = [](NpzSpec& s) {
    s.member = "positions_2d";
    s.dims = 2;
    s.cameras = 3;
  };
  EXPECT_EQ(attach_error(dir, with(two_d)), "");
  EXPECT_NE(attach_error(dir, with([](NpzSpec& s) {
                           s.member = "positions_2d", s.dims = 2, s.cameras = 3, s.frames = 4;
                         }))
                .find("4 2D frames for 3 3D frames"),
            std::string::npos);
  EXPECT_NE(attach_error(
                dir, with([](NpzSpec& s) { s.member = "positions_2d", s.dims = 2, s.cameras = 2; }))
                .find("expected 3 cameras"),
            std::string::npos);
  EXPECT_NE(attach_error(dir, with([](NpzSpec& s) {
                           s.member = "positions_2d", s.dims = 2, s.cameras = 3,
                           s.action = "Jog 1 chunk0";
                         }))
                .find("has no 3D chunk"),
            std::string::npos);
  EXPECT_NE(attach_error(
                dir, with([](NpzSpec& s) { s.member = "positions_2d", s.dims = 3, s.cameras = 3; }))
                .find("(frames, 15, 2)"),
            std::string::npos);
}

TEST(HumanEvaSynthetic, CameraFileErrorsNameTheKey) {
  ::mocap::test::TempDir dir;
  std::ofstream(dir.file("cams.json")) << R"({"extrinsics": {"S1": [
      {"id": "C1", "orientation": [1, 0, 0, 0], "translation_mm": [0, 0, 0]},
      {"id": "C2", "orientation": [1, 0, 0], "translation_mm": [0, 0, 0]},
      {"id": "C3", "orientation": [1, 0, 0, 0], "translation_mm": [0, 0, 0]}]},
      "approx_intrinsics_fitted": {}})";
  try {
    load_cameras(dir.file("cams.json"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("approx_intrinsics_fitted.C1"), std::string::npos)
        << e.what();
  }
  std::ofstream(dir.file("cams2.json")) << R"({"extrinsics": {"S1": [
      {"id": "C1", "orientation": [1, 0, 0, 0], "translation_mm": [0, 0, 0]},
      {"id": "C2", "orientation": [1, 0, 0], "translation_mm": [0, 0, 0]},
      {"id": "C3", "orientation": [1, 0, 0, 0], "translation_mm": [0, 0, 0]}]},
      "approx_intrinsics_fitted": {"C1": {"fx": 1, "fy": 1, "cx": 0, "cy": 0}}})";
  try {
    load_cameras(dir.file("cams2.json"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("extrinsics.S1[1].orientation"), std::string::npos)
        << e.what();
  }
  std::ofstream(dir.file("cams3.json")) << "{";
  EXPECT_THROW(load_cameras(dir.file("cams3.json")), InputError);
}

}  // namespace
}  // namespace mocap::io::humaneva
