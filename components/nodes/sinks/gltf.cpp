// sink.gltf: every tracked person's motion as glTF 2.0 binary (GLB), written at the end of the
// stream: one file per person (`path` with {id}) or one file with everybody (`all_in_one`). The
// frames are those sink.bvh writes (recon/people_bvh_writer.hpp, kept in memory): the database
// skeleton's rotations, root turned by the matched view or placed by the fitting, gaps held. The
// file layout is export/gltf_writer.hpp's (docs/export.md).

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "export/gltf_writer.hpp"
#include "graph/registry.hpp"
#include "posedb/database.hpp"
#include "recon/people_bvh_writer.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

namespace {

// `pattern` with every "{id}" replaced by the id.
std::string path_for(std::string pattern, int id) {
  const std::string key = "{id}";
  for (auto at = pattern.find(key); at != std::string::npos; at = pattern.find(key, at))
    pattern.replace(at, key.size(), std::to_string(id));
  return pattern;
}

}  // namespace

class GltfSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Writes every person's motion as glTF 2.0 binary at the end of the stream: one GLB per "
        "person (path with {id}) or one for all (all_in_one); joints as nodes, skin, stick mesh, "
        "one animation (database skeleton rotations, root translation)");
    c.input<People3D>("in", "reconstructed people with database provenance");
    c.required_param<std::string>(
        "path",
        "output file: a pattern with {id} per person (e.g. out/person_{id}.glb), or the "
        "one file with all_in_one");
    c.required_param<std::string>("db", "the pose database the people were matched against");
    c.param<bool>("all_in_one", false,
                  "one GLB with every person (node names prefixed person_<id>:, each starting at "
                  "its first frame's time)");
    c.param<bool>("mesh", true, "a skinned stick figure per person (false: joints only)");
    c.param<bool>("smooth", true, "smooth the joint rotations with the 1-Euro filter");
    c.param<double>("beta", 0.4, "1-Euro cutoff slope for the rotations", {0.0, 100.0});
    c.param<double>("min_cutoff", 1.0, "1-Euro cutoff at rest (Hz) for the rotations",
                    {0.001, 1000.0});
    c.param<int>("min_frames", 12,
                 "frames a person must have before they get a file (shorter ids: none)",
                 {1, 1000000});
    c.param<double>("fps", 30.0, "input frame rate: the animation's key rate", {0.001, 10000.0});
  }

  void open(Context& ctx) override {
    path_ = ctx.param<std::string>("path");
    all_in_one_ = ctx.param<bool>("all_in_one");
    if (!all_in_one_ && path_.find("{id}") == std::string::npos)
      throw InputError(ctx.node_name(), "path '" + path_ +
                                            "' has no {id}: one file per person needs it, or set "
                                            "all_in_one: true");
    mesh_ = ctx.param<bool>("mesh");
    db_ = std::make_unique<posedb::Database>(posedb::Database::open(ctx.param<std::string>("db")));
    recon::PeopleBvhOptions options;
    options.in_memory = true;
    options.fps = ctx.param<double>("fps");
    options.min_frames = ctx.param<int>("min_frames");
    options.smooth_rotations = ctx.param<bool>("smooth");
    options.smoothing.beta = ctx.param<double>("beta");
    options.smoothing.min_cutoff = ctx.param<double>("min_cutoff");
    fps_ = options.fps;
    frames_ = std::make_unique<recon::PeopleBvhWriter>(*db_, std::move(options));
  }

  void process(Context& ctx) override { frames_->write(ctx.input<People3D>("in")); }

  void close(Context& ctx) override {
    if (!frames_) return;
    frames_->close();
    const std::vector<recon::PersonClip> people = frames_->take_clips();
    exporting::GltfOptions options;
    options.mesh = mesh_;
    std::int64_t first = 0;
    for (std::size_t i = 0; i < people.size(); ++i)
      first = i == 0 ? people[i].first_frame : std::min(first, people[i].first_frame);
    std::vector<exporting::GltfFigure> figures;
    for (const recon::PersonClip& person : people) {
      exporting::GltfFigure figure;
      figure.name = "person_" + std::to_string(person.id);
      figure.clip = &person.clip;
      if (all_in_one_)
        figure.start_seconds = static_cast<double>(person.first_frame - first) / fps_;
      figures.push_back(std::move(figure));
    }
    std::cerr << "sink.gltf '" << ctx.node_name() << "': " << frames_->summary().describe() << "\n";
    if (figures.empty()) return;
    if (all_in_one_) {
      const exporting::GltfSummary s = exporting::write_glb(figures, path_, options);
      std::cerr << "sink.gltf '" << ctx.node_name() << "': " << path_ << " (" << s.figures
                << " people, " << s.bytes << " bytes)\n";
      return;
    }
    for (std::size_t i = 0; i < figures.size(); ++i) {
      const std::string path = path_for(path_, people[i].id);
      const exporting::GltfSummary s = exporting::write_glb({&figures[i], 1}, path, options);
      std::cerr << "sink.gltf '" << ctx.node_name() << "': " << path << " (" << s.frames
                << " frames, " << s.bytes << " bytes)\n";
    }
  }

 private:
  std::string path_;
  bool all_in_one_ = false;
  bool mesh_ = true;
  double fps_ = 30.0;
  std::unique_ptr<posedb::Database> db_;
  std::unique_ptr<recon::PeopleBvhWriter> frames_;
};

MOCAP_REGISTER_NODE("sink.gltf", GltfSink)

}  // namespace mocap::nodes
