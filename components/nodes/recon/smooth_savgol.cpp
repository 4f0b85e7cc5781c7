// recon.smooth_savgol: Savitzky-Golay smoothing of every person's joint positions (order 3,
// window 11 by default, the paper's offline setting). Centred windows need the future: frame t
// leaves once frame t + window/2 has arrived (or at the end).

#include <deque>
#include <optional>

#include "graph/registry.hpp"
#include "recon/savitzky_golay.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class SmoothSavgolNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Smooths each person's 3D joints with a Savitzky-Golay filter (delay: window / 2 frames)");
    c.input<People3D>("in");
    c.output<People3D>("out");
    c.param<int>("order", 3, "polynomial order", {0, 10});
    c.param<int>("window", 11, "window length in frames (odd, > order)", {3, 201});
  }
  void open(Context& ctx) override {
    const int window = ctx.param<int>("window");
    if (window % 2 == 0) throw std::invalid_argument("window must be odd");
    filter_.emplace(ctx.param<int>("order"), window);
    half_ = window / 2;
  }
  void process(Context& ctx) override {
    frames_.push_back(ctx.input<People3D>("in"));
    while (sent_ + static_cast<std::size_t>(half_) < frames_.size()) send_frame(ctx, sent_);
  }
  void close(Context& ctx) override {
    while (sent_ < frames_.size()) send_frame(ctx, sent_);
  }

 private:
  // Smooths frame `index` of the buffer from the person's run of frames around it and sends it.
  void send_frame(Context& ctx, std::size_t index) {
    People3D out = frames_[index];
    for (Person3D& person : out.people) {
      const std::size_t begin = index >= static_cast<std::size_t>(half_) ? index - half_ : 0;
      const std::size_t end = std::min(frames_.size(), index + half_ + 1);
      std::vector<std::size_t>
          run;  // frames of the buffer holding this person, contiguous around index
      std::size_t at = index;
      while (at > begin && find(frames_[at - 1], person.id)) --at;
      for (std::size_t i = at; i < end && find(frames_[i], person.id); ++i) run.push_back(i);
      if (run.size() < 3) continue;
      for (int j = 0; j < kBodyJoints; ++j) {
        track_.clear();
        for (std::size_t i : run) track_.push_back(find(frames_[i], person.id)->positions[j]);
        person.positions[j] = filter_->smooth(track_)[index - run.front()];
      }
    }
    ctx.send("out", std::move(out));
    sent_ = index + 1;
    // Keep what later frames' windows still need: half a window before the next frame to send.
    while (sent_ > static_cast<std::size_t>(half_)) {
      frames_.pop_front();
      --sent_;
    }
  }
  static const Person3D* find(const People3D& frame, int id) {
    for (const Person3D& p : frame.people)
      if (p.id == id) return &p;
    return nullptr;
  }
  std::optional<recon::SavitzkyGolay> filter_;
  int half_ = 5;
  std::deque<People3D> frames_;
  std::size_t sent_ = 0;  // frames_[0, sent_) have been sent
  std::vector<glm::vec3> track_;
};

MOCAP_REGISTER_NODE("recon.smooth_savgol", SmoothSavgolNode)

}  // namespace mocap::nodes
