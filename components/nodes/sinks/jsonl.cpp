// sink.jsonl: one JSON line per input frame, in input order:
//   {"frame": 0, "time": 0.0, "people": [{"id": 1, "joints": {"head": [x, y, z], ...},
//    "joints_abs": {...}, "keypoints": [x, y, c, ...]}], "ground": {"normal": [x, y, z], "offset":
//    d}}
// with the 15 body joint names, metres, camera coordinates (x right, y down, z forward).
// `joints` are root-relative; `joints_abs` (absolute camera-frame positions) appear for people
// whose root translation is estimated (recon.fit), `keypoints` (the 15 body joints' 2D input, image
// pixels as detected and confidence, 0 0 0 where missing) for people reconstructed from a 2D
// detection, so that a recording can be replayed beside its input (mocap view), `ground` once the
// floor is known (points p with normal . p + offset = 0, normal up).
//
// The file is created when the first frame arrives (a run that fails before leaves an earlier
// file untouched). Each line is one write, flushed, so the file holds every finished frame even
// if the run is killed; a kill in the middle of a write can only leave the last line cut, without
// its newline (readers skip such a tail: web::read_poses_jsonl, mocap reconstruct's summary).

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "graph/registry.hpp"

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
    path_ = ctx.param<std::string>("path");
    check_writable(path_);
  }
  void process(Context& ctx) override {
    if (!file_) {
      file_.reset(::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
      if (!file_)
        throw InputError(path_, std::string("cannot create the file: ") + std::strerror(errno));
    }
    const auto& in = ctx.input<People3D>("in");
    nlohmann::ordered_json people = nlohmann::ordered_json::array();
    for (const Person3D& p : in.people) {
      nlohmann::ordered_json person = {{"id", p.id}, {"joints", joints_of(p, glm::vec3(0.0f))}};
      if (p.placed) person["joints_abs"] = joints_of(p, p.root.translation);
      if (has_keypoints(p)) person["keypoints"] = keypoints_of(p);
      people.push_back(std::move(person));
    }
    nlohmann::ordered_json line = {{"frame", in.header.frame},
                                   {"time", static_cast<double>(in.header.capture_ns) * 1e-9},
                                   {"people", people}};
    if (in.has_ground) {
      line["ground"] = {{"normal", {in.ground.normal.x, in.ground.normal.y, in.ground.normal.z}},
                        {"offset", round_mm(in.ground.offset)}};
    }
    const std::string text = line.dump() + "\n";
    write_line(text);
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
  // An existing file is opened for writing and closed (not truncated); for a new one its folder
  // is made and a file created and removed beside it (access() says yes to root even in /proc).
  static void check_writable(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (fs::exists(path, ec)) {
      const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (fd < 0)
        throw InputError(path, std::string("cannot write the file: ") + std::strerror(errno));
      ::close(fd);
      return;
    }
    const fs::path folder = fs::path(path).parent_path();
    if (!folder.empty() && !fs::create_directories(folder, ec) && ec)
      throw InputError(path, "cannot create the file: " + ec.message());
    // Built by append: GCC 12 warns (falsely, -Wrestrict) on "." + name + ".probe".
    std::string probe_name = ".";
    probe_name.append(fs::path(path).filename().string()).append(".probe");
    const fs::path probe = (folder.empty() ? fs::path(".") : folder) / probe_name;
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0 && errno != EEXIST)
      throw InputError(path, std::string("cannot create the file: ") + std::strerror(errno));
    if (fd >= 0) {
      ::close(fd);
      ::unlink(probe.c_str());
    }
  }
  // One write() per line (retried only if the kernel writes part of it); on a failure the file
  // is cut back to its last whole line, so it stays valid.
  void write_line(std::string_view text) {
    std::string_view rest = text;
    while (!rest.empty()) {
      const ssize_t n = ::write(file_.get(), rest.data(), rest.size());
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const int error = n == 0 ? EIO : errno;
        [[maybe_unused]] const int cut = ::ftruncate(file_.get(), end_);  // best effort
        throw InputError(path_, std::string("write failed: ") + std::strerror(error) +
                                    " (disk full or over the file size limit?)");
      }
      rest.remove_prefix(static_cast<std::size_t>(n));
    }
    end_ += static_cast<off_t>(text.size());
  }
  struct Fd {
    int fd = -1;
    Fd() = default;
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    ~Fd() { reset(); }
    void reset(int to = -1) {
      if (fd >= 0) ::close(fd);
      fd = to;
    }
    int get() const { return fd; }
    explicit operator bool() const { return fd >= 0; }
  };
  std::string path_;
  Fd file_;
  off_t end_ = 0;  // size after the last whole line
};

MOCAP_REGISTER_NODE("sink.jsonl", JsonLinesSink)

}  // namespace mocap::nodes
