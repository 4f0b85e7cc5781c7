// The overlay renderer draws each person in their colour where they belong (2D on the left, 3D on
// the right: placed where the fitting put them, or in a row), the 3D view frames and follows them.
// Joining its inputs by frame is the framework's (tests/graph/synchronizer_test.cpp).

#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtx/quaternion.hpp>

#include "core/scene.hpp"
#include "viz/overlay_renderer.hpp"

namespace mocap::viz {
namespace {

// A standing body, metres, camera axes (y down), root at the origin.
std::array<glm::vec3, kBodyJoints> standing_body() {
  std::array<glm::vec3, kBodyJoints> b;
  auto set = [&](Joint j, float x, float y) { b[static_cast<size_t>(index(j))] = {x, y, 0.0f}; };
  set(Joint::head, 0.0f, -0.75f);
  set(Joint::neck, 0.0f, -0.5f);
  set(Joint::right_shoulder, -0.2f, -0.5f);
  set(Joint::right_elbow, -0.25f, -0.2f);
  set(Joint::right_wrist, -0.3f, 0.05f);
  set(Joint::left_shoulder, 0.2f, -0.5f);
  set(Joint::left_elbow, 0.25f, -0.2f);
  set(Joint::left_wrist, 0.3f, 0.05f);
  set(Joint::right_hip, -0.1f, 0.0f);
  set(Joint::right_knee, -0.12f, 0.45f);
  set(Joint::right_ankle, -0.12f, 0.9f);
  set(Joint::left_hip, 0.1f, 0.0f);
  set(Joint::left_knee, 0.12f, 0.45f);
  set(Joint::left_ankle, 0.12f, 0.9f);
  set(Joint::root, 0.0f, 0.0f);
  return b;
}

// COCO-17 keypoints of the standing body drawn at `x0` pixels, 300 pixels a metre.
Person2D person2d(int id, float x0) {
  const auto b = standing_body();
  auto at = [&](Joint j) {
    const glm::vec3 p = b[static_cast<size_t>(index(j))];
    return Keypoint2D{x0 + 300.0f * p.x, 360.0f + 300.0f * p.y, 0.9f};
  };
  Person2D p;
  p.id = id;
  const Keypoint2D head = at(Joint::head);
  p.joints = {head,
              head,
              head,
              {head.x + 10, head.y, 0.9f},
              {head.x - 10, head.y, 0.9f},
              at(Joint::left_shoulder),
              at(Joint::right_shoulder),
              at(Joint::left_elbow),
              at(Joint::right_elbow),
              at(Joint::left_wrist),
              at(Joint::right_wrist),
              at(Joint::left_hip),
              at(Joint::right_hip),
              at(Joint::left_knee),
              at(Joint::right_knee),
              at(Joint::left_ankle),
              at(Joint::right_ankle)};
  p.box = {x0 - 100, 100, 200, 560};
  return p;
}

// Is there a pixel within `radius` of `at` whose colour is close to `colour`?
bool colour_near(const ImageBuffer& image, glm::vec2 at, Rgb colour, int radius = 2) {
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      const int x = static_cast<int>(std::lround(at.x)) + dx;
      const int y = static_cast<int>(std::lround(at.y)) + dy;
      if (x < 0 || y < 0 || x >= image.width() || y >= image.height()) continue;
      const auto* p = reinterpret_cast<const std::uint8_t*>(image.data()) +
                      static_cast<size_t>(y) * image.stride() + static_cast<size_t>(x) * 3;
      if (std::abs(p[0] - colour.b) + std::abs(p[1] - colour.g) + std::abs(p[2] - colour.r) < 30)
        return true;
    }
  }
  return false;
}

int pixels_of(const ImageBuffer& image, Rgb colour, int x_begin, int x_end) {
  int count = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = x_begin; x < x_end; ++x) {
      const auto* p = reinterpret_cast<const std::uint8_t*>(image.data()) +
                      static_cast<size_t>(y) * image.stride() + static_cast<size_t>(x) * 3;
      count += (p[0] == colour.b && p[1] == colour.g && p[2] == colour.r) ? 1 : 0;
    }
  }
  return count;
}

