// The viewer's frame JSON and the poses.jsonl playback: placed and unplaced people, the floor,
// the camera, garbage recordings, the player's clock and controls.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "support/files.hpp"
#include "support/walking_people.hpp"
#include "web/frame_json.hpp"
#include "web/recording.hpp"

namespace mocap::web {
namespace {

using Json = nlohmann::json;
using test::TempDir;

glm::vec3 joint_mm(const Json& person, Joint j) {
  const auto& a = person["joints"];
  const auto i = 3 * index(j);
  return {a[i].get<float>(), a[i + 1].get<float>(), a[i + 2].get<float>()};
}

TEST(FrameJson, PlacedPeopleKeepTheirPositionUnplacedStandOnTheFloorInARow) {
  People3D frame = test::walking_people(3, 7);
  frame.people[0].placed = true;
  frame.people[0].root.translation = {0.5f, 0.2f, 4.0f};
  const Json json = Json::parse(frame_json(frame, std::nullopt));
  ASSERT_EQ(json["type"], "frame");
  EXPECT_EQ(json["frame"], 7);
  ASSERT_EQ(json["people"].size(), 3u);
  const Json& placed = json["people"][0];
  EXPECT_TRUE(placed["placed"].get<bool>());
  EXPECT_EQ(placed["joints"].size(), 3u * kBodyJoints);
  const glm::vec3 head =
      frame.people[0].positions[index(Joint::head)] + glm::vec3(0.5f, 0.2f, 4.0f);
  EXPECT_NEAR(joint_mm(placed, Joint::head).x, 1000 * head.x, 1.0);
  EXPECT_NEAR(joint_mm(placed, Joint::head).y, 1000 * head.y, 1.0);
  EXPECT_NEAR(joint_mm(placed, Joint::head).z, 1000 * head.z, 1.0);
  // The two unplaced people: roots 0.8 m apart, 3 m ahead, hips 0.95 m over the assumed floor
  // (1.5 m below the camera), so their roots are 0.55 m below the camera.
  const glm::vec3 a = joint_mm(json["people"][1], Joint::root);
  const glm::vec3 b = joint_mm(json["people"][2], Joint::root);
  EXPECT_NEAR(b.x - a.x, 800, 1);
  EXPECT_NEAR(a.x + b.x, 0, 1);
  EXPECT_NEAR(a.y, 550, 1);
  EXPECT_NEAR(a.z, 3000, 1);
  EXPECT_FALSE(json["ground"]["known"].get<bool>());
  EXPECT_FALSE(json["camera"]["known"].get<bool>());
  EXPECT_FALSE(json.contains("playback"));
  // Keypoints: 15 x (x, y, confidence).
  EXPECT_EQ(json["people"][1]["keypoints"].size(), 3u * kBodyJoints);
  EXPECT_NEAR(json["people"][1]["keypoints"][2].get<double>(), 0.9, 1e-9);
}

TEST(FrameJson, UnplacedPeopleStandOnAKnownTiltedFloor) {
  People3D frame = test::walking_people(1, 0);
  frame.has_ground = true;
  frame.ground.normal = glm::normalize(glm::dvec3(0.0, -0.9, 0.3));
  frame.ground.offset = 2.0;
  const Json json = Json::parse(frame_json(frame, std::nullopt));
  const glm::vec3 root = joint_mm(json["people"][0], Joint::root) / 1000.0f;
  EXPECT_NEAR(frame.ground.height_of(glm::dvec3(root)), 0.95, 0.003);
  EXPECT_TRUE(json["ground"]["known"].get<bool>());
  EXPECT_NEAR(json["ground"]["offset"].get<double>(), 2.0, 1e-6);
}

TEST(FrameJson, MissingValuesAreNullOrZeroTheCameraAndPlaybackAreSent) {
  People3D frame = test::walking_people(1, 0);
  frame.people[0].positions[index(Joint::left_wrist)].x = std::numeric_limits<float>::quiet_NaN();
  frame.people[0].keypoints[index(Joint::head)] = {std::nanf(""), 3.0f, 0.8f};
  frame.people[0].keypoints[index(Joint::neck)].confidence = 0.0f;
  camera::Camera lens;
  lens.name = "cam_01";
  lens.width = 640;
  lens.height = 480;
  lens.fx = 500.0;
  lens.fy = 510.0;
  lens.cx = 320.5;
  lens.cy = 240.25;
  const ShownCamera camera{lens, false};
  const Json json = Json::parse(frame_json(frame, camera, Playback{3, 10, false, 2.0, 1.5}, 0.25));
  const Json& person = json["people"][0];
  EXPECT_TRUE(person["joints"][3 * index(Joint::left_wrist)].is_null());
  for (const Joint j : {Joint::head, Joint::neck}) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(person["keypoints"][3 * index(j) + c], 0);
  }
  EXPECT_EQ(json["camera"]["width"], 640);
  EXPECT_NEAR(json["camera"]["fy"].get<double>(), 510.0, 1e-6);
  EXPECT_NEAR(json["camera"]["cy"].get<double>(), 240.3, 1e-6);  // 0.1 pixel
  EXPECT_EQ(json["playback"]["index"], 3);
  EXPECT_EQ(json["playback"]["count"], 10);
  EXPECT_FALSE(json["playback"]["playing"].get<bool>());
  EXPECT_NEAR(json["time"].get<double>(), 0.25, 1e-9);
}

// A z-up world (Pose2Sim's convention) with two level cameras on a ring facing the centre: up comes
// from the cameras, the floor (not in the rig) is level with the lowest ankle, every camera is
// sent with its pose (camera -> world rotation, centre) and the people stand where they are.
TEST(FrameJson, AWorldFrameMessageIsDrawnWithEveryCameraOfItsRig) {
  camera::Rig rig;
  for (const double angle : {0.0, 2.0}) {
    camera::Camera c =
        camera::Camera::from_fov(1920, 1080, 60.0, "cam_" + std::to_string(int(angle)));
    const glm::dvec3 centre(4.0 * std::cos(angle), 4.0 * std::sin(angle), 1.6);
    const glm::dvec3 forward = glm::normalize(glm::dvec3(0.0, 0.0, 1.6) - centre);  // level
    const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0.0, 0.0, 1.0)));
    const glm::dvec3 down = glm::cross(forward, right);
    c.set_pose_from_centre(glm::dmat3(right, down, forward), centre);
    rig.cameras.push_back(c);
  }
  People3D frame;
  frame.frame = CoordinateFrame::world();
  Person3D person = test::walking_person(2, 0.3f);
  for (glm::vec3& p : person.positions) p = {p.x, p.z, -p.y};  // y down -> z up
  person.placed = true;
  person.root.translation = {0.5f, -0.2f, 0.95f};
  frame.people.push_back(person);
  const Json json = Json::parse(frame_json(frame, rig));
  EXPECT_TRUE(json["world"].get<bool>());
  EXPECT_NEAR(json["up"][2].get<double>(), 1.0, 1e-3);
  ASSERT_EQ(json["cameras"].size(), 2u);
  const Json& second = json["cameras"][1];
  EXPECT_EQ(second["name"], "cam_2");
  EXPECT_NEAR(second["position"][0].get<double>(), 4.0 * std::cos(2.0), 1e-3);
  EXPECT_NEAR(second["position"][2].get<double>(), 1.6, 1e-3);
  // The rotation's third column is the camera's optical axis in the world.
  const glm::dvec3 axis = rig.cameras[1].optical_axis();
  for (int row = 0; row < 3; ++row)
    EXPECT_NEAR(second["rotation"][3 * row + 2].get<double>(), axis[row], 1e-5);
  EXPECT_EQ(json["camera"]["width"], 1920);
  const glm::vec3 head = joint_mm(json["people"][0], Joint::head) / 1000.0f;
  EXPECT_NEAR(head.z, 0.95f + 0.72f, 0.002);
  EXPECT_FALSE(json["ground"]["known"].get<bool>());
  const float ankle = std::min(person.positions[index(Joint::left_ankle)].z,
                               person.positions[index(Joint::right_ankle)].z) +
                      0.95f;
  EXPECT_NEAR(json["ground"]["offset"].get<double>(), -ankle, 0.002);
  // A rig with a floor: that floor, known.
  rig.floor = GroundPlane{{0.0, 0.0, 1.0}, 0.0};
  const Json with_floor = Json::parse(frame_json(frame, rig));
  EXPECT_TRUE(with_floor["ground"]["known"].get<bool>());
  EXPECT_NEAR(with_floor["ground"]["offset"].get<double>(), 0.0, 1e-9);
  // No rig: up from the people.
  const Json alone = Json::parse(frame_json(frame, camera::Rig{}));
  EXPECT_NEAR(alone["up"][2].get<double>(), 1.0, 1e-3);
  EXPECT_TRUE(alone["cameras"].empty());
  EXPECT_FALSE(alone["camera"]["known"].get<bool>());
}

