// unit.people_script: a test source of matched people, as the temporal selector would send them,
// from a small script over a pose database:
//   script: frames separated by ';', people by ',', each person "id:clip:offset:view"
//           (clip = index into the database's clips, offset = frame within the clip)
// Outputs per script frame: People3D (positions = the database body turned by the view, camera
// axes), People2D (the same body drawn orthographically, BODY_25 layout, boxes side by side) and a
// VideoFrame (a flat colour). With `depth_m` > 0 every person stands that far in front of a
// 640x480 pinhole camera (fx = fy = 600, principal point at the centre), person k at x = 1.2 k m,
// and their People3D carry the exact projection of their joints as keypoints. `skip_2d` lists
// frames whose People2D is not sent; `repeat` plays the script again and again until the graph is
// stopped (for kill tests).

#include <sstream>

#include "graph/registry.hpp"
#include "posedb/database.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

namespace {

struct ScriptPerson {
  int id = 0, clip = 0, offset = 0, view = 0;
};

std::vector<std::vector<ScriptPerson>> parse_script(const std::string& text) {
  std::vector<std::vector<ScriptPerson>> frames(1);
  std::istringstream in(text);
  for (char c; in.get(c);) {
    if (c == ';') frames.emplace_back();
    if (c == ';' || c == ',' || c == ' ') continue;
    in.unget();
    ScriptPerson p;
    char colon;
    if (!(in >> p.id >> colon >> p.clip >> colon >> p.offset >> colon >> p.view))
      throw std::invalid_argument("unit.people_script: bad script near '" + text + "'");
    frames.back().push_back(p);
  }
  return frames;
}

// BODY_25 keypoints of a 2D body given as the 15 joints (pixels); the feet stay missing.
std::vector<Keypoint2D> body25_of(const std::array<glm::vec2, kBodyJoints>& b) {
  std::vector<Keypoint2D> k(25, Keypoint2D{0, 0, 0});
  auto set = [&](int i, glm::vec2 p) { k[static_cast<size_t>(i)] = {p.x, p.y, 0.9f}; };
  const glm::vec2 head = b[index(Joint::head)];
  set(0, head);
  set(1, b[index(Joint::neck)]);
  for (int j = 2; j <= 7; ++j) set(j, b[static_cast<size_t>(j)]);  // same order as Body15
  set(8, b[index(Joint::root)]);
  for (int j = 0; j < 3; ++j) {
    set(9 + j, b[static_cast<size_t>(index(Joint::right_hip) + j)]);
    set(12 + j, b[static_cast<size_t>(index(Joint::left_hip) + j)]);
  }
  set(15, head);
  set(16, head);
  set(17, head - glm::vec2(6, 0));
  set(18, head + glm::vec2(6, 0));
  return k;
}

}  // namespace

