#pragma once
// A TensorFlow.js graph model (model.json + its weight files) read into plain structures: the
// graph's nodes with their attributes decoded, and every weight as float32 or int32 values
// (float16-quantised weights dequantised). Both runtimes start from it: tfjs_graph.* writes it as
// a TensorFlow GraphDef for cv::dnn, xnnpack_runner.cpp builds an XNNPACK subgraph from it.

#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace mocap::detect {

// An error that already names the model file.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws ModelError "TF.js model FILE: WHAT".
[[noreturn]] void fail_model(const std::filesystem::path& file, const std::string& what);

// One TensorFlow AttrValue (exactly one form is set, as in the protobuf).
struct TfjsAttr {
  // `tensor`: a TensorProto (the value of a Const node, whose data is in the weights instead).
  enum class Kind { s, i, f, b, type, shape, list, tensor };
  Kind kind = Kind::s;
  std::string s;  // bytes, base64-decoded
  std::int64_t i = 0;
  float f = 0;
  bool b = false;
  int type = 0;                     // TensorFlow DataType code
  std::vector<std::int64_t> shape;  // Kind::shape: dims (-1 unknown)
  bool unknown_rank = false;
  std::vector<std::string> list_s;  // Kind::list
  std::vector<std::int64_t> list_i;
  std::vector<float> list_f;
  std::vector<int> list_type;
};

struct TfjsNode {
  std::string name;
  std::string op;
  std::vector<std::string> inputs;  // "node", "node:1" (output 1), "^node" (control edge)
  std::map<std::string, TfjsAttr, std::less<>> attr;

  const TfjsAttr* find(std::string_view key) const;
};

struct TfjsWeight {
  bool is_int = false;  // int32 values in `ints`, else float32 values in `floats`
  std::vector<std::int64_t> shape;
  std::vector<float> floats;
  std::vector<std::int32_t> ints;
};

struct TfjsModel {
  std::filesystem::path file;  // model.json, for error messages
  std::vector<TfjsNode> nodes;
  std::unordered_map<std::string, TfjsWeight> weights;
  int producer = 808;  // GraphDef versions.producer
  // Nodes bypassed when the model was read (below) -> the node their consumers read instead.
  std::unordered_map<std::string, std::string> bypassed;
};

// The graph is read as it is, except that the batch-of-one no-ops the TF.js converter leaves at
// the input of single-pose MoveNet (Unpack(axis 0, num 1) or Squeeze(axis 0) followed by
// ExpandDims(axis 0): exact identities) are bypassed: their consumers read the input directly.
// Throws ModelError for an unreadable file, JSON that is not a TF.js graph model, weight files
// shorter or longer than their manifest, or weights of a type it does not read.
TfjsModel read_tfjs_model(const std::filesystem::path& model_json);
// The same from memory: model.json's text and its weight files concatenated in manifest order;
// `name` is what errors call it.
TfjsModel parse_tfjs_model(std::string_view model_json, std::string_view weights,
                           const std::filesystem::path& name);

// The model for an NHWC image input of height × width instead of the size its one Placeholder
// declares, for a fully convolutional graph: the Placeholder's shape is changed and every
// ResizeBilinear whose output size is a constant (Keras' UpSampling2D, frozen at the declared
// size by the converter) gets that size scaled as the input's. Throws ModelError when the model
// has not exactly one 4-D Placeholder or a scaled size is not a whole number (height and width
// must keep the graph's strides: for MB3-CenterNet, multiples of 32).
TfjsModel tfjs_with_input_size(TfjsModel model, std::int64_t height, std::int64_t width);

// The outputs and every node they depend on, up to `input_node` (fed from outside: its own inputs
// are not needed; empty: none). Throws ModelError for a name the graph lacks.
std::set<std::string> tfjs_ancestors(const TfjsModel& model, std::span<const std::string> outputs,
                                     std::string_view input_node = {});

// The node that stands for `name` after the bypasses (`name` itself when it was not bypassed): an
// input node given by name is fed there.
std::string tfjs_resolve(const TfjsModel& model, const std::string& name);

// "x:1" -> "x", "^x" -> "x".
std::string tfjs_base_name(std::string_view input);
// "x:1" -> 1, "x" -> 0.
int tfjs_output_index(std::string_view input);

// The fused_ops list of _FusedConv2D / FusedDepthwiseConv2dNative ("BiasAdd", "Relu6", ...).
std::vector<std::string> tfjs_fused_ops(const TfjsNode& node);

// IEEE 754 binary16 (as stored in TF.js float16-quantised weights) to float.
float half_to_float(std::uint16_t half);

}  // namespace mocap::detect