TEST(FrameJson, HelloNamesTheJointsAndTheFourteenBones) {
  const Json json = Json::parse(hello_json("title"));
  EXPECT_EQ(json["type"], "hello");
  EXPECT_EQ(json["joints"].size(), 15u);
  EXPECT_EQ(json["joints"][0], "head");
  ASSERT_EQ(json["bones"].size(), 14u);
  for (const Json& bone : json["bones"]) {
    const int parent = bone[0], child = bone[1];
    EXPECT_EQ(kJointParent[static_cast<std::size_t>(child)], parent);
  }
}

TEST(Recording, ReadsJointsPlacementFloorAndTimes) {
  TempDir dir;
  const std::string path = dir.file("poses.jsonl");
  std::string text;
  for (int f = 0; f < 3; ++f) {
    Json joints = Json::object(), absolute = Json::object();
    for (int j = 0; j < kBodyJoints; ++j) {
      const float y = j == index(Joint::root) ? 0.0f : -0.1f * static_cast<float>(j);
      joints[std::string(kJointNames[static_cast<std::size_t>(j)])] = {0.0, y, 0.0};
      absolute[std::string(kJointNames[static_cast<std::size_t>(j)])] = {1.0, y + 0.5, 4.0};
    }
    Json line = {{"frame", 10 + f}, {"time", 2.0 + 0.04 * f}};
    line["people"] = Json::array({{{"id", 4}, {"joints", joints}}});
    if (f == 2) {
      line["people"][0]["joints_abs"] = absolute;
      Json keypoints = Json::array();
      for (int j = 0; j < kBodyJoints; ++j)
        keypoints.insert(keypoints.end(), {100.5 + j, 200.0, j == 3 ? 0.0 : 0.9});
      line["people"][0]["keypoints"] = keypoints;
      line["ground"] = {{"normal", {0.0, -1.0, 0.0}}, {"offset", 1.2}};
    }
    text += line.dump() + "\n\n";
  }
  test::write_file(path, text);
  const Recording r = read_poses_jsonl(path);
  ASSERT_EQ(r.frames.size(), 3u);
  EXPECT_EQ(r.frames[1].header.frame, 11);
  EXPECT_NEAR(r.times[2], 0.08, 1e-9);
  EXPECT_FALSE(r.frames[0].people[0].placed);
  EXPECT_FALSE(r.frames[0].has_ground);
  const Person3D& p = r.frames[2].people[0];
  EXPECT_EQ(p.id, 4);
  EXPECT_TRUE(p.placed);
  EXPECT_NEAR(p.root.translation.x, 1.0f, 1e-6);
  EXPECT_NEAR(p.root.translation.y, 0.5f, 1e-6);
  EXPECT_NEAR(p.positions[index(Joint::head)].y, 0.0f, 1e-6);
  EXPECT_NEAR(p.positions[index(Joint::neck)].y, -0.1f, 1e-6);
  EXPECT_TRUE(r.frames[2].has_ground);
  EXPECT_NEAR(r.frames[2].ground.offset, 1.2f, 1e-6);
  // The 2D input written by sink.jsonl comes back for the viewer's 2D panel; 0 confidence =
  // missing.
  EXPECT_EQ(r.frames[0].people[0].keypoints[0].confidence, 0.0f);
  EXPECT_NEAR(p.keypoints[2].x, 102.5f, 1e-4);
  EXPECT_NEAR(p.keypoints[2].y, 200.0f, 1e-4);
  EXPECT_NEAR(p.keypoints[2].confidence, 0.9f, 1e-6);
  EXPECT_EQ(p.keypoints[3].confidence, 0.0f);
  EXPECT_EQ(p.keypoints[3].x, 0.0f);
}

