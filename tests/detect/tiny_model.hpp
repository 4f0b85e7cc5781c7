#pragma once
// A tiny hand-written TF.js graph model (no download needed) for the loader and runtime tests.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/files.hpp"

namespace mocap::detect {

// input (int32 RGB) -> Cast -> _FusedConv2D 1×1, 3 -> 2 channels, [BiasAdd, Relu]; and two
// post-processing nodes the loader refuses.
inline constexpr const char* kTinyModel = R"({
  "format": "graph-model",
  "modelTopology": {"node": [
    {"name": "w", "op": "Const", "attr": {"dtype": {"type": "DT_FLOAT"}}},
    {"name": "b", "op": "Const", "attr": {"dtype": {"type": "DT_FLOAT"}}},
    {"name": "k", "op": "Const", "attr": {"dtype": {"type": "DT_INT32"}}},
    {"name": "input", "op": "Placeholder", "attr": {"dtype": {"type": "DT_INT32"},
      "shape": {"shape": {"dim": [{"size": "1"}, {"size": "-1"}, {"size": "-1"}, {"size": "3"}]}}}},
    {"name": "cast", "op": "Cast", "input": ["input"],
     "attr": {"SrcT": {"type": "DT_INT32"}, "DstT": {"type": "DT_FLOAT"}}},
    {"name": "conv", "op": "_FusedConv2D", "input": ["cast", "w", "b"], "attr": {
      "T": {"type": "DT_FLOAT"}, "strides": {"list": {"i": ["1", "1", "1", "1"]}},
      "dilations": {"list": {"i": ["1", "1", "1", "1"]}}, "padding": {"s": "U0FNRQ=="},
      "data_format": {"s": "TkhXQw=="}, "num_args": {"i": "1"},
      "fused_ops": {"list": {"s": ["Qmlhc0FkZA==", "UmVsdQ=="]}}}},
    {"name": "topk", "op": "TopKV2", "input": ["conv", "k"]},
    {"name": "pack", "op": "Pack", "input": ["conv"]}
  ], "versions": {"producer": 808}},
  "weightsManifest": [{"paths": ["tiny.bin"], "weights": [
    {"name": "w", "shape": [1, 1, 3, 2], "dtype": "float32",
     "quantization": {"dtype": "float16", "original_dtype": "float32"}},
    {"name": "b", "shape": [2], "dtype": "float32",
     "quantization": {"dtype": "float16", "original_dtype": "float32"}},
    {"name": "k", "shape": [], "dtype": "int32"}
  ]}]
})";

// Kernel HWIO: out0 = r + 0.5 g - b - 10, out1 = 2 b + 1 (float16: 1, 0, .5, 0, -1, 2; -10, 1).
inline std::string tiny_weights() {
  const std::vector<std::uint16_t> halves = {0x3C00, 0x0000, 0x3800, 0x0000,
                                             0xBC00, 0x4000, 0xC900, 0x3C00};
  std::string bytes(reinterpret_cast<const char*>(halves.data()), halves.size() * 2);
  const std::int32_t k = 6;
  bytes.append(reinterpret_cast<const char*>(&k), sizeof k);
  return bytes;
}

struct TinyModel {
  test::TempDir dir;
  std::filesystem::path json = dir.path() / "tiny.json";
  explicit TinyModel(const std::string& weights = tiny_weights(), std::string text = kTinyModel) {
    std::ofstream(json) << text;
    std::ofstream(dir.path() / "tiny.bin", std::ios::binary) << weights;
  }
};

}  // namespace mocap::detect