TEST(IdColour, StableDistinctAndGreyWhenUntracked) {
  EXPECT_EQ(id_colour(4), id_colour(4));
  for (int id = 0; id < 20; ++id) {
    const Rgb a = id_colour(id), b = id_colour(id + 1);
    EXPECT_GT(std::abs(a.r - b.r) + std::abs(a.g - b.g) + std::abs(a.b - b.b), 60) << id;
  }
  EXPECT_EQ(id_colour(-1), (Rgb{200, 200, 200}));
}

TEST(OverlayRenderer, TwoUnplacedPeopleDrawnInTheirColoursOnBothPanelsInARow) {
  OverlayRenderer renderer(OverlayOptions{1280, 720});
  ASSERT_EQ(renderer.height(), 480);
  ASSERT_EQ(renderer.width(), 2 * 854);  // 1280 x 720 scaled to 480 high, even width
  People2D people2d;
  people2d.layout = LayoutId::coco17;
  people2d.people = {person2d(2, 400.0f), person2d(7, 900.0f)};
  People3D people3d;
  for (int id : {7, 2}) {  // listed in the other order: the 2D boxes decide left and right
    Person3D p;
    p.id = id;
    p.positions = standing_body();
    people3d.people.push_back(p);
  }
  const ImageBuffer image = renderer.render(people2d, people3d, {}, {42, 25.0});
  ASSERT_EQ(image.width(), renderer.width());
  ASSERT_EQ(image.format(), PixelFormat::bgr8);
  const Rgb two = id_colour(2), seven = id_colour(7);
  // Left panel: each person's neck-root line midway, and the colours stay on their own side.
  for (auto [colour, x0] : {std::pair{two, 400.0f}, std::pair{seven, 900.0f}}) {
    const glm::vec2 mid = renderer.left_point({x0, 360.0f - 300.0f * 0.25f}, 1280, 720);
    EXPECT_TRUE(colour_near(image, mid, colour)) << "2D at " << x0;
    const glm::vec2 knee =
        renderer.left_point({x0 + 300.0f * 0.12f, 360.0f + 300.0f * 0.45f}, 1280, 720);
    EXPECT_TRUE(colour_near(image, knee, colour)) << "2D knee at " << x0;
  }
  const int half = renderer.panel_width();
  EXPECT_GT(pixels_of(image, two, 0, half / 2), 50);
  EXPECT_EQ(pixels_of(image, two, 2 * half / 3, half), 0);
  EXPECT_GT(pixels_of(image, seven, half / 2, half), 50);
  // Right panel: in a row in front of the camera, person 2 on the left (slot 0), 7 on the right,
  // 1.2 m apart; along the spine.
  const auto scene = scene_people(people3d, people2d, scene_floor(people3d), 1.2f);
  ASSERT_EQ(scene.size(), 2u);
  EXPECT_EQ(scene[1].id, 2);
  EXPECT_FALSE(scene[1].placed);
  const auto root = static_cast<std::size_t>(index(Joint::root));
  const auto neck = static_cast<std::size_t>(index(Joint::neck));
  EXPECT_NEAR(scene[0].joints[root].x - scene[1].joints[root].x, 1.2f, 1e-4f);
  EXPECT_NEAR(scene[0].joints[root].z, 3.0f, 1e-4f);  // display_root: 3 m ahead
  for (const ScenePerson& p : scene) {
    const glm::vec2 spine = renderer.scene_pixel((p.joints[root] + p.joints[neck]) / 2.0f);
    EXPECT_GE(spine.x, half);
    EXPECT_TRUE(colour_near(image, spine, id_colour(p.id))) << "3D person " << p.id;
  }
  EXPECT_LT(renderer.scene_pixel(scene[1].joints[root]).x,
            renderer.scene_pixel(scene[0].joints[root]).x);
  EXPECT_GT(pixels_of(image, two, half, 2 * half), 50);
  EXPECT_GT(pixels_of(image, seven, half, 2 * half), 50);
}

