#include "detect/tfjs_graph.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "detect/protobuf_writer.hpp"

namespace mocap::detect {
namespace {

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
// single-pose and MB3-CenterNet; NanoDet's NCHW transposes are beyond OpenCV's TF importer); Shape
// and StridedSlice only occur inside the upsampling chains OpenCV's importer folds into Resize;
// Mean is a spatial mean (squeeze-and-excite); Pad (zero padding before a strided convolution)
// and MaxPool (2 x 2, VALID) are BlazePose's, checked by its golden test.
const std::set<std::string, std::less<>> kPassThroughOps = {
    "Const",   "Placeholder", "Identity", "Conv2D",       "DepthwiseConv2dNative",
    "BiasAdd", "Relu",        "Relu6",    "Add",          "AddV2",
    "Sub",     "Mul",         "Shape",    "StridedSlice", "ResizeBilinear",
    "Sigmoid", "Mean",        "ConcatV2", "Pad",          "MaxPool"};
const std::set<std::string, std::less<>> kSplitOps = {"_FusedConv2D", "FusedDepthwiseConv2dNative"};

ProtoMessage attr_proto(const TfjsAttr& a) {
  ProtoMessage m;
  switch (a.kind) {
    case TfjsAttr::Kind::list: {
      ProtoMessage list;
      for (const std::string& s : a.list_s) list.add_bytes(pb::kListS, s);
      if (!a.list_i.empty()) list.add_packed_int64(pb::kListI, a.list_i);
      if (!a.list_f.empty()) list.add_packed_float(pb::kListF, a.list_f);
      if (!a.list_type.empty()) {
        const std::vector<std::int64_t> types(a.list_type.begin(), a.list_type.end());
        list.add_packed_int64(pb::kListType, types);
      }
      m.add_message(pb::kAttrList, list);
      break;
    }
    case TfjsAttr::Kind::s:
      m.add_bytes(pb::kAttrS, a.s);
      break;
    case TfjsAttr::Kind::i:
      m.add_int64(pb::kAttrI, a.i);
      break;
    case TfjsAttr::Kind::f:
      m.add_float(pb::kAttrF, a.f);
      break;
    case TfjsAttr::Kind::b:
      m.add_varint(pb::kAttrB, a.b ? 1 : 0);
      break;
    case TfjsAttr::Kind::type:
      m.add_varint(pb::kAttrType, static_cast<std::uint64_t>(a.type));
      break;
    case TfjsAttr::Kind::shape: {
      ProtoMessage shape;
      if (a.unknown_rank) shape.add_varint(pb::kShapeUnknownRank, 1);
      for (const std::int64_t size : a.shape) {
        ProtoMessage d;
        d.add_int64(pb::kDimSize, size);
        shape.add_message(pb::kShapeDim, d);
      }
      m.add_message(pb::kAttrShape, shape);
      break;
    }
    case TfjsAttr::Kind::tensor:
      throw std::runtime_error("a tensor-valued attribute outside a Const node");
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
void copy_attrs(ProtoMessage& node, const TfjsNode& n, std::span<const std::string> keys = {}) {
  for (const auto& [key, value] : n.attr) {
    if (!keys.empty() && std::find(keys.begin(), keys.end(), key) == keys.end()) continue;
    add_attr(node, key, attr_proto(value));
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

ProtoMessage const_proto(const std::string& name, const TfjsWeight& w) {
  ProtoMessage tensor, shape;
  const int dtype = w.is_int ? pb::kDtInt32 : pb::kDtFloat;
  tensor.add_varint(pb::kTensorDtype, static_cast<std::uint64_t>(dtype));
  for (const std::int64_t d : w.shape) {
    ProtoMessage dim;
    dim.add_int64(pb::kDimSize, d);
    shape.add_message(pb::kShapeDim, dim);
  }
  tensor.add_message(pb::kTensorShape, shape);
  if (w.is_int && w.ints.size() == 1) {
    // A scalar int32 as int_val: OpenCV reads a ConcatV2 / Split axis from there only.
    tensor.add_packed_int64(pb::kTensorIntVal, std::vector<std::int64_t>{w.ints[0]});
  } else {
    // Little-endian float32 / int32 values, as TensorProto.tensor_content.
    const std::string_view content =
        w.is_int
            ? std::string_view(reinterpret_cast<const char*>(w.ints.data()), w.ints.size() * 4)
            : std::string_view(reinterpret_cast<const char*>(w.floats.data()), w.floats.size() * 4);
    tensor.add_bytes(pb::kTensorContent, content);
  }
  ProtoMessage node = node_proto(name, "Const", {});
  ProtoMessage dtype_attr, value;
  dtype_attr.add_varint(pb::kAttrType, static_cast<std::uint64_t>(dtype));
  value.add_message(pb::kAttrTensor, tensor);
  add_attr(node, "dtype", dtype_attr);
  add_attr(node, "value", value);
  return node;
}

// Empty when the node can be converted, else why not.
std::string unsupported_reason(const TfjsNode& n,
                               const std::map<std::string, const TfjsNode*>& kept) {
  if (kPassThroughOps.contains(n.op)) return {};
  if (kSplitOps.contains(n.op)) {
    const auto ops = tfjs_fused_ops(n);
    const bool ok =
        (ops.size() == 1 || (ops.size() == 2 && (ops[1] == "Relu" || ops[1] == "Relu6"))) &&
        ops[0] == "BiasAdd" && n.inputs.size() == 3;
    if (ok) return {};
    std::string list;
    for (const auto& op : ops) list += (list.empty() ? "" : ",") + op;
    return n.op + " fusing [" + list + "]";
  }
  if (n.op == "Cast" && n.inputs.size() == 1) {
    const auto src = kept.find(tfjs_base_name(n.inputs[0]));
    if (src != kept.end() && src->second->op == "Placeholder") return {};
    return "Cast (only from the input placeholder)";
  }
  return n.op;
}

void check_supported(const TfjsModel& model, const std::set<std::string>& keep,
                     std::string_view input_node) {
  std::map<std::string, const TfjsNode*> kept;
  for (const TfjsNode& n : model.nodes)
    if (keep.contains(n.name)) kept[n.name] = &n;
  std::map<std::string, std::string> refused;  // reason -> first node
  for (const auto& [name, node] : kept) {
    if (name == input_node) continue;
    const std::string reason = unsupported_reason(*node, kept);
    if (!reason.empty()) refused.try_emplace(reason, name);
  }
  if (refused.empty()) return;
  std::string what = "unsupported operation(s) on the way to the requested outputs:";
  for (const auto& [reason, name] : refused) what += " " + reason + " (node '" + name + "');";
  fail_model(model.file,
             what +
                 " the cv::dnn loader converts only the operations of the CNNs of MoveNet and "
                 "MB3-CenterNet (the XNNPACK runtime runs more)");
}

// Conv2D/DepthwiseConv2dNative -> BiasAdd [-> Relu|Relu6]; the last node keeps the fused node's
// name so that its consumers still find it.
void emit_split(ProtoMessage& graph, const TfjsNode& n, const std::vector<std::string>& inputs) {
  static const std::vector<std::string> kConvAttrs = {"T", "strides", "padding", "data_format",
                                                      "dilations"};
  static const std::vector<std::string> kTypeAttrs = {"T", "data_format"};
  const auto ops = tfjs_fused_ops(n);
  const bool has_activation = ops.size() == 2;
  const std::string conv = fused_conv_layer_name(n.name);
  const std::string bias = has_activation ? n.name + "/bias" : n.name;
  const std::string conv_op = n.op == "_FusedConv2D" ? "Conv2D" : "DepthwiseConv2dNative";

  ProtoMessage c = node_proto(conv, conv_op, std::vector<std::string>{inputs[0], inputs[1]});
  copy_attrs(c, n, kConvAttrs);
  graph.add_message(pb::kGraphNode, c);
  ProtoMessage b = node_proto(bias, "BiasAdd", std::vector<std::string>{conv, inputs[2]});
  copy_attrs(b, n, kTypeAttrs);
  graph.add_message(pb::kGraphNode, b);
  if (has_activation) {
    ProtoMessage a = node_proto(n.name, ops[1], std::vector<std::string>{bias});
    copy_attrs(a, n, std::vector<std::string>{"T"});
    graph.add_message(pb::kGraphNode, a);
  }
}

void emit_placeholder(ProtoMessage& graph, const TfjsNode& n, bool fed_as_float) {
  ProtoMessage p = node_proto(n.name, "Placeholder", {});
  if (fed_as_float) {
    ProtoMessage dtype;
    dtype.add_varint(pb::kAttrType, pb::kDtFloat);
    add_attr(p, "dtype", dtype);
    if (const TfjsAttr* shape = n.find("shape")) add_attr(p, "shape", attr_proto(*shape));
  } else {
    copy_attrs(p, n);
  }
  graph.add_message(pb::kGraphNode, p);
}

std::string write_graphdef(const TfjsModel& model, std::span<const std::string> outputs,
                           std::string_view requested_input) {
  const std::string input_node = tfjs_resolve(model, std::string(requested_input));
  const std::set<std::string> keep = tfjs_ancestors(model, outputs, input_node);
  check_supported(model, keep, input_node);

  // A Cast from the input placeholder disappears: its consumers read the placeholder, fed float.
  std::unordered_map<std::string, std::string> renamed;
  std::set<std::string> float_inputs;
  for (const TfjsNode& n : model.nodes) {
    if (keep.contains(n.name) && n.op == "Cast" && n.name != input_node) {
      renamed[n.name] = tfjs_base_name(n.inputs[0]);
      float_inputs.insert(tfjs_base_name(n.inputs[0]));
    }
  }
  ProtoMessage graph;
  for (const TfjsNode& n : model.nodes) {
    if (!keep.contains(n.name) || (n.op == "Cast" && n.name != input_node)) continue;
    if (n.name == input_node) {  // fed from outside: a float placeholder of that name
      emit_placeholder(graph, n, true);
      continue;
    }
    std::vector<std::string> inputs;
    for (const std::string& in : n.inputs) {
      const auto it = renamed.find(in);
      inputs.push_back(it == renamed.end() ? in : it->second);
    }
    if (n.op == "Const") {
      const auto w = model.weights.find(n.name);
      if (w == model.weights.end()) fail_model(model.file, "Const '" + n.name + "' has no weights");
      graph.add_message(pb::kGraphNode, const_proto(n.name, w->second));
    } else if (n.op == "Placeholder") {
      emit_placeholder(graph, n, float_inputs.contains(n.name));
    } else if (kSplitOps.contains(n.op)) {
      if (n.inputs.size() != 3) fail_model(model.file, "node '" + n.name + "' needs 3 inputs");
      emit_split(graph, n, inputs);
    } else {
      ProtoMessage p = node_proto(n.name, n.op, inputs);
      copy_attrs(p, n);
      graph.add_message(pb::kGraphNode, p);
    }
  }
  ProtoMessage versions;
  versions.add_varint(pb::kVersionsProducer, static_cast<std::uint64_t>(model.producer));
  graph.add_message(pb::kGraphVersions, versions);
  return graph.bytes();
}

}  // namespace

std::string fused_conv_layer_name(std::string_view fused_node) {
  return std::string(fused_node) + "/conv";
}

std::string tfjs_to_graphdef(const std::filesystem::path& model_json,
                             std::span<const std::string> outputs, std::string_view input_node) {
  return tfjs_to_graphdef(read_tfjs_model(model_json), outputs, input_node);
}

std::string tfjs_to_graphdef(const TfjsModel& model, std::span<const std::string> outputs,
                             std::string_view input_node) {
  try {
    return write_graphdef(model, outputs, input_node);
  } catch (const ModelError&) {
    throw;
  } catch (const std::exception& e) {
    fail_model(model.file, e.what());
  }
}

}  // namespace mocap::detect