// poses.jsonl of a multi-view reconstruction: joints_world makes every frame world-frame (empty
// ones too); one file cannot mix it with joints_abs.
TEST(Recording, JointsWorldMakeAWorldRecordingAndDoNotMixWithJointsAbs) {
  TempDir dir;
  const std::string path = dir.file("world.jsonl");
  Json joints = Json::object(), world = Json::object();
  for (int j = 0; j < kBodyJoints; ++j) {
    joints[std::string(kJointNames[static_cast<std::size_t>(j)])] = {0.0, 0.0, 0.1 * j};
    world[std::string(kJointNames[static_cast<std::size_t>(j)])] = {2.0, 1.0, 0.9 + 0.1 * j};
  }
  const Json empty = {{"frame", 0}, {"people", Json::array()}};
  Json placed = {{"frame", 1}, {"people", Json::array({{{"id", 7}, {"joints", joints}}})}};
  placed["people"][0]["joints_world"] = world;
  test::write_file(path, empty.dump() + "\n" + placed.dump() + "\n");
  const Recording r = read_poses_jsonl(path);
  EXPECT_TRUE(r.world);
  EXPECT_TRUE(r.frames[0].frame.is_world());
  ASSERT_EQ(r.frames[1].people.size(), 1u);
  EXPECT_TRUE(r.frames[1].people[0].placed);
  EXPECT_NEAR(r.frames[1].people[0].root.translation.z, 0.9f, 1e-6);
  Json abs = placed;
  abs["people"][0].erase("joints_world");
  abs["people"][0]["joints_abs"] = world;
  test::write_file(path, placed.dump() + "\n" + abs.dump() + "\n");
  try {
    read_poses_jsonl(path);
    ADD_FAILURE() << "a file mixing joints_world and joints_abs was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":2:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 1 has joints_world"), std::string::npos) << e.what();
  }
}

