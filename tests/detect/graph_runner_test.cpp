// The GraphRunner interface on tiny hand-written TF.js models (no download needed): both runtimes
// compute the same fused convolution with dequantised weights; XNNPACK names every operation it
// does not convert, refuses inputs of the wrong shape, rebuilds for new input sizes, and lays out
// NCHW inputs, transposes, concatenations, channel splits and reshapes as TensorFlow does.

#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "detect/graph_runner.hpp"
#include "tiny_model.hpp"

namespace mocap::detect {
namespace {

TEST(GraphRunner, ParsesAndNamesBackends) {
  EXPECT_EQ(parse_backend("auto"), Backend::automatic);
  EXPECT_EQ(parse_backend("xnnpack"), Backend::xnnpack);
  EXPECT_EQ(parse_backend("opencv"), Backend::opencv);
  EXPECT_THROW(parse_backend("tflite"), std::invalid_argument);
  EXPECT_EQ(backend_name(Backend::opencv), "opencv");
  EXPECT_EQ(resolve_backend(Backend::automatic),
            xnnpack_available() ? Backend::xnnpack : Backend::opencv);
  EXPECT_EQ(resolve_backend(Backend::opencv), Backend::opencv);
}

std::unique_ptr<GraphRunner> tiny_runner(const TinyModel& model, Backend backend,
                                         std::vector<std::string> outputs = {"conv"}) {
  RunnerOptions options;
  options.backend = backend;
  options.threads = 1;
  return make_graph_runner(model.json, outputs, options);
}

class TinyRunner : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    if (GetParam() == Backend::xnnpack && !xnnpack_available())
      GTEST_SKIP() << "this build has no XNNPACK runtime";
  }
};

// Kernel HWIO: out0 = r + 0.5 g - b - 10, out1 = 2 b + 1, then ReLU (tiny_model.hpp).
TEST_P(TinyRunner, FusedConvolutionWithDequantisedWeightsInNhwc) {
  const TinyModel model;
  const auto runner = tiny_runner(model, GetParam());
  EXPECT_EQ(runner->backend(), GetParam());
  const std::vector<std::int64_t> shape = {1, 1, 2, 3};
  const std::vector<float> rgb = {20, 40, 10, 0, 0, 0};  // NHWC: pixel 0, then the black pixel 1
  std::vector<GraphTensor> out;
  runner->run({shape, rgb}, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].shape, (std::vector<std::int64_t>{1, 1, 2, 2}));
  EXPECT_EQ(out[0].values, (std::vector<float>{20, 21, 0, 1}));
}

TEST_P(TinyRunner, RebuildsForEachInputSizeAndKeepsResults) {
  const TinyModel model;
  const auto runner = tiny_runner(model, GetParam());
  std::vector<GraphTensor> out;
  for (const int width : {2, 3, 2}) {
    const std::vector<std::int64_t> shape = {1, 1, width, 3};
    std::vector<float> rgb(static_cast<std::size_t>(width) * 3, 0.0f);
    rgb[0] = 20, rgb[1] = 40, rgb[2] = 10;
    runner->run({shape, rgb}, out);
    ASSERT_EQ(out[0].values.size(), static_cast<std::size_t>(width) * 2);
    EXPECT_EQ(out[0].values[0], 20.0f);
    EXPECT_EQ(out[0].values.back(), 1.0f);
  }
}

INSTANTIATE_TEST_SUITE_P(Runtimes, TinyRunner, ::testing::Values(Backend::opencv, Backend::xnnpack),
                         [](const auto& p) { return std::string(backend_name(p.param)); });

class XnnpackRunner : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!xnnpack_available()) GTEST_SKIP() << "this build has no XNNPACK runtime";
  }
};

TEST_F(XnnpackRunner, NamesEveryUnsupportedOperationAndTheFile) {
  const TinyModel model;
  try {
    tiny_runner(model, Backend::xnnpack, {"topk", "conv"});
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("TopKV2 (node 'topk')"), std::string::npos) << what;
    EXPECT_NE(what.find("tiny.json"), std::string::npos) << what;
  }
  // A known op the runtime cannot express here (Pack of a computed tensor) names its node.
  try {
    std::vector<GraphTensor> out;
    const std::vector<std::int64_t> shape = {1, 1, 1, 3};
    const std::vector<float> rgb(3, 1.0f);
    tiny_runner(model, Backend::xnnpack, {"pack"})->run({shape, rgb}, out);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("node 'pack'"), std::string::npos) << e.what();
  }
}

TEST_F(XnnpackRunner, AutomaticFallsBackToCvDnnOnlyWhenXnnpackIsNotGivenForTheModel) {
  const TinyModel model;
  EXPECT_EQ(tiny_runner(model, Backend::automatic)->backend(), Backend::xnnpack);
}

