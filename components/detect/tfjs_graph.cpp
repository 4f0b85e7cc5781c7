#include "detect/tfjs_graph.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "detect/protobuf_writer.hpp"

namespace mocap::detect {
namespace {

using nlohmann::json;

// Field numbers of the TensorFlow protos (tensorflow/core/framework/*.proto; OpenCV keeps
// wire-compatible copies in modules/dnn/src/tensorflow/).
namespace pb {
constexpr int kGraphNode = 1, kGraphVersions = 4, kVersionsProducer = 1;
constexpr int kNodeName = 1, kNodeOp = 2, kNodeInput = 3, kNodeAttr = 5;
constexpr int kMapKey = 1, kMapValue = 2;
constexpr int kAttrList = 1, kAttrS = 2, kAttrI = 3, kAttrF = 4, kAttrB = 5, kAttrType = 6,
              kAttrShape = 7, kAttrTensor = 8;
constexpr int kListS = 2, kListI = 3, kListF = 4, kListType = 6;
constexpr int kTensorDtype = 1, kTensorShape = 2, kTensorContent = 4, kTensorIntVal = 7;
constexpr int kShapeDim = 2, kShapeUnknownRank = 3, kDimSize = 1;
constexpr int kDtFloat = 1, kDtInt32 = 3;
}  // namespace pb

// The ops this loader passes to OpenCV (checked with OpenCV 4.6 on MoveNet MultiPose and
// single-pose and on MB3-CenterNet's CNN); Shape and StridedSlice only occur inside the upsampling
// chains OpenCV's importer folds into Resize. Mean is a spatial mean (squeeze-and-excite),
// ConcatV2 joins channels.
const std::set<std::string, std::less<>> kPassThroughOps = {
    "Const",   "Placeholder", "Identity", "Conv2D",       "DepthwiseConv2dNative",
    "BiasAdd", "Relu",        "Relu6",    "Add",          "AddV2",
    "Sub",     "Mul",         "Shape",    "StridedSlice", "ResizeBilinear",
    "Sigmoid", "Mean",        "ConcatV2"};
const std::set<std::string, std::less<>> kSplitOps = {"_FusedConv2D", "FusedDepthwiseConv2dNative"};

struct Node {
  std::string name;
  std::string op;
  std::vector<std::string> inputs;
  json attr;
};

struct Weight {
  int dtype = pb::kDtFloat;
  std::vector<std::int64_t> shape;
  std::string content;  // little-endian float32 or int32 values, as TensorProto.tensor_content
};

// Errors that already name the model file; anything else thrown inside gets the name added.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw ModelError("TF.js model " + file.string() + ": " + what);
}

std::string read_file(const std::filesystem::path& path, const std::filesystem::path& model) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(model, "cannot read " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string base64_decode(std::string_view text) {
  static constexpr std::string_view kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    const auto pos = kAlphabet.find(c);
    if (pos == std::string_view::npos) continue;  // '=' padding
    bits = (bits << 6) | static_cast<std::uint32_t>(pos);
    count += 6;
    if (count >= 8) {
      count -= 8;
      out.push_back(static_cast<char>((bits >> count) & 0xff));
    }
  }
  return out;
}

std::int64_t to_int64(const json& v) {
  return v.is_string() ? std::stoll(v.get<std::string>()) : v.get<std::int64_t>();
}

int dtype_code(const std::string& name) {
  static const std::map<std::string, int, std::less<>> kCodes = {
      {"DT_FLOAT", 1}, {"DT_DOUBLE", 2}, {"DT_INT32", 3}, {"DT_UINT8", 4}, {"DT_INT16", 5},
      {"DT_INT8", 6},  {"DT_STRING", 7}, {"DT_INT64", 9}, {"DT_BOOL", 10}, {"DT_HALF", 19}};
  const auto it = kCodes.find(name);
  if (it == kCodes.end()) throw std::runtime_error("unknown TensorFlow data type " + name);
  return it->second;
}

// Input names may carry an output index ("x:1") or mark a control edge ("^x").
std::string base_name(std::string_view input) {
  if (!input.empty() && input.front() == '^') input.remove_prefix(1);
  const auto colon = input.find(':');
  return std::string(input.substr(0, colon));
}

ProtoMessage shape_proto(const json& shape) {
  ProtoMessage m;
  if (shape.value("unknownRank", false)) m.add_varint(pb::kShapeUnknownRank, 1);
  for (const json& dim : shape.value("dim", json::array())) {
    ProtoMessage d;
    d.add_int64(pb::kDimSize, to_int64(dim.value("size", json("0"))));
    m.add_message(pb::kShapeDim, d);
  }
  return m;
}

ProtoMessage list_proto(const json& list) {
  ProtoMessage m;
  for (const json& s : list.value("s", json::array()))
    m.add_bytes(pb::kListS, base64_decode(s.get<std::string>()));
  std::vector<std::int64_t> ints, types;
  std::vector<float> floats;
  for (const json& i : list.value("i", json::array())) ints.push_back(to_int64(i));
  for (const json& f : list.value("f", json::array())) floats.push_back(f.get<float>());
  for (const json& t : list.value("type", json::array()))
    types.push_back(dtype_code(t.get<std::string>()));
  if (!ints.empty()) m.add_packed_int64(pb::kListI, ints);
  if (!floats.empty()) m.add_packed_float(pb::kListF, floats);
  if (!types.empty()) m.add_packed_int64(pb::kListType, types);
  return m;
}

// protobuf-JSON AttrValue (exactly one of its fields set) to the binary message.
ProtoMessage attr_proto(const std::string& key, const json& value) {
  ProtoMessage m;
  if (value.contains("list")) {
    m.add_message(pb::kAttrList, list_proto(value["list"]));
  } else if (value.contains("s")) {
    m.add_bytes(pb::kAttrS, base64_decode(value["s"].get<std::string>()));
  } else if (value.contains("i")) {
    m.add_int64(pb::kAttrI, to_int64(value["i"]));
  } else if (value.contains("f")) {
    m.add_float(pb::kAttrF, value["f"].get<float>());
  } else if (value.contains("b")) {
    m.add_varint(pb::kAttrB, value["b"].get<bool>() ? 1 : 0);
  } else if (value.contains("type")) {
    m.add_varint(pb::kAttrType, static_cast<std::uint64_t>(dtype_code(value["type"])));
  } else if (value.contains("shape")) {
    m.add_message(pb::kAttrShape, shape_proto(value["shape"]));
  } else {
    throw std::runtime_error("attribute '" + key + "' has a form the loader does not convert");
  }
  return m;
}

void add_attr(ProtoMessage& node, const std::string& key, const ProtoMessage& value) {
  ProtoMessage entry;
  entry.add_bytes(pb::kMapKey, key);
  entry.add_message(pb::kMapValue, value);
  node.add_message(pb::kNodeAttr, entry);
}

// Copies the named attributes that are present (all of them when `keys` is empty).
void copy_attrs(ProtoMessage& node, const json& attr, std::span<const std::string> keys = {}) {
  for (const auto& [key, value] : attr.items()) {
    if (!keys.empty() && std::find(keys.begin(), keys.end(), key) == keys.end()) continue;
    add_attr(node, key, attr_proto(key, value));
  }
}

ProtoMessage node_proto(const std::string& name, const std::string& op,
                        std::span<const std::string> inputs) {
  ProtoMessage m;
  m.add_bytes(pb::kNodeName, name);
  m.add_bytes(pb::kNodeOp, op);
  for (const std::string& input : inputs) m.add_bytes(pb::kNodeInput, input);
  return m;
}

// ---- weights ---------------------------------------------------------------------------------

std::size_t element_count(const std::vector<std::int64_t>& shape) {
  std::size_t n = 1;
  for (const std::int64_t d : shape) n *= static_cast<std::size_t>(d);
  return n;
}

// Reads one manifest entry from `data` at `offset`, advancing it.
Weight read_weight(const json& spec, std::string_view data, std::size_t& offset,
                   const std::filesystem::path& model) {
  Weight w;
  w.shape = spec.at("shape").get<std::vector<std::int64_t>>();
  const std::size_t n = element_count(w.shape);
  const std::string dtype = spec.at("dtype");
  const std::string stored =
      spec.contains("quantization") ? spec["quantization"].at("dtype").get<std::string>() : dtype;
  const std::size_t bytes = n * (stored == "float16" ? 2 : 4);
  if (offset + bytes > data.size()) fail(model, "weight data shorter than its manifest");
  const char* src = data.data() + offset;
  offset += bytes;
  if (dtype == "int32" && stored == "int32") {
    w.dtype = pb::kDtInt32;
    w.content.assign(src, bytes);
  } else if (dtype == "float32" && stored == "float32") {
    w.content.assign(src, bytes);
  } else if (dtype == "float32" && stored == "float16") {
    w.content.resize(n * sizeof(float));
    for (std::size_t i = 0; i < n; ++i) {
      std::uint16_t h;
      std::memcpy(&h, src + 2 * i, 2);
      const float f = half_to_float(h);
      std::memcpy(w.content.data() + i * sizeof(float), &f, sizeof f);
    }
  } else {
    fail(model, "weight '" + spec.at("name").get<std::string>() + "' is " + dtype + " stored as " +
                    stored + ", which the loader does not read");
  }
  return w;
}

std::unordered_map<std::string, Weight> read_weights(const json& manifest,
                                                     const std::filesystem::path& model) {
  std::unordered_map<std::string, Weight> weights;
  for (const json& group : manifest) {
    std::string data;
    for (const json& path : group.at("paths"))
      data += read_file(model.parent_path() / path.get<std::string>(), model);
    std::size_t offset = 0;
    for (const json& spec : group.at("weights"))
      weights[spec.at("name")] = read_weight(spec, data, offset, model);
    if (offset != data.size()) fail(model, "weight files longer than their manifest");
  }
  return weights;
}

ProtoMessage const_proto(const std::string& name, const Weight& w) {
  ProtoMessage tensor, shape;
  tensor.add_varint(pb::kTensorDtype, static_cast<std::uint64_t>(w.dtype));
  for (const std::int64_t d : w.shape) {
    ProtoMessage dim;
    dim.add_int64(pb::kDimSize, d);
    shape.add_message(pb::kShapeDim, dim);
  }
  tensor.add_message(pb::kTensorShape, shape);
  if (w.dtype == pb::kDtInt32 && w.content.size() == sizeof(std::int32_t)) {
    // A scalar int32 as int_val: OpenCV reads a ConcatV2 axis from there only.
    std::int32_t value;
    std::memcpy(&value, w.content.data(), sizeof value);
    tensor.add_packed_int64(pb::kTensorIntVal, std::vector<std::int64_t>{value});
  } else {
    tensor.add_bytes(pb::kTensorContent, w.content);
  }
  ProtoMessage node = node_proto(name, "Const", {});
  ProtoMessage dtype, value;
  dtype.add_varint(pb::kAttrType, static_cast<std::uint64_t>(w.dtype));
  value.add_message(pb::kAttrTensor, tensor);
  add_attr(node, "dtype", dtype);
  add_attr(node, "value", value);
  return node;
}

// ---- graph -----------------------------------------------------------------------------------

std::vector<Node> read_nodes(const json& topology) {
  std::vector<Node> nodes;
  for (const json& n : topology.at("node")) {
    nodes.push_back({n.at("name"), n.at("op"), n.value("input", std::vector<std::string>{}),
                     n.value("attr", json::object())});
  }
  return nodes;
}

// Marks the outputs and everything they depend on.
std::set<std::string> ancestors(const std::vector<Node>& nodes,
                                std::span<const std::string> outputs, std::string_view input_node,
                                const std::filesystem::path& model) {
  std::unordered_map<std::string, const Node*> by_name;
  for (const Node& n : nodes) by_name[n.name] = &n;
  std::set<std::string> keep;
  std::vector<std::string> todo(outputs.begin(), outputs.end());
  while (!todo.empty()) {
    const std::string name = todo.back();
    todo.pop_back();
    if (!keep.insert(name).second) continue;
    const auto it = by_name.find(name);
    if (it == by_name.end()) fail(model, "the graph has no node '" + name + "'");
    if (name == input_node) continue;  // fed from outside: its own inputs are not needed
    for (const std::string& input : it->second->inputs) todo.push_back(base_name(input));
  }
  return keep;
}

std::vector<std::string> fused_ops(const Node& n) {
  std::vector<std::string> ops;
  if (!n.attr.contains("fused_ops")) return ops;
  for (const json& s : n.attr["fused_ops"]["list"].value("s", json::array()))
    ops.push_back(base64_decode(s.get<std::string>()));
  return ops;
}

// Empty when the node can be converted, else why not.
std::string unsupported_reason(const Node& n, const std::map<std::string, const Node*>& kept,
                               std::string_view input_node) {
  if (n.name == input_node || kPassThroughOps.contains(n.op)) return {};
  if (kSplitOps.contains(n.op)) {
    const auto ops = fused_ops(n);
    const bool ok =
        (ops.size() == 1 || (ops.size() == 2 && (ops[1] == "Relu" || ops[1] == "Relu6"))) &&
        ops[0] == "BiasAdd" && n.inputs.size() == 3;
    if (ok) return {};
    std::string list;
    for (const auto& op : ops) list += (list.empty() ? "" : ",") + op;
    return n.op + " fusing [" + list + "]";
  }
  if (n.op == "Cast" && n.inputs.size() == 1) {
    const auto src = kept.find(base_name(n.inputs[0]));
    if (src != kept.end() && src->second->op == "Placeholder") return {};
    return "Cast (only from the input placeholder)";
  }
  return n.op;
}

void check_supported(const std::vector<Node>& nodes, const std::set<std::string>& keep,
                     std::string_view input_node, const std::filesystem::path& model) {
  std::map<std::string, const Node*> kept;
  for (const Node& n : nodes)
    if (keep.contains(n.name)) kept[n.name] = &n;
  std::map<std::string, std::string> refused;  // reason -> first node
  for (const auto& [name, node] : kept) {
    const std::string reason = unsupported_reason(*node, kept, input_node);
    if (!reason.empty()) refused.try_emplace(reason, name);
  }
  if (refused.empty()) return;
  std::string what = "unsupported operation(s) on the way to the requested outputs:";
  for (const auto& [reason, name] : refused) what += " " + reason + " (node '" + name + "');";
  fail(model, what +
                  " the cv::dnn loader converts only the operations of the CNNs of MoveNet and "
                  "MB3-CenterNet");
}

// Conv2D/DepthwiseConv2dNative -> BiasAdd [-> Relu|Relu6]; the last node keeps the fused node's
// name so that its consumers still find it.
void emit_split(ProtoMessage& graph, const Node& n, const std::vector<std::string>& inputs) {
  static const std::vector<std::string> kConvAttrs = {"T", "strides", "padding", "data_format",
                                                      "dilations"};
  static const std::vector<std::string> kTypeAttrs = {"T", "data_format"};
  const auto ops = fused_ops(n);
  const bool has_activation = ops.size() == 2;
  const std::string conv = fused_conv_layer_name(n.name);
  const std::string bias = has_activation ? n.name + "/bias" : n.name;
  const std::string conv_op = n.op == "_FusedConv2D" ? "Conv2D" : "DepthwiseConv2dNative";

  ProtoMessage c = node_proto(conv, conv_op, std::vector<std::string>{inputs[0], inputs[1]});
  copy_attrs(c, n.attr, kConvAttrs);
  graph.add_message(pb::kGraphNode, c);
  ProtoMessage b = node_proto(bias, "BiasAdd", std::vector<std::string>{conv, inputs[2]});
  copy_attrs(b, n.attr, kTypeAttrs);
  graph.add_message(pb::kGraphNode, b);
  if (has_activation) {
    ProtoMessage a = node_proto(n.name, ops[1], std::vector<std::string>{bias});
    copy_attrs(a, n.attr, std::vector<std::string>{"T"});
    graph.add_message(pb::kGraphNode, a);
  }
}

void emit_placeholder(ProtoMessage& graph, const Node& n, bool fed_as_float) {
  ProtoMessage p = node_proto(n.name, n.op, {});
  if (fed_as_float) {
    ProtoMessage dtype;
    dtype.add_varint(pb::kAttrType, pb::kDtFloat);
    add_attr(p, "dtype", dtype);
    if (n.attr.contains("shape")) add_attr(p, "shape", attr_proto("shape", n.attr["shape"]));
  } else {
    copy_attrs(p, n.attr);
  }
  graph.add_message(pb::kGraphNode, p);
}

}  // namespace