TEST(Recording, WithoutTimesFramesAreSpacedByTheFrameRate) {
  TempDir dir;
  const std::string path = dir.file("poses.jsonl");
  test::write_file(path, "{\"people\": []}\n{\"people\": []}\n{\"people\": []}\n");
  const Recording r = read_poses_jsonl(path, 25.0);
  ASSERT_EQ(r.times.size(), 3u);
  EXPECT_NEAR(r.times[2], 0.08, 1e-9);
}

// A writer killed in the middle of a line leaves it without its newline: skipped, said.
TEST(Recording, ALastLineCutByAKillIsSkipped) {
  TempDir dir;
  const std::string path = dir.file("cut.jsonl");
  test::write_file(
      path,
      "{\"time\": 0, \"people\": []}\n{\"time\": 0.1, \"people\": []}\n{\"time\": 0.2, \"peo");
  const Recording r = read_poses_jsonl(path);
  EXPECT_EQ(r.frames.size(), 2u);
  EXPECT_TRUE(r.cut_last_line);
  test::write_file(path, "{\"time\": 0, \"people\": []}\n");
  EXPECT_FALSE(read_poses_jsonl(path).cut_last_line);
  // A cut line alone is not a recording.
  test::write_file(path, "{\"time\": 0, \"peo");
  EXPECT_THROW(read_poses_jsonl(path), InputError);
}

