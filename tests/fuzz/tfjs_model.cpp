// Fuzz target: a TF.js graph model (detect/tfjs_model.hpp parse_tfjs_model): model.json's text,
// optionally a line @@BIN@@ and the weight bytes. A model that reads is written as a GraphDef for
// cv::dnn (detect/tfjs_graph.hpp; not imported) and, for its last node, built and run by the
// XNNPACK runtime (detect/graph_runner.hpp) on an input of its placeholder's shape (free sizes 8).

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "detect/graph_runner.hpp"
#include "detect/tfjs_graph.hpp"
#include "detect/tfjs_model.hpp"
#include "fuzz_support.hpp"

namespace {

using namespace mocap::detect;

constexpr const char* kName = "fuzz-model.json";

// The placeholder's shape with free sizes 8, or nothing when it is huge or absent.
std::vector<std::int64_t> input_shape(const TfjsModel& model) {
  for (const TfjsNode& n : model.nodes) {
    if (n.op != "Placeholder") continue;
    const TfjsAttr* shape = n.find("shape");
    if (!shape || shape->unknown_rank || shape->shape.empty() || shape->shape.size() > 6) break;
    std::vector<std::int64_t> out;
    std::int64_t total = 1;
    for (const std::int64_t d : shape->shape) {
      out.push_back(d < 0 ? 8 : d);
      if (out.back() == 0 || out.back() > 4096 || (total *= out.back()) > (1 << 20)) return {};
    }
    return out;
  }
  return {1, 8, 8, 3};
}

void run(std::shared_ptr<const TfjsModel> model) {
  const TfjsNode* last = nullptr;
  for (const TfjsNode& n : model->nodes)
    if (n.op != "Const") last = &n;
  if (!last) return;
  const std::vector<std::string> outputs = {last->name};
  try {
    tfjs_to_graphdef(*model, outputs);
  } catch (const std::runtime_error& e) {
    mocap::fuzz::expect_named(e, kName);
  }
  if (!xnnpack_available()) return;
  const std::vector<std::int64_t> shape = input_shape(*model);
  if (shape.empty()) return;
  std::size_t size = 1;
  for (const std::int64_t d : shape) size *= static_cast<std::size_t>(d);
  RunnerOptions options;
  options.backend = Backend::xnnpack;
  options.threads = 1;
  const std::vector<float> input(size, 1.0f);
  std::vector<GraphTensor> out;
  make_graph_runner(std::move(model), outputs, options)->run({shape, input}, out);
  for (const GraphTensor& t : out) mocap::fuzz::check(t.values.size() == t.size(), "output size");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view json = mocap::fuzz::text(data, size), weights;
  if (!mocap::fuzz::split(mocap::fuzz::text(data, size), "\n@@BIN@@\n", json, weights))
    weights = {};
  try {
    run(std::make_shared<const TfjsModel>(parse_tfjs_model(json, weights, kName)));
  } catch (const std::invalid_argument& e) {
    mocap::fuzz::expect_named(e, kName);
  } catch (const std::runtime_error& e) {
    mocap::fuzz::expect_named(e, kName);
  }
  return 0;
}