TEST(OverlayRenderer, VideoFrameIsTheLeftBackgroundInAnyPixelFormat) {
  OverlayOptions options;
  options.canvas_width = 640;  // ignored: the video frame's size decides
  OverlayRenderer renderer(options);
  ImageBuffer video(160, 90, PixelFormat::rgb8);
  auto pixels = video.pixels_for_writing();
  for (std::size_t i = 0; i < pixels.size(); i += 3) pixels[i + 1] = std::byte{180};  // green
  const ImageBuffer image = renderer.render({}, {}, video, {0, 0.0});
  // The panel keeps the canvas's shape (426 x 480, the output size is fixed for a run): the 16:9
  // video fills its width, centred, with bands above and below.
  const float right_edge = float(renderer.panel_width()) - 3.0f;
  EXPECT_TRUE(colour_near(image, {right_edge, 240.0f}, {0, 180, 0}, 0));
  EXPECT_TRUE(colour_near(image, renderer.left_point({150, 80}, 160, 90), {0, 180, 0}, 0));
  EXPECT_FALSE(colour_near(image, {right_edge, 470.0f}, {0, 180, 0}, 0));
  // The right panel is not the video.
  EXPECT_FALSE(colour_near(image, {right_edge + 8.0f, 240.0f}, {0, 180, 0}, 0));
}

TEST(OverlayRenderer, MissingJointsAndEmptyFramesDraw) {
  OverlayRenderer renderer(OverlayOptions{});
  People2D people2d;
  people2d.layout = LayoutId::body25;
  Person2D p = person2d(3, 600.0f);
  p.joints.resize(25);  // a BODY_25 person with everything but a few points missing
  for (std::size_t k = 8; k < 25; ++k) p.joints[k] = {NAN, NAN, 0.0f};
  people2d.people.push_back(p);
  People3D people3d;
  Person3D q;
  q.id = 3;
  q.positions = standing_body();
  q.positions[index(Joint::left_wrist)] = glm::vec3(NAN);
  people3d.people.push_back(q);
  EXPECT_NO_THROW(renderer.render(people2d, people3d, {}, {1, 0.0}));
  EXPECT_NO_THROW(renderer.render({}, {}, {}, {2, 0.0}));
  EXPECT_THROW(OverlayRenderer(OverlayOptions{8, 720, 480}), std::invalid_argument);
}

// A camera looking down 52 degrees sees a standing person tilted; upright_positions stands them
// up again (head straight above the root, feet straight below), keeping left and right.
TEST(UprightPositions, RemovesTheTiltOfACameraLookingDown) {
  const auto standing = standing_body();  // image axes, y down, facing the camera
  // Body frame (y up, facing +Z) to a level camera on +Z: x stays, y and z flip; then the
  // camera pitches down about its x axis.
  const glm::quat level_camera = glm::angleAxis(glm::pi<float>(), glm::vec3(1, 0, 0));
  for (float pitch_deg : {0.0f, 21.4f, 52.0f, -10.0f}) {
    const glm::quat to_camera =
        glm::angleAxis(glm::radians(pitch_deg), glm::vec3(1, 0, 0)) * level_camera;
    Person3D person;
    person.root.rotation = to_camera;
    for (int j = 0; j < kBodyJoints; ++j) {
      const glm::vec3 body = glm::inverse(level_camera) * standing[static_cast<size_t>(j)];
      person.positions[static_cast<size_t>(j)] = to_camera * body;
    }
    const auto upright = upright_positions(person);
    for (int j = 0; j < kBodyJoints; ++j) {
      EXPECT_LT(glm::distance(upright[static_cast<size_t>(j)], standing[static_cast<size_t>(j)]),
                1e-5f)
          << "pitch " << pitch_deg << " joint " << j;
    }
  }
  Person3D unset;  // identity rotation: left as it is
  unset.positions = standing;
  EXPECT_EQ(upright_positions(unset), standing);
}

// --- the 3D panel: people placed by the fitting