float half_to_float(std::uint16_t half) {
  const std::uint32_t sign = (half >> 15) & 1u;
  const int exponent = (half >> 10) & 0x1f;
  const std::uint32_t mantissa = half & 0x3ffu;
  float magnitude;
  if (exponent == 0) {
    magnitude = std::ldexp(static_cast<float>(mantissa), -24);  // zero or subnormal
  } else if (exponent == 31) {
    magnitude = mantissa ? std::nanf("") : INFINITY;
  } else {
    magnitude = std::ldexp(static_cast<float>(mantissa | 0x400u), exponent - 25);
  }
  return sign ? -magnitude : magnitude;
}

std::string fused_conv_layer_name(std::string_view fused_node) {
  return std::string(fused_node) + "/conv";
}

std::string tfjs_to_graphdef(const std::filesystem::path& model_json,
                             std::span<const std::string> outputs, std::string_view input_node) {
  json model;
  try {
    model = json::parse(read_file(model_json, model_json));
  } catch (const json::exception& e) {
    fail(model_json, std::string("not valid JSON: ") + e.what());
  }
  if (!model.contains("modelTopology") || !model.contains("weightsManifest"))
    fail(model_json, "not a TF.js graph model (no modelTopology or weightsManifest)");
  try {
    const std::vector<Node> nodes = read_nodes(model["modelTopology"]);
    const std::set<std::string> keep = ancestors(nodes, outputs, input_node, model_json);
    check_supported(nodes, keep, input_node, model_json);
    const auto weights = read_weights(model["weightsManifest"], model_json);

    // A Cast from the input placeholder disappears: its consumers read the placeholder, fed float.
    std::unordered_map<std::string, std::string> renamed;
    std::set<std::string> float_inputs;
    for (const Node& n : nodes) {
      if (keep.contains(n.name) && n.op == "Cast") {
        renamed[n.name] = base_name(n.inputs[0]);
        float_inputs.insert(base_name(n.inputs[0]));
      }
    }
    ProtoMessage graph;
    for (const Node& n : nodes) {
      if (!keep.contains(n.name) || n.op == "Cast") continue;
      std::vector<std::string> inputs;
      for (const std::string& in : n.inputs) {
        const auto it = renamed.find(in);
        inputs.push_back(it == renamed.end() ? in : it->second);
      }
      if (n.name == input_node) {
        // Shaped like the graph's own input (any batch), so that OpenCV knows the layout is NHWC.
        ProtoMessage p = node_proto(n.name, "Placeholder", {});
        ProtoMessage dtype;
        dtype.add_varint(pb::kAttrType, pb::kDtFloat);
        add_attr(p, "dtype", dtype);
        for (const Node& original : nodes) {
          if (original.op != "Placeholder" || !original.attr.contains("shape")) continue;
          json shape = original.attr["shape"];
          if (shape.contains("shape") && shape["shape"].contains("dim") &&
              !shape["shape"]["dim"].empty())
            shape["shape"]["dim"][0]["size"] = "-1";
          add_attr(p, "shape", attr_proto("shape", shape));
          break;
        }
        graph.add_message(pb::kGraphNode, p);
      } else if (n.op == "Const") {
        const auto w = weights.find(n.name);
        if (w == weights.end()) fail(model_json, "Const '" + n.name + "' has no weights");
        graph.add_message(pb::kGraphNode, const_proto(n.name, w->second));
      } else if (n.op == "Placeholder") {
        emit_placeholder(graph, n, float_inputs.contains(n.name));
      } else if (kSplitOps.contains(n.op)) {
        emit_split(graph, n, inputs);
      } else {
        ProtoMessage p = node_proto(n.name, n.op, inputs);
        copy_attrs(p, n.attr);
        graph.add_message(pb::kGraphNode, p);
      }
    }
    ProtoMessage versions;
    versions.add_varint(
        pb::kVersionsProducer,
        model["modelTopology"].value("versions", json::object()).value("producer", 808));
    graph.add_message(pb::kGraphVersions, versions);
    return graph.bytes();
  } catch (const ModelError&) {
    throw;
  } catch (const std::exception& e) {  // JSON structure, numbers, data types
    fail(model_json, e.what());
  }
}

}  // namespace mocap::detect
