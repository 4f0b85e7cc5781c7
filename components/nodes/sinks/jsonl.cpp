// sink.jsonl: one JSON line per input frame, in input order:
//   {"frame": 0, "time": 0.0, "people": [{"id": 1, "joints": {"head": [x, y, z], ...},
//    "joints_abs": {...}, "keypoints": [x, y, c, ...]}], "ground": {"normal": [x, y, z], "offset":
//    d}}
// with the 15 body joint names, metres, in the message's frame: a camera's coordinates (x right,
// y down, z forward), or the rig's world. `joints` are root-relative; `joints_abs` (absolute
// camera-frame positions) appear for people whose root translation is estimated (recon.fit),
// `joints_world` instead for people of a world-frame message (the rig's world, e.g. a multi-view
// reconstruction), `keypoints` (the 15 body joints' 2D input, image
// pixels as detected and confidence, 0 0 0 where missing) for people reconstructed from a 2D
// detection, so that a recording can be replayed beside its input (mocap view), `ground` once the
// floor is known (points p with normal . p + offset = 0, normal up).
//
// The file is written through io::LineFile: created when the first frame arrives (a run that
// fails before leaves an earlier file untouched), one write per line, so the file holds every
// finished frame even if the run is killed; a kill in the middle of a write can only leave the
// last line cut, without its newline (readers skip such a tail: web::read_poses_jsonl, mocap
// reconstruct's summary).

#include <algorithm>
#include <cmath>
#include <optional>

#include <nlohmann/json.hpp>

#include "graph/registry.hpp"
#include "io/line_file.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class JsonLinesSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Writes one JSON line per frame with every person's 15 joints");
    c.input<People3D>("in");
    c.required_param<std::string>(
        "path",
        "file to write (poses.jsonl; its folder made at the start, the file at the first frame)");
  }
  // The file is created when the first frame arrives, so that a run failing before it (a busy
  // port, a bad parameter of another node) leaves an earlier file of that name untouched; that
  // it can be written is checked now, without touching it, so such a run still fails at once.
  void open(Context& ctx) override {
    file_.emplace(ctx.param<std::string>("path"));
    file_->check_writable();
  }
  void process(Context& ctx) override {
    const auto& in = ctx.input<People3D>("in");
    nlohmann::ordered_json people = nlohmann::ordered_json::array();
    for (const Person3D& p : in.people) {
      nlohmann::ordered_json person = {{"id", p.id}, {"joints", joints_of(p, glm::vec3(0.0f))}};
      if (p.placed)
        person[in.frame.is_world() ? "joints_world" : "joints_abs"] =
            joints_of(p, p.root.translation);
      if (has_keypoints(p)) person["keypoints"] = keypoints_of(p);
      people.push_back(std::move(person));
    }
    nlohmann::ordered_json line = {{"frame", in.header.frame},
                                   {"time", static_cast<double>(in.header.capture_ns) * 1e-9},
                                   {"people", people}};
    if (in.has_ground) {
      line["ground"] = {{"normal", {in.ground.normal.x, in.ground.normal.y, in.ground.normal.z}},
                        {"offset", round_mm(static_cast<float>(in.ground.offset))}};
    }
    file_->write(line.dump());
  }
  void close(Context&) override { file_.reset(); }

 private:
  static nlohmann::ordered_json joints_of(const Person3D& p, const glm::vec3& shift) {
    nlohmann::ordered_json joints = nlohmann::ordered_json::object();
    for (int j = 0; j < kBodyJoints; ++j) {
      const glm::vec3 v = p.positions[static_cast<std::size_t>(j)] + shift;
      joints[std::string(kJointNames[j])] = {round_mm(v.x), round_mm(v.y), round_mm(v.z)};
    }
    return joints;
  }
  static bool has_keypoints(const Person3D& p) {
    return std::any_of(p.keypoints.begin(), p.keypoints.end(),
                       [](const Keypoint2D& k) { return k.confidence > 0; });
  }
  // Flat [x, y, confidence] per joint, a tenth of a pixel; a missing keypoint is 0 0 0.
  static nlohmann::ordered_json keypoints_of(const Person3D& p) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const Keypoint2D& k : p.keypoints) {
      const bool ok = k.confidence > 0 && std::isfinite(k.x) && std::isfinite(k.y);
      out.push_back(ok ? std::round(static_cast<double>(k.x) * 10.0) / 10.0 : 0.0);
      out.push_back(ok ? std::round(static_cast<double>(k.y) * 10.0) / 10.0 : 0.0);
      out.push_back(ok ? std::round(static_cast<double>(k.confidence) * 100.0) / 100.0 : 0.0);
    }
    return out;
  }
  // Millimetre precision keeps the file small and the numbers readable.
  static double round_mm(float v) { return std::round(static_cast<double>(v) * 1000.0) / 1000.0; }
  std::optional<io::LineFile> file_;
};

MOCAP_REGISTER_NODE("sink.jsonl", JsonLinesSink)

}  // namespace mocap::nodes