// A camera 3 m above a level floor looking down by `pitch_deg`, and a person standing on that
// floor `x` metres to the right of it and `ahead` metres in front (along the floor), placed as
// the fitting places people: root-relative positions turned into the camera frame, root
// translation, the floor in the camera frame.
struct TiltedCamera {
  float pitch_deg = 30.0f;
  float height = 3.0f;
  glm::vec3 up() const {
    const float a = glm::radians(pitch_deg);
    return {0.0f, -std::cos(a), -std::sin(a)};
  }
  glm::vec3 ahead() const {
    const float a = glm::radians(pitch_deg);
    return {0.0f, -std::sin(a), std::cos(a)};
  }
  GroundPlane ground() const { return {up(), height}; }
  Person3D person(int id, float x, float ahead_m) const {
    const glm::quat level_camera = glm::angleAxis(glm::pi<float>(), glm::vec3(1, 0, 0));
    const glm::quat tilt = glm::rotation(glm::vec3(0, -1, 0), up());
    Person3D p;
    p.id = id;
    p.placed = true;
    p.root.rotation = tilt * level_camera;
    const auto body = standing_body();  // ankles 0.9 m below the root
    for (int j = 0; j < kBodyJoints; ++j)
      p.positions[static_cast<size_t>(j)] = tilt * body[static_cast<size_t>(j)];
    p.root.translation = x * glm::vec3(1, 0, 0) + (0.9f - height) * up() + ahead_m * this->ahead();
    return p;
  }
};

glm::vec3 joint(const ScenePerson& p, Joint j) { return p.joints[static_cast<size_t>(index(j))]; }

bool in_right_panel(const OverlayRenderer& r, glm::vec2 p) {
  return p.x >= float(r.panel_width()) && p.x < float(r.width()) && p.y >= 0.0f &&
         p.y < float(r.height());
}

int pixels_near(const ImageBuffer& image, Rgb colour, int x_begin, int x_end) {
  int count = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = x_begin; x < x_end; ++x) {
      const auto* p = reinterpret_cast<const std::uint8_t*>(image.data()) +
                      static_cast<size_t>(y) * image.stride() + static_cast<size_t>(x) * 3;
      count +=
          std::abs(p[0] - colour.b) + std::abs(p[1] - colour.g) + std::abs(p[2] - colour.r) < 20;
    }
  }
  return count;
}

TEST(ScenePanel, PlacedPeopleStandWhereTheFitPutThemUprightOnTheFloorGrid) {
  const TiltedCamera camera;
  People3D people3d;
  people3d.has_ground = true;
  people3d.ground = camera.ground();
  people3d.people = {camera.person(3, -1.0f, 4.0f), camera.person(5, 2.0f, 8.0f)};
  OverlayRenderer renderer(OverlayOptions{768, 576});
  const ImageBuffer image = renderer.render({}, people3d, {}, {0, 0.0});
  const auto scene = scene_people(people3d, {}, scene_floor(people3d), 1.2f);
  ASSERT_EQ(scene.size(), 2u);
  std::array<glm::vec2, 2> roots;
  for (std::size_t i = 0; i < 2; ++i) {
    const ScenePerson& p = scene[i];
    EXPECT_TRUE(p.placed);
    EXPECT_EQ(joint(p, Joint::root), people3d.people[i].root.translation);
    // Feet on the floor (ankles 0.9 m below the hips, the hips 0.9 m above the floor).
    EXPECT_NEAR(renderer.scene_camera().floor_coordinates(joint(p, Joint::left_ankle)).y, 0.0f,
                1e-4f);
    for (const glm::vec3& q : p.joints)
      EXPECT_TRUE(in_right_panel(renderer, renderer.scene_pixel(q))) << "person " << p.id;
    const glm::vec2 spine =
        renderer.scene_pixel((joint(p, Joint::root) + joint(p, Joint::neck)) / 2.0f);
    EXPECT_TRUE(colour_near(image, spine, id_colour(p.id))) << "person " << p.id;
    // Upright in the panel although the camera looks down 30 degrees: the head straight above
    // the root.
    const glm::vec2 head = renderer.scene_pixel(joint(p, Joint::head));
    roots[i] = renderer.scene_pixel(joint(p, Joint::root));
    EXPECT_NEAR(head.x, roots[i].x, 1.0f) << "person " << p.id;
    EXPECT_LT(head.y, roots[i].y - 10.0f) << "person " << p.id;
  }
  // Person 5 stands farther and more to the right: higher up and to the right in the view.
  EXPECT_LT(roots[1].y, roots[0].y);
  EXPECT_GT(roots[1].x, roots[0].x);
  // Both were placed: nobody stands in a row, and the floor grid is drawn.
  EXPECT_GT(pixels_near(image, {56, 56, 56}, renderer.panel_width(), renderer.width()), 300);
}