class PeopleScriptSource : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Test source: matched people from a script over a pose database");
    c.output<People3D>("people3d");
    c.output<People2D>("people2d");
    c.output<VideoFrame>("video");
    c.required_param<std::string>("db", "pose database");
    c.required_param<std::string>("script", "frames ';', people ',', person id:clip:offset:view");
    c.param_list<std::int64_t>("skip_2d", {}, "frames sent without People2D", {0, 1e9});
    c.param<bool>("repeat", false, "play the script until stopped");
    c.param<double>("interval_ms", 0.0, "pause between frames", {0, 10000});
    c.param<double>("depth_m", 0.0, "place people in front of a pinhole camera (0: no keypoints)",
                    {0, 100});
  }

  void open(Context& ctx) override {
    db_ = std::make_unique<posedb::Database>(posedb::Database::open(ctx.param<std::string>("db")));
    script_ = parse_script(ctx.param<std::string>("script"));
    skip_2d_ = ctx.param<std::vector<std::int64_t>>("skip_2d");
    repeat_ = ctx.param<bool>("repeat");
    depth_m_ = ctx.param<float>("depth_m");
    interval_ =
        std::chrono::nanoseconds(static_cast<std::int64_t>(ctx.param<double>("interval_ms") * 1e6));
  }

  void process(Context& ctx) override {
    if (!repeat_ && frame_ >= static_cast<std::int64_t>(script_.size())) return ctx.finish();
    if (frame_ > 0 && interval_.count() > 0 && !ctx.sleep_for(interval_)) return;
    const Header header{"script", static_cast<std::uint64_t>(frame_),
                        1'000'000'000 + frame_ * 40'000'000, frame_};
    const auto& people = script_[static_cast<size_t>(frame_) % script_.size()];
    const auto loop = static_cast<int>(frame_ / static_cast<std::int64_t>(script_.size()));
    People3D p3;
    People2D p2;
    p3.header = p2.header = header;
    p2.layout = LayoutId::body25;
    for (std::size_t slot = 0; slot < people.size(); ++slot) {
      p3.people.push_back(person3d(people[slot], loop));
      if (depth_m_ > 0) project(p3.people.back(), static_cast<int>(slot));
      p2.people.push_back(person2d(p3.people.back(), static_cast<int>(slot)));
    }
    VideoFrame video;
    video.header = header;
    video.image = ImageBuffer(320, 180, PixelFormat::rgb8);
    for (std::size_t i = 0; i < video.image.size_bytes(); i += 3)
      video.image.pixels_for_writing()[i] = std::byte{200};  // red, in RGB
    ctx.send("video", std::move(video));
    if (std::find(skip_2d_.begin(), skip_2d_.end(), frame_) == skip_2d_.end())
      ctx.send("people2d", std::move(p2));
    ctx.send("people3d", std::move(p3));
    ++frame_;
  }

 private:
  Person3D person3d(const ScriptPerson& s, int loop) const {
    const posedb::ClipInfo& clip = db_->clips()[static_cast<size_t>(s.clip)];
    const auto frame =
        clip.first_frame + static_cast<std::uint32_t>(s.offset + loop) % clip.frame_count;
    Person3D p;
    p.id = s.id;
    p.provenance = {clip.name, frame, s.view};
    const glm::quat turn = glm::angleAxis(
        -glm::radians(db_->views()[static_cast<size_t>(s.view)].yaw_deg), glm::vec3(0, 1, 0));
    const auto joints = db_->joints(frame);
    for (int j = 0; j < kBodyJoints; ++j) {
      const glm::vec3 body = turn * glm::vec3(joints[3 * j], joints[3 * j + 1], joints[3 * j + 2]);
      p.positions[static_cast<size_t>(j)] = glm::vec3(body.x, -body.y, -body.z);  // camera axes
    }
    return p;
  }

  // The exact keypoints of `p` standing at (1.2 slot, 0, depth_m) in the camera frame.
  void project(Person3D& p, int slot) const {
    const glm::vec3 root = p.positions[index(Joint::root)];
    const glm::vec3 at(1.2f * static_cast<float>(slot), 0.0f, depth_m_);
    for (int j = 0; j < kBodyJoints; ++j) {
      const glm::vec3 c = p.positions[static_cast<size_t>(j)] - root + at;
      p.keypoints[static_cast<size_t>(j)] = {320.0f + 600.0f * c.x / c.z,
                                             240.0f + 600.0f * c.y / c.z, 0.9f};
    }
  }

  // The body seen from the front, 200 pixels a metre, each person 300 pixels right of the last.
  static Person2D person2d(const Person3D& p3, int slot) {
    std::array<glm::vec2, kBodyJoints> body;
    for (int j = 0; j < kBodyJoints; ++j) {
      const glm::vec3 q = p3.positions[static_cast<size_t>(j)];
      body[static_cast<size_t>(j)] =
          glm::vec2(250.0f + 300.0f * float(slot) + 200.0f * q.x, 360.0f + 200.0f * q.y);
    }
    Person2D p;
    p.id = p3.id;
    p.joints = body25_of(body);
    glm::vec2 lo(1e9f), hi(-1e9f);
    for (const glm::vec2& b : body) {
      lo = glm::min(lo, b);
      hi = glm::max(hi, b);
    }
    p.box = {lo.x, lo.y, hi.x - lo.x, hi.y - lo.y};
    return p;
  }

  std::unique_ptr<posedb::Database> db_;
  std::vector<std::vector<ScriptPerson>> script_;
  std::vector<std::int64_t> skip_2d_;
  bool repeat_ = false;
  float depth_m_ = 0.0f;
  std::chrono::nanoseconds interval_{0};
  std::int64_t frame_ = 0;
};

MOCAP_REGISTER_NODE("unit.people_script", PeopleScriptSource)

}  // namespace mocap::nodes
