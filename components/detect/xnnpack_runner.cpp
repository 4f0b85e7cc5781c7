// GraphRunner on XNNPACK: the TF.js model built into an XNNPACK subgraph per input shape
// (xnnpack_graph.hpp), each with its runtime (memory planned, weights packed), kept for the
// shapes seen last. The runner owns its thread pool: two runners on one thread each use two cores
// without sharing anything.

#include <pthreadpool.h>

#include <algorithm>
#include <cstring>
#include <list>
#include <mutex>
#include <stdexcept>

#include "detect/runner_backends.hpp"
#include "detect/xnnpack_graph.hpp"

namespace mocap::detect {
namespace {

constexpr std::size_t kCachedShapes = 4;  // input sizes kept built (MultiPose: one per frame size)
constexpr std::size_t kExtraFloats = XNN_EXTRA_BYTES / sizeof(float);  // XNNPACK reads past ends

struct PoolDeleter {
  void operator()(pthreadpool* p) const { pthreadpool_destroy(p); }
};
struct RuntimeDeleter {
  void operator()(xnn_runtime* r) const { xnn_delete_runtime(r); }
};

// Copies between TensorFlow's row-major order and a value's physical order (layouts of
// xnnpack_graph.hpp). `to_physical` scatters logical -> physical, else gathers.
void relayout(const xnn::Layout& layout, const float* from, float* to, bool to_physical) {
  std::vector<std::size_t> sizes, strides;  // per logical sub-axis, in logical order
  std::vector<std::size_t> physical_strides(layout.physical.size(), 1);
  for (std::size_t p = layout.physical.size(); p-- > 1;)
    physical_strides[p - 1] = physical_strides[p] * layout.physical[p];
  for (const auto& group : layout.groups)
    for (const int p : group) {
      sizes.push_back(layout.physical[static_cast<std::size_t>(p)]);
      strides.push_back(physical_strides[static_cast<std::size_t>(p)]);
    }
  std::size_t total = 1;
  for (const std::size_t s : sizes) total *= s;
  std::vector<std::size_t> index(sizes.size(), 0);
  std::size_t offset = 0;
  for (std::size_t flat = 0; flat < total; ++flat) {
    if (to_physical)
      to[offset] = from[flat];
    else
      to[flat] = from[offset];
    for (std::size_t a = sizes.size(); a-- > 0;) {
      offset += strides[a];
      if (++index[a] < sizes[a]) break;
      offset -= strides[a] * sizes[a];
      index[a] = 0;
    }
  }
}

bool is_row_major(const xnn::Layout& layout) {
  int next = 0;
  for (const auto& group : layout.groups)
    for (const int p : group)
      if (p != next++) return false;
  return next == static_cast<int>(layout.physical.size());
}

std::size_t count(const std::vector<std::size_t>& dims) {
  std::size_t n = 1;
  for (const std::size_t d : dims) n *= d;
  return n;
}

class XnnpackRunner : public GraphRunner {
 public:
  XnnpackRunner(std::shared_ptr<const TfjsModel> model, std::span<const std::string> outputs,
                const RunnerOptions& options)
      : model_(std::move(model)), cut_(xnn::make_cut(*model_, outputs, options.input_node)) {
    xnn::check_supported(*model_, cut_);
    const int threads = options.threads;
    for (const TfjsNode& n : model_->nodes)
      if (n.name == cut_.input && n.op == "Placeholder")
        if (const TfjsAttr* shape = n.find("shape"); shape && !shape->unknown_rank)
          declared_shape_ = shape->shape;
    if (threads > 1) {  // else the calling thread alone
      pool_.reset(pthreadpool_create(static_cast<std::size_t>(threads)));
      if (!pool_) throw std::runtime_error("could not start the XNNPACK thread pool");
    }
  }

  void run(const GraphTensorView& input, std::vector<GraphTensor>& outputs) override {
    check_input(input);
    Compiled& c = compiled_for(input.shape);
    if (is_row_major(c.graph.input_layout))
      std::copy(input.values.begin(), input.values.end(), c.input.begin());
    else
      relayout(c.graph.input_layout, input.values.data(), c.input.data(), true);
    if (xnn_invoke_runtime(c.runtime.get()) != xnn_status_success)
      throw std::runtime_error("XNNPACK failed to run " + model_->file.string());
    outputs.resize(c.outputs.size());
    for (std::size_t i = 0; i < c.outputs.size(); ++i) {
      const xnn::Layout& layout = c.graph.output_layouts[i];
      GraphTensor& out = outputs[i];
      out.shape = layout.logical_shape();
      out.values.resize(count(layout.physical));
      if (is_row_major(layout))
        std::copy(c.outputs[i].begin(), c.outputs[i].begin() + static_cast<long>(out.values.size()),
                  out.values.begin());
      else
        relayout(layout, c.outputs[i].data(), out.values.data(), false);
    }
  }