TEST_F(XnnpackRunner, RefusesInputsOfTheWrongShape) {
  const TinyModel model;
  const auto runner = tiny_runner(model, Backend::xnnpack);
  std::vector<GraphTensor> out;
  const std::vector<std::int64_t> four_channels = {1, 1, 1, 4};
  EXPECT_THROW(runner->run({four_channels, std::vector<float>(4, 0.0f)}, out),
               std::invalid_argument);
  const std::vector<std::int64_t> shape = {1, 1, 2, 3};
  EXPECT_THROW(runner->run({shape, std::vector<float>(5, 0.0f)}, out), std::invalid_argument);
  const std::vector<std::int64_t> empty = {1, 0, 2, 3};
  EXPECT_THROW(runner->run({empty, std::vector<float>{}}, out), std::invalid_argument);
}

// NCHW float input -> Transpose to NHWC -> the tiny convolution -> ConcatV2 with itself along
// channels -> Transpose to NCHW -> SplitV into channels [1, 3] -> Reshape of the second part to
// [1, 3, H * W].
constexpr const char* kLayoutModel = R"({
  "modelTopology": {"node": [
    {"name": "w", "op": "Const"}, {"name": "b", "op": "Const"},
    {"name": "to_nhwc", "op": "Const"}, {"name": "to_nchw", "op": "Const"},
    {"name": "channels", "op": "Const"}, {"name": "sizes", "op": "Const"},
    {"name": "axis1", "op": "Const"}, {"name": "flat", "op": "Const"},
    {"name": "input", "op": "Placeholder", "attr": {"dtype": {"type": "DT_FLOAT"},
      "shape": {"shape": {"dim": [{"size": "1"}, {"size": "3"}, {"size": "-1"}, {"size": "-1"}]}}}},
    {"name": "nhwc", "op": "Transpose", "input": ["input", "to_nhwc"]},
    {"name": "conv", "op": "_FusedConv2D", "input": ["nhwc", "w", "b"], "attr": {
      "strides": {"list": {"i": ["1", "1", "1", "1"]}}, "padding": {"s": "U0FNRQ=="},
      "fused_ops": {"list": {"s": ["Qmlhc0FkZA==", "UmVsdQ=="]}}}},
    {"name": "cat", "op": "ConcatV2", "input": ["conv", "conv", "channels"]},
    {"name": "nchw", "op": "Transpose", "input": ["cat", "to_nchw"]},
    {"name": "split", "op": "SplitV", "input": ["nchw", "sizes", "axis1"],
     "attr": {"num_split": {"i": "2"}}},
    {"name": "rows", "op": "Reshape", "input": ["split:1", "flat"]}
  ]},
  "weightsManifest": [{"paths": ["layout.bin"], "weights": [
    {"name": "w", "shape": [1, 1, 3, 2], "dtype": "float32",
     "quantization": {"dtype": "float16", "original_dtype": "float32"}},
    {"name": "b", "shape": [2], "dtype": "float32",
     "quantization": {"dtype": "float16", "original_dtype": "float32"}},
    {"name": "to_nhwc", "shape": [4], "dtype": "int32"},
    {"name": "to_nchw", "shape": [4], "dtype": "int32"},
    {"name": "channels", "shape": [], "dtype": "int32"},
    {"name": "sizes", "shape": [2], "dtype": "int32"},
    {"name": "axis1", "shape": [], "dtype": "int32"},
    {"name": "flat", "shape": [3], "dtype": "int32"}
  ]}]
})";

TEST_F(XnnpackRunner, LaysOutNchwInputsTransposesConcatenationsSplitsAndReshapes) {
  std::string weights = tiny_weights().substr(0, 16);  // w and b (float16)
  for (const std::int32_t v : {0, 2, 3, 1, 0, 3, 1, 2, 3, 1, 3, 1, 1, 3, -1})
    weights.append(reinterpret_cast<const char*>(&v), sizeof v);
  test::TempDir dir;
  std::ofstream(dir.path() / "layout.json") << kLayoutModel;
  std::ofstream(dir.path() / "layout.bin", std::ios::binary) << weights;
  RunnerOptions options;
  options.backend = Backend::xnnpack;
  const std::vector<std::string> outputs = {"split", "rows", "cat"};
  const auto runner = make_graph_runner(dir.path() / "layout.json", outputs, options);
  // NCHW 1×3×1×2: pixel 0 is RGB (20, 40, 10), pixel 1 is black.
  const std::vector<std::int64_t> shape = {1, 3, 1, 2};
  const std::vector<float> planes = {20, 0, 40, 0, 10, 0};
  std::vector<GraphTensor> out;
  runner->run({shape, planes}, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].shape, (std::vector<std::int64_t>{1, 1, 1, 2}));  // channel 0 of both pixels
  EXPECT_EQ(out[0].values, (std::vector<float>{20, 0}));
  EXPECT_EQ(out[1].shape, (std::vector<std::int64_t>{1, 3, 2}));  // channels 1..3: c1, c0, c1
  EXPECT_EQ(out[1].values, (std::vector<float>{21, 1, 20, 0, 21, 1}));
  EXPECT_EQ(out[2].shape, (std::vector<std::int64_t>{1, 1, 2, 4}));  // NHWC, channels c0 c1 c0 c1
  EXPECT_EQ(out[2].values, (std::vector<float>{20, 21, 20, 21, 0, 1, 0, 1}));
}

}  // namespace
}  // namespace mocap::detect