TEST(Recording, GarbageIsAnErrorNamingTheFileAndLine) {
  TempDir dir;
  const std::string path = dir.file("bad.jsonl");
  const auto message = [&](const std::string& text) -> std::string {
    test::write_file(path, text);
    try {
      read_poses_jsonl(path);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(message("").find("bad.jsonl: no frames"), std::string::npos);
  EXPECT_NE(message("{\"people\": []}\n{\"people\": [{\"id\": 1, \"joi\n").find("bad.jsonl:2:"),
            std::string::npos);
  EXPECT_NE(message("{\"people\": []}\n{\"people\": [{\"id\": 1, \"joi\n{\"people\": []}\n")
                .find("bad.jsonl:2:"),
            std::string::npos);
  EXPECT_NE(message("{\"people\": [{\"id\": 1, \"joints\": {\"head\": [0, 0, 0]}}]}\n")
                .find("has no joint 'neck'"),
            std::string::npos);
  EXPECT_NE(message("{\"people\": 5}").find("bad.jsonl:1:"), std::string::npos);
  std::string joints;
  for (int j = 0; j < kBodyJoints; ++j)
    joints += std::string(j ? ", " : "") + "\"" + std::string(kJointNames[j]) + "\": [0, 0, 0]";
  const std::string person = "{\"people\": [{\"id\": 1, \"joints\": {" + joints + "}, ";
  EXPECT_NE(message(person + "\"keypoints\": [1, 2, 3]}]}").find("not 15 x [x, y, confidence]"),
            std::string::npos);
  EXPECT_NE(
      message(person + "\"keypoints\": " + Json(std::vector<std::string>(45, "a")).dump() + "}]}")
          .find("something not a number"),
      std::string::npos);
  EXPECT_NE(message("[1, 2]").find("bad.jsonl:1:"), std::string::npos);
  EXPECT_NE(message("{\"people\": [], \"ground\": {\"normal\": [0, 0, 0], \"offset\": 1}}")
                .find("bad.jsonl:1:"),
            std::string::npos);
  EXPECT_NE(message("no file").find("bad.jsonl"), std::string::npos);
  EXPECT_THROW(read_poses_jsonl(dir.file("absent.jsonl")), InputError);
  std::mt19937 random(7);
  for (int round = 0; round < 50; ++round) {
    std::string bytes(1 + random() % 300, '\0');
    for (char& c : bytes) c = static_cast<char>(random() & 0xff);
    EXPECT_NE(message(bytes).find("bad.jsonl"), std::string::npos) << "round " << round;
  }
}

TEST(Player, PlaysLoopsPausesSeeksAndChangesSpeed) {
  Player player({0.0, 0.1, 0.2, 0.3});  // period 0.4 s: the last frame shows for 0.1 s
  EXPECT_EQ(player.advance(0.05), 0u);
  EXPECT_EQ(player.advance(0.1), 1u);
  EXPECT_EQ(player.advance(0.2), 3u);  // clock 0.35
  EXPECT_EQ(player.advance(0.1), 0u);  // 0.45 -> loops to 0.05
  EXPECT_TRUE(player.apply(R"({"cmd": "pause"})"));
  EXPECT_FALSE(player.playing());
  EXPECT_EQ(player.advance(5.0), 0u);
  EXPECT_TRUE(player.apply(R"({"cmd": "seek", "index": 2})"));
  EXPECT_EQ(player.index(), 2u);
  EXPECT_TRUE(player.apply(R"({"cmd": "seek", "index": 99})"));
  EXPECT_EQ(player.index(), 3u);
  EXPECT_TRUE(player.apply(R"({"cmd": "seek", "index": 1})"));
  EXPECT_TRUE(player.apply(R"({"cmd": "speed", "value": 2})"));
  EXPECT_TRUE(player.apply(R"({"cmd": "play"})"));
  EXPECT_EQ(player.advance(0.05), 2u);  // 0.1 + 2 x 0.05
  EXPECT_DOUBLE_EQ(player.speed(), 2.0);
  for (const char* bad : {"", "{", "[]", "{\"cmd\": 3}", "{\"cmd\": \"seek\"}",
                          "{\"cmd\": \"speed\", \"value\": \"x\"}", "{\"cmd\": \"jump\"}"}) {
    EXPECT_FALSE(player.apply(bad)) << bad;
  }
  Player one({0.0});
  EXPECT_EQ(one.advance(1.0), 0u);
}

}  // namespace
}  // namespace mocap::web