  Backend backend() const override { return Backend::xnnpack; }

 private:
  struct Compiled {
    std::vector<std::int64_t> shape;
    xnn::BuiltGraph graph;
    std::unique_ptr<xnn_runtime, RuntimeDeleter> runtime;
    std::vector<float> input;
    std::vector<std::vector<float>> outputs;
  };

  void check_input(const GraphTensorView& input) const {
    std::size_t size = 1;
    for (const std::int64_t d : input.shape) {
      if (d <= 0 || d > (1 << 20) || size > (std::size_t{1} << 28) / static_cast<std::size_t>(d))
        throw std::invalid_argument("input dimension " + std::to_string(d) + " for " +
                                    model_->file.string() + " (empty or too large)");
      size *= static_cast<std::size_t>(d);
    }
    if (size != input.values.size())
      throw std::invalid_argument("input of " + std::to_string(input.values.size()) +
                                  " values for a shape of " + std::to_string(size) + " to " +
                                  model_->file.string());
    if (declared_shape_.empty()) return;
    bool fits = declared_shape_.size() == input.shape.size();
    for (std::size_t a = 0; fits && a < input.shape.size(); ++a)
      fits = declared_shape_[a] < 0 || declared_shape_[a] == input.shape[a];
    if (!fits)
      throw std::invalid_argument(model_->file.string() + " takes inputs shaped " +
                                  describe(declared_shape_) + ", not " + describe(input.shape));
  }

  static std::string describe(std::span<const std::int64_t> shape) {
    std::string s = "[";
    for (std::size_t i = 0; i < shape.size(); ++i) {
      if (i) s += ',';
      s += shape[i] < 0 ? std::string("?") : std::to_string(shape[i]);
    }
    return s + "]";
  }

  Compiled& compiled_for(std::span<const std::int64_t> shape) {
    for (auto it = cache_.begin(); it != cache_.end(); ++it) {
      if (std::equal(it->shape.begin(), it->shape.end(), shape.begin(), shape.end())) {
        cache_.splice(cache_.begin(), cache_, it);  // most recent first
        return cache_.front();
      }
    }
    Compiled c;
    c.shape.assign(shape.begin(), shape.end());
    c.graph = xnn::build_subgraph(*model_, cut_, shape);
    xnn_runtime_t runtime = nullptr;
    if (xnn_create_runtime_v2(c.graph.subgraph.get(), pool_.get(), 0, &runtime) !=
        xnn_status_success)
      fail_model(model_->file, "XNNPACK could not create a runtime for input " + describe(shape));
    c.runtime.reset(runtime);
    c.input.assign(count(c.graph.input_layout.physical) + kExtraFloats, 0.0f);
    std::vector<xnn_external_value> externals = {{c.graph.input_id, c.input.data()}};
    for (std::size_t i = 0; i < c.graph.output_ids.size(); ++i) {
      c.outputs.emplace_back(count(c.graph.output_layouts[i].physical) + kExtraFloats, 0.0f);
      externals.push_back({c.graph.output_ids[i], c.outputs.back().data()});
    }
    if (xnn_setup_runtime(c.runtime.get(), externals.size(), externals.data()) !=
        xnn_status_success)
      fail_model(model_->file, "XNNPACK could not set up the runtime for input " + describe(shape));
    cache_.push_front(std::move(c));
    if (cache_.size() > kCachedShapes) cache_.pop_back();
    return cache_.front();
  }

  std::shared_ptr<const TfjsModel> model_;
  xnn::GraphCut cut_;
  std::vector<std::int64_t> declared_shape_;  // the placeholder's, -1 for free sizes
  std::unique_ptr<pthreadpool, PoolDeleter> pool_;
  std::list<Compiled> cache_;
};

}  // namespace

bool initialise_xnnpack() {
  static std::once_flag once;
  static bool ok = false;
  std::call_once(once, [] { ok = xnn_initialize(nullptr) == xnn_status_success; });
  return ok;
}

std::unique_ptr<GraphRunner> make_xnnpack_runner(std::shared_ptr<const TfjsModel> model,
                                                 std::span<const std::string> outputs,
                                                 const RunnerOptions& options) {
  return std::make_unique<XnnpackRunner>(std::move(model), outputs, options);
}

}  // namespace mocap::detect
