// sink.trc in the test harness: one TRC per person id that io::read_trc reads back, the world's
// Z up turned to OpenSim's Y up as Pose2Sim turns it, frames a person is missing in as empty rows
// (so Frame# stays the input frame + 1), and errors naming the path or the camera.

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "graph/harness.hpp"
#include "io/trc.hpp"
#include "support/files.hpp"

namespace mocap::nodes {
namespace {

// Person `id` at frame `frame`: every joint at a distinct place, root translation (1, 2, 3) + id.
Person3D person(int id, int frame) {
  Person3D p;
  p.id = id;
  p.placed = true;
  p.root.translation = glm::vec3(1.0f + static_cast<float>(id), 2.0f, 3.0f);
  for (int j = 0; j < kBodyJoints; ++j)
    p.positions[static_cast<std::size_t>(j)] =
        glm::vec3(0.01f * static_cast<float>(j), 0.1f * static_cast<float>(frame), -0.02f * j);
  p.positions[static_cast<std::size_t>(Joint::root)] = glm::vec3(0.0f);
  return p;
}

People3D world(std::int64_t frame, std::vector<Person3D> people) {
  People3D m;
  m.header.frame = frame;
  m.frame = CoordinateFrame::world();
  m.people = std::move(people);
  return m;
}

TEST(TrcSink, OneFilePerPersonInOpenSimAxesWithGapsAsEmptyRows) {
  test::TempDir dir;
  const std::string pattern = dir.file("out/person_{id}.trc");
  graph::Harness sink("sink.trc", {{"path", pattern}, {"fps", "50"}});
  sink.push("in", world(0, {person(1, 0)}));
  sink.push("in", world(1, {person(1, 1), person(2, 1)}));
  sink.push("in", world(2, {person(2, 2)}));
  sink.push("in", world(3, {person(1, 3)}));
  sink.finish();

  const io::TrcFile one = io::read_trc(dir.file("out/person_1.trc"));
  EXPECT_EQ(one.rate, 50.0);
  ASSERT_EQ(one.markers.size(), 15u);
  EXPECT_EQ(one.markers[0], "Head");
  EXPECT_EQ(one.markers[14], "Hip");
  ASSERT_EQ(one.frames.size(), 4u);  // frames 0..3, frame 2 empty
  EXPECT_TRUE(std::isnan(one.frames[2][0].x));
  // World (x, y, z), Z up, is (y, z, x) in the TRC: the root (2, 2, 3) at (2, 3, 2).
  EXPECT_NEAR(one.frames[0][14].x, 2.0f, 1e-6f);
  EXPECT_NEAR(one.frames[0][14].y, 3.0f, 1e-6f);
  EXPECT_NEAR(one.frames[0][14].z, 2.0f, 1e-6f);
  // Joint 3 at frame 3: world (2 + 0.03, 2 + 0.3, 3 - 0.06).
  EXPECT_NEAR(one.frames[3][3].x, 2.3f, 1e-5f);
  EXPECT_NEAR(one.frames[3][3].y, 2.94f, 1e-5f);
  EXPECT_NEAR(one.frames[3][3].z, 2.03f, 1e-5f);

  const io::TrcFile two = io::read_trc(dir.file("out/person_2.trc"));
  ASSERT_EQ(two.frames.size(), 2u);  // from its first appearance (frame 1) to its last
  EXPECT_NEAR(two.frames[0][14].z, 3.0f, 1e-6f);
}

TEST(TrcSink, YUpWorldIsWrittenAsItIs) {
  test::TempDir dir;
  graph::Harness sink("sink.trc", {{"path", dir.file("p{id}.trc")}, {"world_up", "y"}});
  sink.push("in", world(7, {person(4, 7)}));
  sink.finish();
  const io::TrcFile f = io::read_trc(dir.file("p4.trc"));
  ASSERT_EQ(f.frames.size(), 1u);
  EXPECT_NEAR(f.frames[0][14].x, 5.0f, 1e-6f);
  EXPECT_NEAR(f.frames[0][14].y, 2.0f, 1e-6f);
}

TEST(TrcSink, ErrorsNameThePathOrTheCamera) {
  test::TempDir dir;
  try {
    graph::Harness sink("sink.trc", {{"path", dir.file("no_id.trc")}});
    sink.open();
    FAIL() << "a path without {id} was taken";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("{id}"), std::string::npos) << e.what();
  }
  graph::Harness sink("sink.trc", {{"path", dir.file("p{id}.trc")}});
  People3D camera_frame = world(0, {person(1, 0)});
  camera_frame.frame = CoordinateFrame::of_camera("cam_left");
  try {
    sink.push("in", camera_frame);
    sink.finish();
    FAIL() << "camera-frame people were written";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("cam_left"), std::string::npos) << e.what();
  }
  EXPECT_THROW(graph::Harness("sink.trc", {{"path", "x{id}"}, {"world_up", "x"}}), InputError);
}

}  // namespace
}  // namespace mocap::nodes