TEST(ScenePanel, UnplacedPeopleStandInARowOnTheFloorBesidePlacedOnes) {
  const TiltedCamera camera;
  People3D people3d;
  people3d.has_ground = true;
  people3d.ground = camera.ground();
  Person3D unplaced = camera.person(9, 0.0f, 0.0f);
  unplaced.placed = false;
  unplaced.root.translation = glm::vec3(0.0f);
  people3d.people = {camera.person(3, 0.0f, 6.0f), unplaced};
  OverlayRenderer renderer(OverlayOptions{768, 576});
  const ImageBuffer image = renderer.render({}, people3d, {}, {0, 0.0});
  const auto scene = scene_people(people3d, {}, people3d.ground, 1.2f);
  ASSERT_EQ(scene.size(), 2u);
  EXPECT_FALSE(scene[1].placed);
  const glm::vec3 root = renderer.scene_camera().floor_coordinates(joint(scene[1], Joint::root));
  EXPECT_NEAR(root.y, 0.95f, 1e-3f);  // core/scene.hpp display_root: hips 0.95 m above the floor
  EXPECT_NEAR(renderer.scene_camera().floor_coordinates(joint(scene[1], Joint::head)).x, root.x,
              1e-3f);  // stood upright on the floor
  const glm::vec2 spine =
      renderer.scene_pixel((joint(scene[1], Joint::root) + joint(scene[1], Joint::neck)) / 2.0f);
  EXPECT_TRUE(colour_near(image, spine, id_colour(9)));
}

TEST(ScenePanel, FloorIsTheKnownOneElseUnderThePlacedFeetElseAssumed) {
  const TiltedCamera camera;
  People3D people3d;
  people3d.people = {camera.person(1, 0.0f, 5.0f)};
  const GroundPlane under_feet = scene_floor(people3d);  // level in the image, through the ankles
  EXPECT_EQ(under_feet.normal, glm::dvec3(0, -1, 0));
  const glm::vec3 ankle =
      people3d.people[0].root.translation + people3d.people[0].positions[index(Joint::left_ankle)];
  EXPECT_NEAR(under_feet.offset, ankle.y, 1e-5f);
  people3d.has_ground = true;
  people3d.ground = camera.ground();
  EXPECT_EQ(scene_floor(people3d).normal, glm::dvec3(camera.up()));
  people3d = {};
  EXPECT_EQ(scene_floor(people3d).offset, assumed_ground().offset);
}

// The view takes in someone far away in the very frame they appear, and comes back slowly when
// they are gone.
TEST(ScenePanel, ViewGrowsAtOnceAndShrinksSlowly) {
  const TiltedCamera camera;
  People3D near_only;
  near_only.has_ground = true;
  near_only.ground = camera.ground();
  near_only.people = {camera.person(1, 0.0f, 4.0f)};
  People3D with_far = near_only;
  with_far.people.push_back(camera.person(2, 6.0f, 25.0f));
  OverlayRenderer renderer(OverlayOptions{768, 576});
  renderer.render({}, near_only, {}, {0, 0.0});
  const float close_up = renderer.scene_camera().pixels_per_metre();
  renderer.render({}, with_far, {}, {1, 0.0});
  const float wide = renderer.scene_camera().pixels_per_metre();
  EXPECT_LT(wide, close_up / 2.0f);
  for (const ScenePerson& p : scene_people(with_far, {}, with_far.ground, 1.2f))
    for (const glm::vec3& q : p.joints)
      EXPECT_TRUE(in_right_panel(renderer, renderer.scene_pixel(q))) << "person " << p.id;
  renderer.render({}, near_only, {}, {2, 0.0});
  EXPECT_LT(renderer.scene_camera().pixels_per_metre(), 1.2f * wide);  // no jump back
  for (int f = 3; f < 100; ++f) renderer.render({}, near_only, {}, {f, 0.0});
  EXPECT_NEAR(renderer.scene_camera().pixels_per_metre(), close_up, 0.02f * close_up);
}

}  // namespace
}  // namespace mocap::viz
