#include "io/openpose_json.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "support/shared_data.hpp"

namespace mocap::io {
namespace {

using test::TempDir;

void write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// One person as OpenPose writes it: `keypoints` triples, then the arrays the reader ignores.
std::string person_json(const std::vector<float>& xyc, const std::string& id = "[-1]") {
  std::ostringstream out;
  out << "{\"person_id\":" << id << ",\"pose_keypoints_2d\":[";
  for (std::size_t i = 0; i < xyc.size(); ++i) out << (i ? "," : "") << xyc[i];
  out << "],\"face_keypoints_2d\":[],\"hand_left_keypoints_2d\":[],\"hand_right_keypoints_2d\":[],"
         "\"pose_keypoints_3d\":[],\"face_keypoints_3d\":[],\"hand_left_keypoints_3d\":[],"
         "\"hand_right_keypoints_3d\":[]}";
  return out.str();
}

std::string frame_json(const std::vector<std::string>& people) {
  std::string out = "{\"version\":1.3,\"people\":[";
  for (std::size_t i = 0; i < people.size(); ++i) out += (i ? "," : "") + people[i];
  return out + "]}";
}

// A standing person, 1.7 units tall in image pixels ×100, as BODY_25 (neck between the
// shoulders, eyes beside the nose, ankles far below).
std::vector<float> body25_person(float dx = 0.0f) {
  const float p[25][2] = {{0, 0},     {0, 20},    {-20, 20},  {-25, 50},  {-25, 80},
                          {20, 20},   {25, 50},   {25, 80},   {0, 80},    {-10, 80},
                          {-10, 120}, {-10, 160}, {10, 80},   {10, 120},  {10, 160},
                          {-3, -3},   {3, -3},    {-7, -1},   {7, -1},    {12, 168},
                          {14, 166},  {9, 163},   {-12, 168}, {-14, 166}, {-9, 163}};
  std::vector<float> xyc;
  for (const auto& k : p) xyc.insert(xyc.end(), {300 + dx + k[0], 200 + k[1], 0.9f});
  return xyc;
}

// The same person in BODY_25B order (COCO-17, then neck, head top, feet).
std::vector<float> body25b_person() {
  const std::vector<float> b = body25_person();
  const int from_body25[17] = {0, 16, 15, 18, 17, 5, 2, 6, 3, 7, 4, 12, 9, 13, 10, 14, 11};
  std::vector<float> xyc;
  for (int k : from_body25) xyc.insert(xyc.end(), {b[3 * k], b[3 * k + 1], b[3 * k + 2]});
  xyc.insert(xyc.end(), {300, 212, 0.9f, 300, 190, 0.9f});  // neck, head top
  for (int k = 19; k < 25; ++k) xyc.insert(xyc.end(), {b[3 * k], b[3 * k + 1], b[3 * k + 2]});
  return xyc;
}

TEST(OpenPoseJson, ParsesPeopleIdsBoxesAndMissingKeypoints) {
  std::vector<float> a = body25_person();
  a[3 * 4] = a[3 * 4 + 1] = a[3 * 4 + 2] = 0.0f;  // right wrist undetected: (0, 0, 0)
  const People2D f = parse_openpose_json(
      frame_json({person_json(a), person_json(body25_person(100), "7"), person_json({}, "[3]")}),
      "frame.json");
  EXPECT_EQ(f.layout, LayoutId::body25);
  ASSERT_EQ(f.people.size(),
            2u);  // the person with no pose keypoints (face or hands only) is skipped
  EXPECT_EQ(f.people[0].id, -1);
  EXPECT_EQ(f.people[1].id, 7);
  ASSERT_EQ(f.people[0].joints.size(), 25u);
  EXPECT_TRUE(std::isnan(f.people[0].joints[4].x));
  EXPECT_EQ(f.people[0].joints[4].confidence, 0.0f);
  EXPECT_FLOAT_EQ(f.people[0].joints[1].y, 220.0f);
  EXPECT_FLOAT_EQ(f.people[0].box.x, 275.0f);  // x from 300 - 25 ...
  EXPECT_FLOAT_EQ(f.people[0].box.width, 50.0f);
  EXPECT_FLOAT_EQ(f.people[0].box.height, 171.0f);  // ... y from 197 to 368
}

TEST(OpenPoseJson, LayoutFromTheKeypointCount) {
  const std::vector<float> coco18(18 * 3, 1.0f), coco17(17 * 3, 1.0f);
  EXPECT_EQ(parse_openpose_json(frame_json({person_json(coco18)}), "a").layout, LayoutId::coco18);
  EXPECT_EQ(parse_openpose_json(frame_json({person_json(coco17)}), "a").layout, LayoutId::coco17);
  const std::string b = frame_json({person_json(body25b_person())});
  EXPECT_EQ(parse_openpose_json(b, "a").layout, LayoutId::body25);  // the caller's default
  EXPECT_EQ(parse_openpose_json(b, "a", {Body25Choice::body25b}).layout, LayoutId::body25b);
  EXPECT_EQ(parse_openpose_json(b, "a", {Body25Choice::detect}).layout, LayoutId::body25b);
  const std::string a = frame_json({person_json(body25_person())});
  EXPECT_EQ(parse_openpose_json(a, "a", {Body25Choice::detect}).layout, LayoutId::body25);
  EXPECT_EQ(parse_openpose_json(frame_json({}), "a", {Body25Choice::detect}).layout,
            LayoutId::body25);
}

TEST(OpenPoseJson, Body25VotesAbstainWithoutEvidence) {
  People2D f = parse_openpose_json(frame_json({person_json(body25_person())}), "a");
  EXPECT_EQ(vote_body25_variant(f).body25, 1);
  // A lone head: eye to nose is half the head's extent; that must not vote.
  for (int k = 0; k < 25; ++k) {
    if (k != 0 && k != 15 && k != 16 && k != 17 && k != 18) f.people[0].joints[k].confidence = 0;
  }
  EXPECT_EQ(vote_body25_variant(f).abstained, 1);
}

std::string error_of(const std::string& text) {
  try {
    parse_openpose_json(text, "bad.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(OpenPoseJson, MalformedInputNamesFileAndKey) {
  const std::string good = person_json(body25_person());
  EXPECT_NE(error_of("").find("bad.json: empty file"), std::string::npos);
  EXPECT_NE(error_of(frame_json({good}).substr(0, 100)).find("not valid JSON"), std::string::npos);
  EXPECT_NE(error_of("[1,2]").find("not a JSON object"), std::string::npos);
  EXPECT_NE(error_of("{\"version\":1.3}").find("no \"people\""), std::string::npos);
  EXPECT_NE(error_of(frame_json({person_json(std::vector<float>(74, 1.0f))}))
                .find("people[0].pose_keypoints_2d holds 74 values"),
            std::string::npos);
  EXPECT_NE(error_of(frame_json({person_json(std::vector<float>(60, 1.0f))})).find("20 keypoints"),
            std::string::npos);
  EXPECT_NE(error_of(frame_json({good, person_json(std::vector<float>(54, 1.0f))}))
                .find("people[1] has 18 keypoints but earlier people have 25"),
            std::string::npos);
  std::string with_nan = frame_json({good});
  with_nan.replace(with_nan.find("300"), 3, "NaN");
  EXPECT_NE(error_of(with_nan).find("not valid JSON"), std::string::npos);
  std::string with_null = frame_json({good});
  with_null.replace(with_null.find("300"), 3, "null");
  EXPECT_NE(error_of(with_null).find("people[0].pose_keypoints_2d[0] is not a finite number"),
            std::string::npos);
  std::string huge = frame_json({good});
  huge.replace(huge.find("300"), 3, "1e999");
  EXPECT_NE(error_of(huge).find("number overflow"), std::string::npos);
  EXPECT_NE(error_of("{\"people\":[{\"person_id\":[-1]}]}").find("missing or not an array"),
            std::string::npos);
  EXPECT_NE(error_of("{\"people\":[5]}").find("people[0] is not an object"), std::string::npos);
}

// Every prefix and many random corruptions of a valid file either parse or throw InputError.
TEST(OpenPoseJson, CorruptedTextNeverCrashes) {
  const std::string good =
      frame_json({person_json(body25_person()), person_json(body25_person(50))});
  for (std::size_t n = 0; n < good.size(); n += 7) {
    EXPECT_THROW(parse_openpose_json(good.substr(0, n), "cut.json"), InputError);
  }
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::size_t> where(0, good.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string text = good;
    for (int k = 0; k < 3; ++k) text[where(rng)] = static_cast<char>(byte(rng));
    try {
      parse_openpose_json(text, "flipped.json");
    } catch (const InputError&) {
    }
  }
}

// What the writer writes reads back to the same people: ids, keypoints, a missing keypoint (NaN or
// confidence 0) as OpenPose's 0, 0, 0; an empty frame stays a frame; the file name is OpenPose's.
TEST(OpenPoseJson, WrittenFramesReadBack) {
  TempDir dir;
  People2D frame;
  frame.layout = LayoutId::coco17;
  for (int id : {-1, 4}) {
    Person2D& p = frame.people.emplace_back();
    p.id = id;
    for (int j = 0; j < 17; ++j)
      p.joints.push_back({100.25f + 10.0f * j + static_cast<float>(id), 50.5f + 3.0f * j, 0.75f});
  }
  frame.people[0].joints[3] = {std::nanf(""), std::nanf(""), 0.0f};
  frame.people[1].joints[5].confidence = 0.0f;
  const auto file = openpose_file_name(dir.path(), "cam_01", 7);
  EXPECT_EQ(file.filename().string(), "cam_01_000000000007_keypoints.json");
  write_openpose_file(file, frame);
  const People2D back = read_openpose_file(file);
  EXPECT_EQ(back.layout, LayoutId::coco17);
  ASSERT_EQ(back.people.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.people[i].id, frame.people[i].id);
    ASSERT_EQ(back.people[i].joints.size(), 17u);
    for (std::size_t j = 0; j < 17; ++j) {
      const Keypoint2D& a = frame.people[i].joints[j];
      const Keypoint2D& b = back.people[i].joints[j];
      if (a.confidence > 0.0f) {
        EXPECT_EQ(b.x, a.x);
        EXPECT_EQ(b.y, a.y);
        EXPECT_EQ(b.confidence, a.confidence);
      } else {
        EXPECT_TRUE(std::isnan(b.x)) << i << " " << j;
        EXPECT_EQ(b.confidence, 0.0f);
      }
    }
  }
  People2D nobody;
  nobody.layout = LayoutId::coco17;
  write_openpose_file(openpose_file_name(dir.path(), "cam_01", 8), nobody);
  const OpenPoseSequence folder = read_openpose_folder(dir.path());
  ASSERT_EQ(folder.frames.size(), 2u);
  EXPECT_TRUE(folder.frames[1].people.empty());
  EXPECT_TRUE(folder.problems.empty());
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".partial"));
}

TEST(OpenPoseJson, FrameNumbers) {
  EXPECT_EQ(frame_number("video_000000000123_keypoints.json"), 123);
  EXPECT_EQ(frame_number("cam01.0042.json"), 42);
  EXPECT_EQ(frame_number("Static_cam_01.00011.json"), 11);
  EXPECT_EQ(frame_number("keypoints.json"), std::nullopt);
  EXPECT_EQ(frame_number("x_1234567890123456789012.json"), std::nullopt);  // would overflow
}

TEST(OpenPoseFolder, GapsAndBadFilesAreReportedAndSkipped) {
  TempDir dir;
  const std::string one = frame_json({person_json(body25_person())});
  const std::string two =
      frame_json({person_json(body25_person()), person_json(body25_person(90))});
  write(dir.file("clip_000000000010_keypoints.json"), one);
  write(dir.file("clip_000000000011_keypoints.json"), two);
  // 12 is missing, and 20..22.
  write(dir.file("clip_000000000013_keypoints.json"), two.substr(0, two.size() / 2));  // truncated
  write(dir.file("clip_000000000014_keypoints.json"), "");                             // empty
  std::string noise(300, '\0');
  std::mt19937 rng(5);
  for (char& c : noise) c = static_cast<char>(rng());
  write(dir.file("clip_000000000015_keypoints.json"), noise);  // random bytes
  write(dir.file("clip_000000000016_keypoints.json"),
        frame_json({person_json(std::vector<float>(74, 1.0f))}));  // wrong shape
  write(dir.file("clip_000000000017_keypoints.json"),
        frame_json({person_json(std::vector<float>(54, 1.0f))}));       // COCO-18 among BODY_25
  write(dir.file("clip_000000000018_keypoints.json"), frame_json({}));  // nobody: fine
  write(dir.file("clip_000000000019_keypoints.json"), one);
  write(dir.file("other_000000000019_keypoints.json"), two);  // same number again
  write(dir.file("clip_000000000023_keypoints.json"), one);
  write(dir.file("notes.txt"), "not a frame");
  write(dir.file("summary.json"), "{}");  // no number: not a frame

  const OpenPoseSequence s = read_openpose_folder(dir.path());
  EXPECT_EQ(s.first_frame, 10);
  ASSERT_EQ(s.frames.size(), 14u);
  EXPECT_EQ(s.layout, LayoutId::body25);
  const std::vector<std::size_t> people = {1, 2, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1};
  for (std::size_t i = 0; i < people.size(); ++i) {
    EXPECT_EQ(s.frames[i].people.size(), people[i]) << "frame " << 10 + i;
    EXPECT_EQ(s.frames[i].header.frame, static_cast<std::int64_t>(10 + i));
    EXPECT_EQ(s.frames[i].header.seq, i);
    EXPECT_EQ(s.frames[i].layout, LayoutId::body25);
  }
  std::map<std::int64_t, FrameProblemKind> kinds;
  for (const auto& p : s.problems) {
    kinds[p.frame] = p.kind;
    EXPECT_FALSE(p.message.empty());
  }
  EXPECT_EQ(s.problems.size(), 8u);
  EXPECT_EQ(kinds[12], FrameProblemKind::missing);
  EXPECT_EQ(kinds[20], FrameProblemKind::missing);
  EXPECT_EQ(s.problems.back().count, 3);
  EXPECT_NE(s.problems.back().message.find("frames 20..22 have no files"), std::string::npos);
  for (int f : {13, 14, 15, 16}) EXPECT_EQ(kinds[f], FrameProblemKind::malformed) << f;
  EXPECT_EQ(kinds[17], FrameProblemKind::layout_mismatch);
  EXPECT_EQ(kinds[19], FrameProblemKind::duplicate);
  for (std::size_t i = 1; i < s.problems.size(); ++i) {
    EXPECT_LE(s.problems[i - 1].frame, s.problems[i].frame);
  }
  EXPECT_NE(s.problems[1].message.find("clip_000000000013_keypoints.json"), std::string::npos);
}

TEST(OpenPoseFolder, UnusableFoldersThrow) {
  TempDir dir;
  EXPECT_THROW(read_openpose_folder(dir.path()), InputError);  // no frame files
  EXPECT_THROW(read_openpose_folder(dir.path() / "absent"), InputError);
  write(dir.file("a_0.json"), frame_json({}));
  write(dir.file("a_99999999999.json"), frame_json({}));
  EXPECT_THROW(read_openpose_folder(dir.path()), InputError);  // absurd span of numbers
  TempDir small;
  write(small.file("b_0.json"), frame_json({}));
  write(small.file("b_5.json"), frame_json({}));
  OpenPoseOptions options;
  options.max_frames = 5;
  EXPECT_THROW(read_openpose_folder(small.path(), options), InputError);
  options.max_frames = 6;
  EXPECT_EQ(read_openpose_folder(small.path(), options).frames.size(), 6u);
}

TEST(OpenPoseFolder, OversizedFileIsAProblemNotACrash) {
  TempDir dir;
  write(dir.file("f_0.json"), frame_json({person_json(body25_person())}));
  OpenPoseOptions options;
  options.max_file_bytes = 100;
  const OpenPoseSequence s = read_openpose_folder(dir.path(), options);
  ASSERT_EQ(s.problems.size(), 1u);
  EXPECT_NE(s.problems[0].message.find("limit"), std::string::npos);
}

// ../shared/data/eval/openpose_json: the badminton video, 750 frames, BODY_25 (README).
TEST(OpenPoseShared, BadmintonFolderMatchesItsReadme) {
  MOCAP_REQUIRE_SHARED("eval/openpose_json/json/video_000000000000_keypoints.json");
  const OpenPoseSequence s =
      read_openpose_folder(test::shared_data() / "eval/openpose_json/json", {Body25Choice::detect});
  EXPECT_TRUE(s.problems.empty()) << s.problems.front().message;
  ASSERT_EQ(s.frames.size(), 750u);
  EXPECT_EQ(s.first_frame, 0);
  EXPECT_EQ(s.layout, LayoutId::body25);
  EXPECT_GT(s.votes.body25, 5000);
  EXPECT_EQ(s.votes.body25b, 0);
  std::map<std::size_t, int> frames_with;
  std::size_t slots = 0, undetected = 0;
  float min_x = 1e9f, max_x = -1e9f;
  for (const auto& f : s.frames) {
    ++frames_with[f.people.size()];
    for (const auto& p : f.people) {
      EXPECT_EQ(p.id, -1);
      for (const auto& k : p.joints) {
        ++slots;
        if (k.confidence == 0.0f) {
          ++undetected;
          continue;
        }
        min_x = std::min(min_x, k.x);
        max_x = std::max(max_x, k.x);
      }
    }
  }
  const std::map<std::size_t, int> readme = {{7, 8}, {8, 165}, {9, 565}, {10, 9}, {11, 2}, {12, 1}};
  EXPECT_EQ(frames_with, readme);
  EXPECT_EQ(slots, 164625u);
  EXPECT_EQ(undetected, 15623u);
  EXPECT_NEAR(min_x, 7.8f, 0.05f);
  EXPECT_NEAR(max_x, 1810.6f, 0.05f);
}

// ../shared/data/eval/pose2sim_demo: BODY_25B, four cameras (README).
TEST(OpenPoseShared, Pose2SimFoldersAreDetectedAsBody25b) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/S00_P00_T01_BalancingTrial/pose/cam01_json");
  const auto root = test::shared_data() / "eval/pose2sim_demo";
  const std::map<std::string, std::map<std::size_t, int>> people = {{"cam01", {{2, 99}, {3, 1}}},
                                                                    {"cam02", {{2, 100}}},
                                                                    {"cam03", {{1, 100}}},
                                                                    {"cam04", {{1, 100}}}};
  for (const auto& [cam, expected] : people) {
    const auto folder = root / "S00_P00_T01_BalancingTrial/pose" / (cam + "_json");
    const OpenPoseSequence s = read_openpose_folder(folder, {Body25Choice::detect});
    EXPECT_TRUE(s.problems.empty()) << cam;
    EXPECT_EQ(s.frames.size(), 100u) << cam;
    EXPECT_EQ(s.layout, LayoutId::body25b) << cam;
    EXPECT_EQ(s.votes.body25, 0) << cam;
    std::map<std::size_t, int> frames_with;
    for (const auto& f : s.frames) ++frames_with[f.people.size()];
    EXPECT_EQ(frames_with, expected) << cam;
    // Without detection the caller's choice stands.
    EXPECT_EQ(read_openpose_folder(folder).layout, LayoutId::body25) << cam;
  }
  for (int cam = 1; cam <= 4; ++cam) {
    const auto folder =
        root / "S00_P00_T00_StaticTrial/pose" / ("cam0" + std::to_string(cam) + "_json");
    const OpenPoseSequence s = read_openpose_folder(folder, {Body25Choice::detect});
    EXPECT_EQ(s.frames.size(), 12u);
    EXPECT_EQ(s.layout, LayoutId::body25b) << folder;
  }
}

}  // namespace
}  // namespace mocap::io
