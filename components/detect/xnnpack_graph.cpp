#include "detect/xnnpack_graph.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <variant>

namespace mocap::detect::xnn {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kLargestIndex = 1 << 30;  // sizes, indices and axes beyond are garbage
constexpr std::size_t kLargestTensor = 1
                                       << 28;  // values (1 GiB): a network needing more is refused

// A value known when the subgraph is built (weights, shape arithmetic), folded on the host.
// Integers and float32 are both exact in a double.
struct Const {
  std::vector<std::int64_t> shape;
  std::vector<double> v;
  bool is_int = false;
};

// A tensor computed by the subgraph.
struct Tensor {
  std::uint32_t id = XNN_INVALID_VALUE_ID;
  Layout layout;
};

using Value = std::variant<Const, Tensor>;

// What the builder cannot express (a data transpose, a split of a non-channel axis, ...).
class Unsupported : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
// A convolution (or another NHWC op) whose input lies transposed: the graph expects an NCHW
// input fed as it is. The builder then retries with the input fed as NHWC.
class NeedsTranspose : public Unsupported {
 public:
  using Unsupported::Unsupported;
};
// An input size the graph does not accept (shapes that do not broadcast, a kernel larger than
// its input, ...).
class ShapeMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::size_t product(std::span<const std::int64_t> shape) {
  std::size_t n = 1;
  for (const std::int64_t d : shape) n *= static_cast<std::size_t>(std::max<std::int64_t>(d, 0));
  return n;
}

std::string shape_text(std::span<const std::int64_t> shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? "," : "") + std::to_string(shape[i]);
  return s + "]";
}

std::vector<std::size_t> row_major_strides(std::span<const std::int64_t> shape) {
  std::vector<std::size_t> strides(shape.size(), 1);
  for (std::size_t i = shape.size(); i-- > 1;)
    strides[i - 1] = strides[i] * static_cast<std::size_t>(shape[i]);
  return strides;
}

// Calls f(flat index, multi-index) for every element of `shape`, row-major.
void for_each_index(std::span<const std::int64_t> shape,
                    const std::function<void(std::size_t, std::span<const std::int64_t>)>& f) {
  const std::size_t n = product(shape);
  std::vector<std::int64_t> index(shape.size(), 0);
  for (std::size_t flat = 0; flat < n; ++flat) {
    f(flat, index);
    for (std::size_t a = shape.size(); a-- > 0;) {
      if (++index[a] < shape[a]) break;
      index[a] = 0;
    }
  }
}

// Numpy broadcasting of two shapes.
std::vector<std::int64_t> broadcast_shape(std::span<const std::int64_t> a,
                                          std::span<const std::int64_t> b) {
  const std::size_t rank = std::max(a.size(), b.size());
  std::vector<std::int64_t> out(rank);
  for (std::size_t i = 0; i < rank; ++i) {
    const std::int64_t da = i + a.size() >= rank ? a[i + a.size() - rank] : 1;
    const std::int64_t db = i + b.size() >= rank ? b[i + b.size() - rank] : 1;
    if (da != db && da != 1 && db != 1)
      throw ShapeMismatch("shapes " + shape_text(a) + " and " + shape_text(b) +
                          " do not broadcast");
    out[i] = std::max(da, db);
  }
  return out;
}

// Flat index into `shape` (right-aligned to `index`, broadcast along its unit axes).
std::size_t broadcast_offset(std::span<const std::int64_t> shape,
                             std::span<const std::int64_t> index) {
  std::size_t offset = 0;
  const std::size_t skip = index.size() - shape.size();
  for (std::size_t a = 0; a < shape.size(); ++a)
    offset = offset * static_cast<std::size_t>(shape[a]) +
             static_cast<std::size_t>(shape[a] == 1 ? 0 : index[a + skip]);
  return offset;
}

std::int64_t normalise_axis(std::int64_t axis, std::size_t rank) {
  const auto r = static_cast<std::int64_t>(rank);
  if (axis < -r || axis >= std::max<std::int64_t>(r, 1))
    throw ShapeMismatch("axis " + std::to_string(axis) + " outside a rank-" + std::to_string(r) +
                        " tensor");
  return axis < 0 ? axis + r : axis;
}

Layout identity_layout(std::span<const std::int64_t> shape) {
  Layout l;
  for (std::size_t a = 0; a < shape.size(); ++a) {
    l.physical.push_back(static_cast<std::size_t>(shape[a]));
    l.groups.push_back({static_cast<int>(a)});
  }
  return l;
}

// The physical axes of a group that are not of size one.
std::vector<int> non_unit(const Layout& l, const std::vector<int>& group) {
  std::vector<int> out;
  for (const int p : group)
    if (l.physical[static_cast<std::size_t>(p)] != 1) out.push_back(p);
  return out;
}

// True when the logical row-major order is the physical memory order.
bool is_plain(const Layout& l) {
  int last = -1;
  for (const auto& group : l.groups)
    for (const int p : non_unit(l, group)) {
      if (p <= last) return false;
      last = p;
    }
  return true;
}

// True when the physical value is exactly the logical tensor, axis for axis.
bool is_identity(const Layout& l) {
  if (l.physical.size() != l.groups.size()) return false;
  for (std::size_t a = 0; a < l.groups.size(); ++a) {
    const auto nu = non_unit(l, l.groups[a]);
    if (!(nu.empty() && l.physical[a] == 1) && nu != std::vector<int>{static_cast<int>(a)})
      return false;
  }
  return true;
}

struct ConvParams {
  std::int64_t stride_h = 1, stride_w = 1, dilation_h = 1, dilation_w = 1;
  bool same = false;
};

std::int64_t conv_output_size(std::int64_t in, std::int64_t kernel, std::int64_t stride,
                              std::int64_t dilation, bool same) {
  if (same) return (in + stride - 1) / stride;
  const std::int64_t effective = (kernel - 1) * dilation + 1;
  return in >= effective ? (in - effective) / stride + 1 : 0;
}

class Builder {
 public:
  using Handler = void (Builder::*)(const TfjsNode&);
  static const std::map<std::string, Handler, std::less<>>& handlers();

  Builder(const TfjsModel& model, const GraphCut& cut, std::span<const std::int64_t> input_shape,
          bool nchw_input)
      : model_(model),
        outputs_(cut.outputs),
        input_node_(cut.input),
        input_shape_(input_shape.begin(), input_shape.end()),
        nchw_input_(nchw_input) {
    for (const TfjsNode& n : model.nodes) by_name_[n.name] = &n;
  }

  BuiltGraph build();

 private:
  std::vector<const TfjsNode*> topological_order() const;
  void count_consumers(const std::vector<const TfjsNode*>& order);
  void plan_bias_folds(const std::vector<const TfjsNode*>& order);

  // ---- values
  const Value& value(const std::string& input) const;
  const Const& constant(const TfjsNode& n, std::size_t input) const;
  const Tensor* tensor_or_null(const TfjsNode& n, std::size_t input) const;
  std::vector<std::int64_t> ints(const TfjsNode& n, std::size_t input) const;
  void set(const TfjsNode& n, Value v, int index = 0) {
    values_[n.name + ":" + std::to_string(index)] = std::move(v);
  }
  std::vector<std::int64_t> logical_shape(const Value& v) const;

  // ---- subgraph helpers
  std::uint32_t define_tensor(std::span<const std::size_t> dims, const float* data = nullptr,
                              std::uint32_t flags = 0);
  std::uint32_t define_static(std::vector<float> data, std::span<const std::size_t> dims);
  // Queues an XNNPACK node: build() defines the nodes whose output is used (XNNPACK 2022 does not
  // prune dead nodes and would leave their outputs without memory).
  using Define = std::function<xnn_status(xnn_subgraph_t)>;
  void emit(const TfjsNode& n, std::string what, std::vector<std::uint32_t> inputs,
            std::uint32_t output, Define define);
  void define_live_nodes();
  std::uint32_t nhwc(const Tensor& t, const TfjsNode& n);
  Tensor copy_to(const Tensor& t, std::span<const std::int64_t> shape, const TfjsNode& n);
  std::uint32_t const_in_frame(const Const& c, const Layout& frame);
  Tensor clamp(const Tensor& t, float lo, float hi, const TfjsNode& n);

  // ---- ops
  void op_placeholder(const TfjsNode& n);
  void op_const(const TfjsNode& n);
  void op_identity(const TfjsNode& n);
  void op_cast(const TfjsNode& n);
  void op_shape(const TfjsNode& n);
  void op_expand_dims(const TfjsNode& n);
  void op_squeeze(const TfjsNode& n);
  void op_unpack(const TfjsNode& n);
  void op_reshape(const TfjsNode& n);
  void op_transpose(const TfjsNode& n);
  void op_strided_slice(const TfjsNode& n);
  void op_pack(const TfjsNode& n);
  void op_concat(const TfjsNode& n);
  void op_binary(const TfjsNode& n);
  void op_unary(const TfjsNode& n);
  void op_conv(const TfjsNode& n);
  void op_max_pool(const TfjsNode& n);
  void op_mean(const TfjsNode& n);
  void op_pad(const TfjsNode& n);
  void op_resize_bilinear(const TfjsNode& n);
  void op_split(const TfjsNode& n);
  void op_sparse_to_dense(const TfjsNode& n);
  void op_gather(const TfjsNode& n);

  Tensor binary_tensor(const std::string& op, const Value& a, const Value& b, const TfjsNode& n);
  Const fold_binary(const std::string& op, const Const& a, const Const& b) const;
  Tensor concat_tensors(const std::vector<Tensor>& parts, std::int64_t axis, const TfjsNode& n);

  const TfjsModel& model_;
  std::vector<std::string> outputs_;
  std::string input_node_;
  std::vector<std::int64_t> input_shape_;
  bool nchw_input_;
  std::unordered_map<std::string, const TfjsNode*> by_name_;
  std::unordered_map<std::string, int> consumers_;
  std::unordered_map<std::string, std::string> bias_of_conv_;  // conv node -> bias Const node
  std::unordered_map<std::string, std::string> folded_add_;    // Add node -> its conv node
  std::unordered_map<std::string, Value> values_;              // "node:output" -> value
  struct Pending {
    const TfjsNode* node;
    std::string what;
    std::vector<std::uint32_t> inputs;
    std::uint32_t output;
    Define define;
  };
  std::vector<Pending> pending_;
  std::vector<std::uint32_t> external_outputs_;
  BuiltGraph out_;
};

const std::map<std::string, Builder::Handler, std::less<>>& Builder::handlers() {
  static const std::map<std::string, Handler, std::less<>> kHandlers = {
      {"Placeholder", &Builder::op_placeholder},
      {"Const", &Builder::op_const},
      {"Identity", &Builder::op_identity},
      {"StopGradient", &Builder::op_identity},
      {"Cast", &Builder::op_cast},
      {"Shape", &Builder::op_shape},
      {"ExpandDims", &Builder::op_expand_dims},
      {"Squeeze", &Builder::op_squeeze},
      {"Unpack", &Builder::op_unpack},
      {"Reshape", &Builder::op_reshape},
      {"Transpose", &Builder::op_transpose},
      {"StridedSlice", &Builder::op_strided_slice},
      {"Pack", &Builder::op_pack},
      {"ConcatV2", &Builder::op_concat},
      {"Add", &Builder::op_binary},
      {"AddV2", &Builder::op_binary},
      {"BiasAdd", &Builder::op_binary},
      {"Sub", &Builder::op_binary},
      {"Mul", &Builder::op_binary},
      {"RealDiv", &Builder::op_binary},
      {"Div", &Builder::op_binary},
      {"Maximum", &Builder::op_binary},
      {"Minimum", &Builder::op_binary},
      {"SquaredDifference", &Builder::op_binary},
      {"FloorDiv", &Builder::op_binary},
      {"FloorMod", &Builder::op_binary},
      {"Relu", &Builder::op_unary},
      {"Relu6", &Builder::op_unary},
      {"LeakyRelu", &Builder::op_unary},
      {"Sigmoid", &Builder::op_unary},
      {"Elu", &Builder::op_unary},
      {"Abs", &Builder::op_unary},
      {"Neg", &Builder::op_unary},
      {"Square", &Builder::op_unary},
      {"Sqrt", &Builder::op_unary},
      {"Floor", &Builder::op_unary},
      {"Ceil", &Builder::op_unary},
      {"Conv2D", &Builder::op_conv},
      {"_FusedConv2D", &Builder::op_conv},
      {"DepthwiseConv2dNative", &Builder::op_conv},
      {"FusedDepthwiseConv2dNative", &Builder::op_conv},
      {"MaxPool", &Builder::op_max_pool},
      {"Mean", &Builder::op_mean},
      {"Pad", &Builder::op_pad},
      {"PadV2", &Builder::op_pad},
      {"ResizeBilinear", &Builder::op_resize_bilinear},
      {"Split", &Builder::op_split},
      {"SplitV", &Builder::op_split},
      {"SparseToDense", &Builder::op_sparse_to_dense},
      {"GatherV2", &Builder::op_gather},
  };
  return kHandlers;
}

// ---- graph walk -------------------------------------------------------------------------------

std::vector<const TfjsNode*> Builder::topological_order() const {
  std::vector<const TfjsNode*> order;
  std::unordered_map<std::string, int> state;  // 1: on the stack, 2: done
  for (const std::string& output : outputs_) {
    std::vector<std::pair<const TfjsNode*, std::size_t>> stack;
    const auto push = [&](const std::string& name) {
      const auto it = by_name_.find(name);
      if (it == by_name_.end()) fail_model(model_.file, "the graph has no node '" + name + "'");
      const int s = state[name];
      if (s == 1) fail_model(model_.file, "the graph has a cycle through node '" + name + "'");
      if (s == 0) {
        state[name] = 1;
        stack.emplace_back(it->second, 0);
      }
    };
    push(tfjs_base_name(output));
    while (!stack.empty()) {
      auto& [node, next] = stack.back();
      if (next < node->inputs.size() && node->name != input_node_) {
        const std::string& input = node->inputs[next++];
        if (!input.empty() && input.front() == '^') continue;  // control edges carry no data
        push(tfjs_base_name(input));
        continue;
      }
      state[node->name] = 2;
      order.push_back(node);
      stack.pop_back();
    }
  }
  return order;
}

void Builder::count_consumers(const std::vector<const TfjsNode*>& order) {
  for (const TfjsNode* n : order)
    for (const std::string& input : n->inputs) ++consumers_[tfjs_base_name(input)];
  for (const std::string& output : outputs_) ++consumers_[tfjs_base_name(output)];
}

// Conv2D -> Add(bias Const of the output channels), the ONNX-converted form of a biased
// convolution (nanodet): the bias goes into the convolution, the Add disappears.
void Builder::plan_bias_folds(const std::vector<const TfjsNode*>& order) {
  for (const TfjsNode* n : order) {
    if ((n->op != "Add" && n->op != "AddV2" && n->op != "BiasAdd") || n->inputs.size() != 2)
      continue;
    for (int side = 0; side < 2; ++side) {
      const auto conv = by_name_.find(n->inputs[static_cast<std::size_t>(side)]);
      const auto bias = by_name_.find(n->inputs[static_cast<std::size_t>(1 - side)]);
      if (conv == by_name_.end() || bias == by_name_.end()) continue;
      const TfjsNode& c = *conv->second;
      if ((c.op != "Conv2D" && c.op != "DepthwiseConv2dNative") || c.inputs.size() != 2 ||
          consumers_[c.name] != 1 || bias->second->op != "Const" || bias_of_conv_.contains(c.name))
        continue;
      const auto w = model_.weights.find(bias->second->name);
      const auto k = model_.weights.find(tfjs_base_name(c.inputs[1]));
      if (w == model_.weights.end() || k == model_.weights.end() || w->second.is_int ||
          w->second.shape.size() != 1 || k->second.shape.size() != 4)
        continue;
      const std::int64_t channels =
          c.op == "Conv2D" ? k->second.shape[3] : k->second.shape[2] * k->second.shape[3];
      if (w->second.shape[0] != channels) continue;
      bias_of_conv_[c.name] = bias->second->name;
      folded_add_[n->name] = c.name;
      break;
    }
  }
}

// ---- values -----------------------------------------------------------------------------------

const Value& Builder::value(const std::string& input) const {
  const std::string key = tfjs_base_name(input) + ":" + std::to_string(tfjs_output_index(input));
  const auto it = values_.find(key);
  if (it == values_.end())
    throw Unsupported("no value for input '" + input + "' (an output index the op lacks?)");
  return it->second;
}

const Const& Builder::constant(const TfjsNode& n, std::size_t input) const {
  if (input >= n.inputs.size()) throw Unsupported("input " + std::to_string(input) + " missing");
  const auto* c = std::get_if<Const>(&value(n.inputs[input]));
  if (!c)
    throw Unsupported("input " + std::to_string(input) +
                      " must be known when the network is built (a constant)");
  return *c;
}

const Tensor* Builder::tensor_or_null(const TfjsNode& n, std::size_t input) const {
  if (input >= n.inputs.size()) throw Unsupported("input " + std::to_string(input) + " missing");
  return std::get_if<Tensor>(&value(n.inputs[input]));
}

std::vector<std::int64_t> Builder::ints(const TfjsNode& n, std::size_t input) const {
  const Const& c = constant(n, input);
  std::vector<std::int64_t> out;
  for (const double v : c.v) {
    if (!(std::fabs(v) < kLargestIndex))
      throw ShapeMismatch("input " + std::to_string(input) + " holds " + std::to_string(v) +
                          ", not a size, index or axis");
    out.push_back(static_cast<std::int64_t>(v));
  }
  return out;
}

std::vector<std::int64_t> Builder::logical_shape(const Value& v) const {
  if (const auto* c = std::get_if<Const>(&v)) return c->shape;
  return std::get<Tensor>(v).layout.logical_shape();
}

// ---- subgraph helpers -------------------------------------------------------------------------

void Builder::emit(const TfjsNode& n, std::string what, std::vector<std::uint32_t> inputs,
                   std::uint32_t output, Define define) {
  pending_.push_back({&n, std::move(what), std::move(inputs), output, std::move(define)});
}

// Defines, in order, the queued nodes that lead to an external output.
void Builder::define_live_nodes() {
  std::set<std::uint32_t> needed(external_outputs_.begin(), external_outputs_.end());
  std::vector<bool> live(pending_.size(), false);
  for (std::size_t i = pending_.size(); i-- > 0;) {
    if (!needed.contains(pending_[i].output)) continue;
    live[i] = true;
    needed.insert(pending_[i].inputs.begin(), pending_[i].inputs.end());
  }
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    if (!live[i]) continue;
    const xnn_status status = pending_[i].define(out_.subgraph.get());
    if (status != xnn_status_success)
      fail_model(model_.file, "XNNPACK refused " + pending_[i].what + " (status " +
                                  std::to_string(static_cast<int>(status)) + ") for node '" +
                                  pending_[i].node->name + "'");
  }
}

std::uint32_t Builder::define_tensor(std::span<const std::size_t> dims, const float* data,
                                     std::uint32_t flags) {
  std::size_t values = 1;
  for (const std::size_t d : dims) {
    if (d == 0 || d > kLargestTensor || values > kLargestTensor / d)
      throw ShapeMismatch("a tensor of " + std::to_string(d) + " x " + std::to_string(values) +
                          " values (empty or over " + std::to_string(kLargestTensor) + ")");
    values *= d;
  }
  std::uint32_t id = XNN_INVALID_VALUE_ID;
  const xnn_status s = xnn_define_tensor_value(out_.subgraph.get(), xnn_datatype_fp32, dims.size(),
                                               dims.data(), data, XNN_INVALID_VALUE_ID, flags, &id);
  if (s != xnn_status_success)
    throw Unsupported("XNNPACK refused a tensor of rank " + std::to_string(dims.size()));
  return id;
}

std::uint32_t Builder::define_static(std::vector<float> data, std::span<const std::size_t> dims) {
  out_.arena.push_back(std::move(data));
  return define_tensor(dims, out_.arena.back().data());
}

// The tensor as an XNNPACK NHWC value, copied into logical order when it lies otherwise but in
// the right memory order already.
std::uint32_t Builder::nhwc(const Tensor& t, const TfjsNode& n) {
  if (t.layout.groups.size() != 4)
    throw Unsupported("needs a 4-D NHWC tensor, got rank " +
                      std::to_string(t.layout.groups.size()));
  if (is_identity(t.layout)) return t.id;
  if (!is_plain(t.layout))
    throw NeedsTranspose(
        "needs its input transposed to NHWC, which this runtime cannot do inside the "
        "network");
  return copy_to(t, t.layout.logical_shape(), n).id;
}

// A copy of a plain tensor with `shape` (same element count) as its identity layout.
Tensor Builder::copy_to(const Tensor& t, std::span<const std::int64_t> shape, const TfjsNode& n) {
  std::vector<std::size_t> dims(shape.begin(), shape.end());
  Tensor out{define_tensor(dims), identity_layout(shape)};
  emit(n, "a reshape", {t.id}, out.id, [dims, in = t.id, id = out.id](xnn_subgraph_t s) {
    return xnn_define_static_reshape(s, dims.size(), dims.data(), in, id, 0);
  });
  return out;
}

// A constant laid out in `frame`'s physical axes for a broadcasting elementwise op with a tensor
// of that layout (the constant right-aligned to the tensor's logical rank).
std::uint32_t Builder::const_in_frame(const Const& c, const Layout& frame) {
  const std::vector<std::int64_t> logical = frame.logical_shape();
  if (c.shape.size() > logical.size())
    throw Unsupported("a constant of higher rank than the tensor it combines with");
  const std::size_t skip = logical.size() - c.shape.size();
  std::vector<std::int64_t> dims(frame.physical.size(), 1);
  std::vector<bool> spread(logical.size(), false);  // constant varies along this logical axis
  for (std::size_t a = 0; a < logical.size(); ++a) {
    const std::int64_t cd = a >= skip ? c.shape[a - skip] : 1;
    if (cd == 1) continue;
    if (cd != logical[a])
      throw ShapeMismatch("a constant " + shape_text(c.shape) + " does not broadcast to " +
                          shape_text(logical));
    spread[a] = true;
    for (const int p : frame.groups[a])
      dims[static_cast<std::size_t>(p)] = static_cast<std::int64_t>(frame.physical[p]);
  }
  std::vector<float> data(product(dims));
  const auto cstrides = row_major_strides(c.shape);
  for_each_index(dims, [&](std::size_t flat, std::span<const std::int64_t> pi) {
    std::size_t offset = 0;
    for (std::size_t a = skip; a < logical.size(); ++a) {
      if (!spread[a]) continue;
      std::size_t index = 0;
      for (const int p : frame.groups[a])
        index = index * frame.physical[static_cast<std::size_t>(p)] +
                static_cast<std::size_t>(pi[static_cast<std::size_t>(p)]);
      offset += index * cstrides[a - skip];
    }
    data[flat] = static_cast<float>(c.v[offset]);
  });
  std::vector<std::size_t> udims(dims.begin(), dims.end());
  return define_static(std::move(data), udims);
}

Tensor Builder::clamp(const Tensor& t, float lo, float hi, const TfjsNode& n) {
  Tensor out{define_tensor(t.layout.physical), t.layout};
  emit(n, "a clamp", {t.id}, out.id, [=, in = t.id, id = out.id](xnn_subgraph_t s) {
    return xnn_define_clamp(s, lo, hi, in, id, 0);
  });
  return out;
}

// ---- ops: structure ---------------------------------------------------------------------------

void Builder::op_placeholder(const TfjsNode& n) {
  if (product(input_shape_) == 0) throw ShapeMismatch("empty input " + shape_text(input_shape_));
  Layout layout;
  if (nchw_input_) {  // fed as NHWC: logical N, C, H, W are physical 0, 3, 1, 2
    const auto& s = input_shape_;
    layout.physical = {static_cast<std::size_t>(s[0]), static_cast<std::size_t>(s[2]),
                       static_cast<std::size_t>(s[3]), static_cast<std::size_t>(s[1])};
    layout.groups = {{0}, {3}, {1}, {2}};
  } else {
    layout = identity_layout(input_shape_);
  }
  out_.input_id = define_tensor(layout.physical, nullptr, XNN_VALUE_FLAG_EXTERNAL_INPUT);
  out_.input_layout = layout;
  set(n, Tensor{out_.input_id, layout});
}

void Builder::op_const(const TfjsNode& n) {
  const auto w = model_.weights.find(n.name);
  if (w == model_.weights.end()) fail_model(model_.file, "Const '" + n.name + "' has no weights");
  Const c{w->second.shape, {}, w->second.is_int};
  if (c.is_int)
    c.v.assign(w->second.ints.begin(), w->second.ints.end());
  else
    c.v.assign(w->second.floats.begin(), w->second.floats.end());
  set(n, std::move(c));
}

void Builder::op_identity(const TfjsNode& n) { set(n, value(n.inputs.at(0))); }

// The input's int32 -> float Cast is dropped (the input is fed as float); constants convert.
void Builder::op_cast(const TfjsNode& n) {
  Value v = value(n.inputs.at(0));
  const TfjsAttr* dst = n.find("DstT");
  const bool to_int = dst && dst->type != 1 && dst->type != 2 && dst->type != 19;
  if (auto* c = std::get_if<Const>(&v)) {
    c->is_int = to_int;
    if (to_int)
      for (double& x : c->v) x = std::trunc(x);
  } else if (to_int) {
    throw Unsupported("Cast of a computed tensor to an integer type (tensors are float)");
  }
  set(n, std::move(v));
}

void Builder::op_shape(const TfjsNode& n) {
  const auto shape = logical_shape(value(n.inputs.at(0)));
  set(n, Const{{static_cast<std::int64_t>(shape.size())},
               std::vector<double>(shape.begin(), shape.end()),
               true});
}

void Builder::op_expand_dims(const TfjsNode& n) {
  Value v = value(n.inputs.at(0));
  const auto shape = logical_shape(v);
  const auto axes = ints(n, 1);
  if (axes.size() != 1) throw Unsupported("ExpandDims of several axes");
  std::int64_t axis = axes[0];
  if (axis < 0) axis += static_cast<std::int64_t>(shape.size()) + 1;
  if (axis < 0 || axis > static_cast<std::int64_t>(shape.size()))
    throw ShapeMismatch("ExpandDims axis out of range");
  if (auto* c = std::get_if<Const>(&v)) {
    c->shape.insert(c->shape.begin() + axis, 1);
  } else {
    auto& groups = std::get<Tensor>(v).layout.groups;
    groups.insert(groups.begin() + axis, std::vector<int>{});
  }
  set(n, std::move(v));
}

// Removes unit logical axes (`axes`; every unit axis when empty).
void drop_unit_axes(Value& v, std::vector<std::int64_t> axes, std::vector<std::int64_t> shape) {
  if (axes.empty())
    for (std::size_t a = 0; a < shape.size(); ++a)
      if (shape[a] == 1) axes.push_back(static_cast<std::int64_t>(a));
  for (auto& a : axes) a = normalise_axis(a, shape.size());
  std::sort(axes.rbegin(), axes.rend());
  axes.erase(std::unique(axes.begin(), axes.end()), axes.end());
  for (const std::int64_t a : axes) {
    if (shape[static_cast<std::size_t>(a)] != 1)
      throw ShapeMismatch("cannot squeeze an axis of size " +
                          std::to_string(shape[static_cast<std::size_t>(a)]));
    if (auto* c = std::get_if<Const>(&v))
      c->shape.erase(c->shape.begin() + a);
    else
      std::get<Tensor>(v).layout.groups.erase(std::get<Tensor>(v).layout.groups.begin() + a);
  }
}

void Builder::op_squeeze(const TfjsNode& n) {
  Value v = value(n.inputs.at(0));
  const TfjsAttr* dims = n.find("squeeze_dims");
  drop_unit_axes(v, dims ? dims->list_i : std::vector<std::int64_t>{}, logical_shape(v));
  set(n, std::move(v));
}

void Builder::op_unpack(const TfjsNode& n) {
  const Value& in = value(n.inputs.at(0));
  const auto shape = logical_shape(in);
  const TfjsAttr* axis_attr = n.find("axis");
  const std::int64_t axis = normalise_axis(axis_attr ? axis_attr->i : 0, shape.size());
  const auto count = shape[static_cast<std::size_t>(axis)];
  if (const auto* c = std::get_if<Const>(&in)) {
    std::vector<std::int64_t> part_shape = shape;
    part_shape.erase(part_shape.begin() + axis);
    const auto strides = row_major_strides(shape);
    for (std::int64_t k = 0; k < count; ++k) {
      Const part{part_shape, {}, c->is_int};
      for_each_index(part_shape, [&](std::size_t, std::span<const std::int64_t> idx) {
        std::size_t offset = 0;
        for (std::size_t a = 0, b = 0; a < shape.size(); ++a)
          offset += strides[a] *
                    static_cast<std::size_t>(static_cast<std::int64_t>(a) == axis ? k : idx[b++]);
        part.v.push_back(c->v[offset]);
      });
      set(n, std::move(part), static_cast<int>(k));
    }
    return;
  }
  if (count != 1) throw Unsupported("Unpack of a computed tensor into several parts");
  Value v = in;
  drop_unit_axes(v, {axis}, shape);
  set(n, std::move(v));
}

// New groups for `shape` from the physical axes of `l` taken in logical order, or false when an
// axis would have to split a physical axis.
bool regroup(const Layout& l, std::span<const std::int64_t> shape,
             std::vector<std::vector<int>>& groups) {
  std::vector<int> axes;  // non-unit physical axes in logical order
  for (const auto& group : l.groups)
    for (const int p : non_unit(l, group)) axes.push_back(p);
  groups.assign(shape.size(), {});
  std::size_t next = 0;
  for (std::size_t a = 0; a < shape.size(); ++a) {
    std::int64_t size = 1;
    while (size < shape[a] && next < axes.size()) {
      const int p = axes[next++];
      size *= static_cast<std::int64_t>(l.physical[static_cast<std::size_t>(p)]);
      groups[a].push_back(p);
    }
    if (size != shape[a]) return false;
  }
  return next == axes.size();
}

void Builder::op_reshape(const TfjsNode& n) {
  Value v = value(n.inputs.at(0));
  const auto old_shape = logical_shape(v);
  auto shape = ints(n, 1);
  const std::size_t total = product(old_shape);
  std::size_t known = 1;
  int unknown = -1;
  for (std::size_t a = 0; a < shape.size(); ++a) {
    if (shape[a] == -1 && unknown < 0)
      unknown = static_cast<int>(a);
    else if (shape[a] < 0)
      throw ShapeMismatch("Reshape to " + shape_text(shape));
    else
      known *= static_cast<std::size_t>(shape[a]);
  }
  if (unknown >= 0 && known > 0)
    shape[static_cast<std::size_t>(unknown)] = static_cast<std::int64_t>(total / known);
  if (product(shape) != total)
    throw ShapeMismatch("Reshape of " + shape_text(old_shape) + " to " + shape_text(shape));
  if (auto* c = std::get_if<Const>(&v)) {
    c->shape = shape;
    set(n, std::move(v));
    return;
  }
  Tensor& t = std::get<Tensor>(v);
  std::vector<std::vector<int>> groups;
  if (regroup(t.layout, shape, groups)) {
    t.layout.groups = std::move(groups);
    set(n, std::move(v));
  } else if (is_plain(t.layout)) {
    set(n, copy_to(t, shape, n));
  } else {
    throw Unsupported("Reshape of a transposed tensor that needs its data moved");
  }
}

void Builder::op_transpose(const TfjsNode& n) {
  Value v = value(n.inputs.at(0));
  const auto shape = logical_shape(v);
  const auto perm = ints(n, 1);
  std::vector<std::int64_t> sorted = perm;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t a = 0; a < sorted.size(); ++a)
    if (sorted.size() != shape.size() || sorted[a] != static_cast<std::int64_t>(a))
      throw ShapeMismatch("Transpose permutation " + shape_text(perm) + " of a rank-" +
                          std::to_string(shape.size()) + " tensor");
  if (auto* c = std::get_if<Const>(&v)) {
    Const out{{}, {}, c->is_int};
    for (const auto p : perm) out.shape.push_back(c->shape[static_cast<std::size_t>(p)]);
    const auto strides = row_major_strides(c->shape);
    for_each_index(out.shape, [&](std::size_t, std::span<const std::int64_t> idx) {
      std::size_t offset = 0;
      for (std::size_t a = 0; a < perm.size(); ++a)
        offset += strides[static_cast<std::size_t>(perm[a])] * static_cast<std::size_t>(idx[a]);
      out.v.push_back(c->v[offset]);
    });
    set(n, std::move(out));
    return;
  }
  Layout& l = std::get<Tensor>(v).layout;
  std::vector<std::vector<int>> groups;
  for (const auto p : perm) groups.push_back(l.groups[static_cast<std::size_t>(p)]);
  l.groups = std::move(groups);
  set(n, std::move(v));
}

// Constant StridedSlice (shape arithmetic): begin/end masks and shrinking, no ellipsis.
void Builder::op_strided_slice(const TfjsNode& n) {
  const Const& c = constant(n, 0);
  const auto begin = ints(n, 1), end = ints(n, 2), step = ints(n, 3);
  const auto mask = [&](const char* key) {
    const TfjsAttr* a = n.find(key);
    return a ? a->i : 0;
  };
  if (mask("ellipsis_mask") || mask("new_axis_mask"))
    throw Unsupported("StridedSlice with an ellipsis or new axes");
  const std::size_t rank = c.shape.size();
  if (begin.size() > rank || end.size() != begin.size() || step.size() != begin.size())
    throw ShapeMismatch("StridedSlice bounds do not match the input's rank");
  std::vector<std::vector<std::int64_t>> picks(rank);
  std::vector<std::int64_t> out_shape;
  for (std::size_t a = 0; a < rank; ++a) {
    const std::int64_t dim = c.shape[a];
    if (a >= begin.size()) {
      for (std::int64_t i = 0; i < dim; ++i) picks[a].push_back(i);
      out_shape.push_back(dim);
      continue;
    }
    const std::int64_t s = step[a];
    if (s == 0) throw ShapeMismatch("StridedSlice step 0");
    const auto clamp_index = [&](std::int64_t i, bool is_end) {
      if (i < 0) i += dim;
      return s > 0 ? std::clamp<std::int64_t>(i, 0, dim)
                   : std::clamp<std::int64_t>(i, -1, dim - (is_end ? 0 : 1));
    };
    std::int64_t b =
        (mask("begin_mask") >> a) & 1 ? (s > 0 ? 0 : dim - 1) : clamp_index(begin[a], false);
    std::int64_t e = (mask("end_mask") >> a) & 1 ? (s > 0 ? dim : -1) : clamp_index(end[a], true);
    if ((mask("shrink_axis_mask") >> a) & 1) {
      b = begin[a] < 0 ? begin[a] + dim : begin[a];
      if (b < 0 || b >= dim) throw ShapeMismatch("StridedSlice index out of range");
      picks[a] = {b};
      continue;
    }
    for (std::int64_t i = b; s > 0 ? i < e : i > e; i += s) picks[a].push_back(i);
    out_shape.push_back(static_cast<std::int64_t>(picks[a].size()));
  }
  std::vector<std::int64_t> full_shape;
  for (const auto& p : picks) full_shape.push_back(static_cast<std::int64_t>(p.size()));
  Const out{out_shape, {}, c.is_int};
  const auto strides = row_major_strides(c.shape);
  for_each_index(full_shape, [&](std::size_t, std::span<const std::int64_t> idx) {
    std::size_t offset = 0;
    for (std::size_t a = 0; a < rank; ++a)
      offset += strides[a] * static_cast<std::size_t>(picks[a][static_cast<std::size_t>(idx[a])]);
    out.v.push_back(c.v[offset]);
  });
  set(n, std::move(out));
}

void Builder::op_pack(const TfjsNode& n) {
  std::vector<const Const*> parts;
  for (std::size_t i = 0; i < n.inputs.size(); ++i) parts.push_back(&constant(n, i));
  if (parts.empty()) throw ShapeMismatch("Pack of nothing");
  const auto& shape = parts[0]->shape;
  const TfjsAttr* axis_attr = n.find("axis");
  std::int64_t axis = axis_attr ? axis_attr->i : 0;
  if (axis < 0) axis += static_cast<std::int64_t>(shape.size()) + 1;
  if (axis < 0 || axis > static_cast<std::int64_t>(shape.size()))
    throw ShapeMismatch("Pack axis out of range");
  Const out{shape, {}, parts[0]->is_int};
  out.shape.insert(out.shape.begin() + axis, static_cast<std::int64_t>(parts.size()));
  for_each_index(out.shape, [&](std::size_t, std::span<const std::int64_t> idx) {
    const Const& part = *parts[static_cast<std::size_t>(idx[static_cast<std::size_t>(axis)])];
    if (part.shape != shape) throw ShapeMismatch("Pack of differently shaped values");
    std::size_t offset = 0;
    for (std::size_t a = 0, b = 0; a < idx.size(); ++a)
      if (static_cast<std::int64_t>(a) != axis)
        offset = offset * static_cast<std::size_t>(shape[b++]) + static_cast<std::size_t>(idx[a]);
    out.v.push_back(part.v[offset]);
  });
  set(n, std::move(out));
}

void Builder::op_concat(const TfjsNode& n) {
  if (n.inputs.size() < 2) throw ShapeMismatch("ConcatV2 without inputs");
  const std::size_t count = n.inputs.size() - 1;  // the last input is the axis
  const auto axis_value = ints(n, count);
  if (axis_value.size() != 1) throw ShapeMismatch("ConcatV2 axis is not a scalar");
  std::vector<Tensor> tensors;
  std::vector<const Const*> consts;
  for (std::size_t i = 0; i < count; ++i) {
    if (const Tensor* t = tensor_or_null(n, i))
      tensors.push_back(*t);
    else
      consts.push_back(&constant(n, i));
  }
  if (!tensors.empty()) {
    if (!consts.empty()) throw Unsupported("ConcatV2 of computed tensors with constants");
    const std::size_t rank = tensors[0].layout.groups.size();
    set(n, concat_tensors(tensors, normalise_axis(axis_value[0], rank), n));
    return;
  }
  const std::size_t rank = consts[0]->shape.size();
  const std::int64_t axis = normalise_axis(axis_value[0], rank);
  Const out{consts[0]->shape, {}, consts[0]->is_int};
  out.shape[static_cast<std::size_t>(axis)] = 0;
  for (const Const* c : consts) {
    if (c->shape.size() != rank) throw ShapeMismatch("ConcatV2 of different ranks");
    out.shape[static_cast<std::size_t>(axis)] += c->shape[static_cast<std::size_t>(axis)];
  }
  for_each_index(out.shape, [&](std::size_t, std::span<const std::int64_t> idx) {
    std::int64_t along = idx[static_cast<std::size_t>(axis)];
    for (const Const* c : consts) {
      const std::int64_t size = c->shape[static_cast<std::size_t>(axis)];
      if (along >= size) {
        along -= size;
        continue;
      }
      std::size_t offset = 0;
      for (std::size_t a = 0; a < rank; ++a) {
        if (a != static_cast<std::size_t>(axis) && c->shape[a] != out.shape[a])
          throw ShapeMismatch("ConcatV2 of mismatched shapes");
        offset = offset * static_cast<std::size_t>(c->shape[a]) +
                 static_cast<std::size_t>(a == static_cast<std::size_t>(axis) ? along : idx[a]);
      }
      out.v.push_back(c->v[offset]);
      break;
    }
  });
  set(n, std::move(out));
}

// Concatenation without a concatenate operator: each part zero-padded to the full extent along
// the axis, then added up (x + 0 is exact).
Tensor Builder::concat_tensors(const std::vector<Tensor>& parts, std::int64_t axis,
                               const TfjsNode& n) {
  const Layout& first = parts[0].layout;
  if (first.groups[static_cast<std::size_t>(axis)].size() != 1)
    throw Unsupported("ConcatV2 along an axis that is not one physical axis");
  const auto p = static_cast<std::size_t>(first.groups[static_cast<std::size_t>(axis)][0]);
  std::size_t total = 0;
  for (const Tensor& t : parts) {
    if (t.layout.groups != first.groups || t.layout.physical.size() != first.physical.size())
      throw Unsupported("ConcatV2 of tensors laid out differently");
    for (std::size_t q = 0; q < first.physical.size(); ++q)
      if (q != p && t.layout.physical[q] != first.physical[q])
        throw ShapeMismatch("ConcatV2 of mismatched shapes");
    total += t.layout.physical[p];
  }
  Layout layout = first;
  layout.physical[p] = total;
  std::optional<Tensor> sum;
  std::size_t offset = 0;
  for (const Tensor& t : parts) {
    std::vector<std::size_t> pre(layout.physical.size(), 0), post(layout.physical.size(), 0);
    pre[p] = offset;
    post[p] = total - offset - t.layout.physical[p];
    offset += t.layout.physical[p];
    Tensor padded{define_tensor(layout.physical), layout};
    emit(n, "a padding (concatenation)", {t.id}, padded.id,
         [pre, post, in = t.id, id = padded.id](xnn_subgraph_t s) {
           return xnn_define_static_constant_pad(s, pre.data(), post.data(), 0.0f, in, id, 0);
         });
    if (!sum) {
      sum = padded;
      continue;
    }
    Tensor added{define_tensor(layout.physical), layout};
    emit(n, "an addition (concatenation)", {sum->id, padded.id}, added.id,
         [a = sum->id, b = padded.id, id = added.id](xnn_subgraph_t s) {
           return xnn_define_add2(s, -kInf, kInf, a, b, id, 0);
         });
    sum = added;
  }
  return *sum;
}

// ---- ops: arithmetic --------------------------------------------------------------------------

double apply_binary(const std::string& op, double a, double b, bool ints) {
  if (op == "Add" || op == "AddV2" || op == "BiasAdd") return a + b;
  if (op == "Sub") return a - b;
  if (op == "Mul") return a * b;
  if (op == "RealDiv" || op == "Div") return ints ? std::trunc(a / b) : a / b;
  if (op == "Maximum") return std::max(a, b);
  if (op == "Minimum") return std::min(a, b);
  if (op == "SquaredDifference") return (a - b) * (a - b);
  if (op == "FloorDiv") return std::floor(a / b);
  if (op == "FloorMod") return a - std::floor(a / b) * b;
  throw Unsupported("binary op " + op);
}

Const Builder::fold_binary(const std::string& op, const Const& a, const Const& b) const {
  Const out{broadcast_shape(a.shape, b.shape), {}, a.is_int && b.is_int};
  if (product(out.shape) > (1u << 24)) throw Unsupported("a constant of more than 16 M values");
  for_each_index(out.shape, [&](std::size_t, std::span<const std::int64_t> idx) {
    double r = apply_binary(op, a.v[broadcast_offset(a.shape, idx)],
                            b.v[broadcast_offset(b.shape, idx)], out.is_int);
    if (!out.is_int) r = static_cast<float>(r);  // float32 arithmetic, as TensorFlow
    out.v.push_back(r);
  });
  return out;
}

// Broadcast-compatible physical frames: equal physical rank, and every non-unit physical axis of
// both sides carrying the same (right-aligned) logical axis.
Layout joint_layout(const Layout& a, const Layout& b) {
  if (a.physical.size() != b.physical.size())
    throw Unsupported("an elementwise op on tensors laid out differently");
  const std::size_t rank = std::max(a.groups.size(), b.groups.size());
  const auto owner = [&](const Layout& l) {
    std::vector<int> by_axis(l.physical.size(), -1);
    const std::size_t skip = rank - l.groups.size();
    for (std::size_t g = 0; g < l.groups.size(); ++g)
      for (const int p : non_unit(l, l.groups[g]))
        by_axis[static_cast<std::size_t>(p)] = static_cast<int>(g + skip);
    return by_axis;
  };
  const auto oa = owner(a), ob = owner(b);
  Layout out;
  out.groups.assign(rank, {});
  for (std::size_t p = 0; p < a.physical.size(); ++p) {
    const std::size_t da = a.physical[p], db = b.physical[p];
    if (da != 1 && db != 1 && (da != db || oa[p] != ob[p]))
      throw ShapeMismatch("tensors that do not broadcast");
    out.physical.push_back(std::max(da, db));
    const int o = da != 1 ? oa[p] : db != 1 ? ob[p] : -1;
    if (o >= 0) out.groups[static_cast<std::size_t>(o)].push_back(static_cast<int>(p));
  }
  return out;
}

Tensor Builder::binary_tensor(const std::string& op, const Value& a, const Value& b,
                              const TfjsNode& n) {
  const Tensor* ta = std::get_if<Tensor>(&a);
  const Tensor* tb = std::get_if<Tensor>(&b);
  const Layout& frame = ta ? ta->layout : tb->layout;
  const std::uint32_t ia = ta ? ta->id : const_in_frame(std::get<Const>(a), frame);
  const std::uint32_t ib = tb ? tb->id : const_in_frame(std::get<Const>(b), frame);
  Layout layout = frame;
  if (ta && tb) {
    layout = joint_layout(ta->layout, tb->layout);
  } else {
    broadcast_shape(frame.logical_shape(), logical_shape(ta ? b : a));  // throws on a mismatch
    if (logical_shape(ta ? b : a).size() > frame.groups.size())
      throw Unsupported("a constant of higher rank than the tensor it combines with");
  }
  Tensor out{define_tensor(layout.physical), layout};
  const std::uint32_t id = out.id;
  Define define;
  if (op == "Add" || op == "AddV2" || op == "BiasAdd")
    define = [=](xnn_subgraph_t s) { return xnn_define_add2(s, -kInf, kInf, ia, ib, id, 0); };
  else if (op == "Sub")
    define = [=](xnn_subgraph_t s) { return xnn_define_subtract(s, -kInf, kInf, ia, ib, id, 0); };
  else if (op == "Mul")
    define = [=](xnn_subgraph_t s) { return xnn_define_multiply2(s, -kInf, kInf, ia, ib, id, 0); };
  else if (op == "RealDiv" || op == "Div")
    define = [=](xnn_subgraph_t s) { return xnn_define_divide(s, -kInf, kInf, ia, ib, id, 0); };
  else if (op == "Maximum")
    define = [=](xnn_subgraph_t s) { return xnn_define_maximum2(s, ia, ib, id, 0); };
  else if (op == "Minimum")
    define = [=](xnn_subgraph_t s) { return xnn_define_minimum2(s, ia, ib, id, 0); };
  else if (op == "SquaredDifference")
    define = [=](xnn_subgraph_t s) { return xnn_define_squared_difference(s, ia, ib, id, 0); };
  else
    throw Unsupported(op + " of computed tensors");
  emit(n, op, {ia, ib}, id, std::move(define));
  return out;
}

void Builder::op_binary(const TfjsNode& n) {
  if (n.inputs.size() != 2) throw ShapeMismatch(n.op + " needs two inputs");
  if (const auto folded = folded_add_.find(n.name); folded != folded_add_.end()) {
    set(n, value(folded->second));  // the bias went into the convolution
    return;
  }
  const Value& a = value(n.inputs[0]);
  const Value& b = value(n.inputs[1]);
  const Const* ca = std::get_if<Const>(&a);
  const Const* cb = std::get_if<Const>(&b);
  if (ca && cb)
    set(n, fold_binary(n.op, *ca, *cb));
  else
    set(n, binary_tensor(n.op, a, b, n));
}

double apply_unary(const std::string& op, double x, float alpha) {
  if (op == "Relu") return std::max(x, 0.0);
  if (op == "Relu6") return std::clamp(x, 0.0, 6.0);
  if (op == "LeakyRelu") return x < 0 ? x * alpha : x;
  if (op == "Sigmoid") return 1.0 / (1.0 + std::exp(-x));
  if (op == "Elu") return x < 0 ? std::expm1(x) : x;
  if (op == "Abs") return std::fabs(x);
  if (op == "Neg") return -x;
  if (op == "Square") return x * x;
  if (op == "Sqrt") return std::sqrt(x);
  if (op == "Floor") return std::floor(x);
  if (op == "Ceil") return std::ceil(x);
  throw Unsupported("unary op " + op);
}

void Builder::op_unary(const TfjsNode& n) {
  const TfjsAttr* alpha_attr = n.find("alpha");
  const float alpha = alpha_attr ? alpha_attr->f : 0.2f;  // TensorFlow's LeakyRelu default
  const Value& in = value(n.inputs.at(0));
  if (const auto* c = std::get_if<Const>(&in)) {
    Const out{c->shape, {}, false};
    for (const double x : c->v) out.v.push_back(static_cast<float>(apply_unary(n.op, x, alpha)));
    set(n, std::move(out));
    return;
  }
  const Tensor& t = std::get<Tensor>(in);
  if (n.op == "Relu") return set(n, clamp(t, 0.0f, kInf, n));
  if (n.op == "Relu6") return set(n, clamp(t, 0.0f, 6.0f, n));
  Tensor out{define_tensor(t.layout.physical), t.layout};
  using Unary = xnn_status (*)(xnn_subgraph_t, std::uint32_t, std::uint32_t, std::uint32_t);
  static const std::map<std::string, Unary, std::less<>> kUnary = {
      {"Sigmoid", xnn_define_sigmoid},  {"Abs", xnn_define_abs},
      {"Neg", xnn_define_negate},       {"Square", xnn_define_square},
      {"Sqrt", xnn_define_square_root}, {"Floor", xnn_define_floor},
      {"Ceil", xnn_define_ceiling}};
  const std::uint32_t from = t.id, id = out.id;
  Define define;
  if (n.op == "LeakyRelu")
    define = [=](xnn_subgraph_t s) { return xnn_define_leaky_relu(s, alpha, from, id, 0); };
  else if (n.op == "Elu")
    define = [=](xnn_subgraph_t s) { return xnn_define_elu(s, 1.0f, from, id, 0); };
  else if (const auto f = kUnary.find(n.op); f != kUnary.end())
    define = [=, f = f->second](xnn_subgraph_t s) { return f(s, from, id, 0); };
  else
    throw Unsupported("unary op " + n.op);
  emit(n, n.op, {from}, id, std::move(define));
  set(n, out);
}

// ---- ops: convolution and pooling -------------------------------------------------------------

ConvParams conv_params(const TfjsNode& n) {
  ConvParams p;
  const TfjsAttr* strides = n.find("strides");
  const TfjsAttr* dilations = n.find("dilations");
  const TfjsAttr* padding = n.find("padding");
  const TfjsAttr* format = n.find("data_format");
  if (format && format->s != "NHWC") throw Unsupported(n.op + " in " + format->s + " layout");
  if (strides && strides->list_i.size() == 4) {
    p.stride_h = strides->list_i[1];
    p.stride_w = strides->list_i[2];
  }
  if (dilations && dilations->list_i.size() == 4) {
    p.dilation_h = dilations->list_i[1];
    p.dilation_w = dilations->list_i[2];
  }
  if (!padding || (padding->s != "SAME" && padding->s != "VALID"))
    throw Unsupported(n.op + " with padding " + (padding ? padding->s : std::string("(none)")));
  p.same = padding->s == "SAME";
  if (p.stride_h < 1 || p.stride_w < 1 || p.dilation_h < 1 || p.dilation_w < 1 || p.stride_h > 64 ||
      p.stride_w > 64 || p.dilation_h > 64 || p.dilation_w > 64)
    throw Unsupported(n.op + " with strides or dilations out of range");
  return p;
}

void Builder::op_conv(const TfjsNode& n) {
  const bool depthwise = n.op.find("Depthwise") != std::string::npos;
  const bool fused = n.op.front() == '_' || n.op.starts_with("Fused");
  const Tensor* input = tensor_or_null(n, 0);
  if (!input) throw Unsupported(n.op + " of a constant");
  const std::uint32_t in = nhwc(*input, n);
  const Const& kernel = constant(n, 1);
  if (kernel.shape.size() != 4 || product(kernel.shape) == 0)
    throw ShapeMismatch(n.op + " kernel " + shape_text(kernel.shape));
  const ConvParams p = conv_params(n);
  const auto in_shape = input->layout.logical_shape();
  const std::int64_t kh = kernel.shape[0], kw = kernel.shape[1], ki = kernel.shape[2],
                     ko = kernel.shape[3];
  const std::int64_t channels = in_shape[3];
  const std::int64_t out_channels = depthwise ? ki * ko : ko;
  if ((depthwise && ki != channels) || (!depthwise && (channels % ki != 0 || ko % (channels / ki))))
    throw ShapeMismatch(n.op + " kernel " + shape_text(kernel.shape) + " on " +
                        std::to_string(channels) + " channels");
  const std::int64_t groups = depthwise ? 1 : channels / ki;

  // Bias and activation: fused ones, or a bias Add folded in by plan_bias_folds.
  std::vector<float> bias(static_cast<std::size_t>(out_channels), 0.0f);
  float lo = -kInf, hi = kInf;
  bool leaky = false;
  float leaky_alpha = 0.2f;
  if (fused) {
    const auto ops = tfjs_fused_ops(n);
    if (ops.empty() || ops[0] != "BiasAdd" || ops.size() > 2 || n.inputs.size() < 3)
      throw Unsupported(n.op + " fusing other than BiasAdd [+ activation]");
    const Const& b = constant(n, 2);
    if (b.v.size() != bias.size()) throw ShapeMismatch(n.op + " bias size");
    std::copy(b.v.begin(), b.v.end(), bias.begin());
    if (ops.size() == 2) {
      if (ops[1] == "Relu") {
        lo = 0.0f;
      } else if (ops[1] == "Relu6") {
        lo = 0.0f;
        hi = 6.0f;
      } else if (ops[1] == "LeakyRelu") {
        leaky = true;
        if (const TfjsAttr* a = n.find("leakyrelu_alpha")) leaky_alpha = a->f;
      } else {
        throw Unsupported(n.op + " fusing " + ops[1]);
      }
    }
  } else if (const auto folded = bias_of_conv_.find(n.name); folded != bias_of_conv_.end()) {
    const auto& w = model_.weights.at(folded->second).floats;
    std::copy(w.begin(), w.end(), bias.begin());
  }

  const std::int64_t oh = conv_output_size(in_shape[1], kh, p.stride_h, p.dilation_h, p.same);
  const std::int64_t ow = conv_output_size(in_shape[2], kw, p.stride_w, p.dilation_w, p.same);
  if (oh <= 0 || ow <= 0)
    throw ShapeMismatch(n.op + " kernel larger than its " + shape_text(in_shape) + " input");
  const std::vector<std::int64_t> out_shape = {in_shape[0], oh, ow, out_channels};
  Tensor out{define_tensor(std::vector<std::size_t>(out_shape.begin(), out_shape.end())),
             identity_layout(out_shape)};

  // TF HWIO -> XNNPACK OHWI; depthwise [kh, kw, C, M] is XNNPACK's [1, kh, kw, C * M] already.
  std::vector<float> filter(kernel.v.size());
  std::vector<std::size_t> filter_dims;
  if (depthwise) {
    std::copy(kernel.v.begin(), kernel.v.end(), filter.begin());
    filter_dims = {1, static_cast<std::size_t>(kh), static_cast<std::size_t>(kw),
                   static_cast<std::size_t>(out_channels)};
  } else {
    std::size_t i = 0;
    for (std::int64_t o = 0; o < ko; ++o)
      for (std::int64_t y = 0; y < kh; ++y)
        for (std::int64_t x = 0; x < kw; ++x)
          for (std::int64_t c = 0; c < ki; ++c)
            filter[i++] = static_cast<float>(
                kernel.v[static_cast<std::size_t>(((y * kw + x) * ki + c) * ko + o)]);
    filter_dims = {static_cast<std::size_t>(ko), static_cast<std::size_t>(kh),
                   static_cast<std::size_t>(kw), static_cast<std::size_t>(ki)};
  }
  const std::uint32_t filter_id = define_static(std::move(filter), filter_dims);
  const std::vector<std::size_t> bias_dims = {bias.size()};
  const std::uint32_t bias_id = define_static(std::move(bias), bias_dims);
  const std::uint32_t flags = p.same ? XNN_FLAG_TENSORFLOW_SAME_PADDING : 0;
  const auto u = [](std::int64_t v) { return static_cast<std::uint32_t>(v); };
  const std::uint32_t id = out.id;
  if (depthwise) {
    emit(n, "a depthwise convolution", {in}, id, [=](xnn_subgraph_t s) {
      return xnn_define_depthwise_convolution_2d(s, 0, 0, 0, 0, u(kh), u(kw), u(p.stride_h),
                                                 u(p.stride_w), u(p.dilation_h), u(p.dilation_w),
                                                 u(ko), static_cast<std::size_t>(ki), lo, hi, in,
                                                 filter_id, bias_id, id, flags);
    });
  } else {
    emit(n, "a convolution", {in}, id, [=](xnn_subgraph_t s) {
      return xnn_define_convolution_2d(
          s, 0, 0, 0, 0, u(kh), u(kw), u(p.stride_h), u(p.stride_w), u(p.dilation_h),
          u(p.dilation_w), u(groups), static_cast<std::size_t>(ki),
          static_cast<std::size_t>(ko / groups), lo, hi, in, filter_id, bias_id, id, flags);
    });
  }
  if (leaky) {
    Tensor activated{define_tensor(out.layout.physical), out.layout};
    emit(n, "a leaky ReLU", {id}, activated.id, [=, to = activated.id](xnn_subgraph_t s) {
      return xnn_define_leaky_relu(s, leaky_alpha, id, to, 0);
    });
    out = activated;
  }
  set(n, out);
}

void Builder::op_max_pool(const TfjsNode& n) {
  const Tensor* input = tensor_or_null(n, 0);
  if (!input) throw Unsupported("MaxPool of a constant");
  const std::uint32_t in = nhwc(*input, n);
  const TfjsAttr* ksize = n.find("ksize");
  if (!ksize || ksize->list_i.size() != 4 || ksize->list_i[0] != 1 || ksize->list_i[3] != 1)
    throw Unsupported("MaxPool other than over height and width");
  const ConvParams p = conv_params(n);
  const auto in_shape = input->layout.logical_shape();
  const std::int64_t kh = ksize->list_i[1], kw = ksize->list_i[2];
  if (kh < 1 || kw < 1 || kh > 255 || kw > 255) throw Unsupported("MaxPool window out of range");
  const std::int64_t oh = conv_output_size(in_shape[1], kh, p.stride_h, 1, p.same);
  const std::int64_t ow = conv_output_size(in_shape[2], kw, p.stride_w, 1, p.same);
  if (oh <= 0 || ow <= 0) throw ShapeMismatch("MaxPool window larger than its input");
  const std::vector<std::int64_t> out_shape = {in_shape[0], oh, ow, in_shape[3]};
  Tensor out{define_tensor(std::vector<std::size_t>(out_shape.begin(), out_shape.end())),
             identity_layout(out_shape)};
  const auto u = [](std::int64_t v) { return static_cast<std::uint32_t>(v); };
  emit(n, "a max pooling", {in}, out.id, [=, id = out.id](xnn_subgraph_t s) {
    return xnn_define_max_pooling_2d(s, 0, 0, 0, 0, u(kh), u(kw), u(p.stride_h), u(p.stride_w), 1,
                                     1, -kInf, kInf, in, id,
                                     p.same ? XNN_FLAG_TENSORFLOW_SAME_PADDING : 0);
  });
  set(n, out);
}

// Mean over the two spatial axes of a 4-D value: global average pooling.
void Builder::op_mean(const TfjsNode& n) {
  const Tensor* input = tensor_or_null(n, 0);
  if (!input) throw Unsupported("Mean of a constant");
  const Layout& l = input->layout;
  auto axes = ints(n, 1);
  for (auto& a : axes) a = normalise_axis(a, l.groups.size());
  std::set<int> physical_axes;
  for (const auto a : axes)
    for (const int p : non_unit(l, l.groups[static_cast<std::size_t>(a)])) physical_axes.insert(p);
  if (l.physical.size() != 4 ||
      !std::includes(std::set<int>{1, 2}.begin(), std::set<int>{1, 2}.end(), physical_axes.begin(),
                     physical_axes.end()))
    throw Unsupported("Mean other than over height and width");
  Layout layout = l;
  layout.physical[1] = layout.physical[2] = 1;
  Tensor out{define_tensor(layout.physical), layout};
  emit(n, "a global average pooling", {input->id}, out.id,
       [in = input->id, id = out.id](xnn_subgraph_t s) {
         return xnn_define_global_average_pooling_2d(s, -kInf, kInf, in, id, 0);
       });
  Value v = out;
  const TfjsAttr* keep = n.find("keep_dims");
  if (!keep || !keep->b) {
    std::vector<std::int64_t> shape = layout.logical_shape();
    drop_unit_axes(v, axes, shape);
  }
  set(n, std::move(v));
}

void Builder::op_pad(const TfjsNode& n) {
  const Tensor* input = tensor_or_null(n, 0);
  if (!input) throw Unsupported(n.op + " of a constant");
  const Layout& l = input->layout;
  const auto pads = ints(n, 1);
  if (pads.size() != 2 * l.groups.size()) throw ShapeMismatch(n.op + " paddings do not match");
  float fill = 0.0f;
  if (n.op == "PadV2") {
    const Const& c = constant(n, 2);
    if (c.v.size() != 1) throw ShapeMismatch("PadV2 value is not a scalar");
    fill = static_cast<float>(c.v[0]);
  }
  Layout layout = l;
  std::vector<std::size_t> pre(l.physical.size(), 0), post(l.physical.size(), 0);
  for (std::size_t a = 0; a < l.groups.size(); ++a) {
    const std::int64_t before = pads[2 * a], after = pads[2 * a + 1];
    if (before < 0 || after < 0 || before > 4096 || after > 4096)
      throw Unsupported(n.op + " by a negative or huge amount");
    if (before == 0 && after == 0) continue;
    if (l.groups[a].size() != 1) throw Unsupported(n.op + " of an axis that is not one axis");
    const auto p = static_cast<std::size_t>(l.groups[a][0]);
    pre[p] = static_cast<std::size_t>(before);
    post[p] = static_cast<std::size_t>(after);
    layout.physical[p] += pre[p] + post[p];
  }
  Tensor out{define_tensor(layout.physical), layout};
  emit(n, "a padding", {input->id}, out.id,
       [pre, post, fill, in = input->id, id = out.id](xnn_subgraph_t s) {
         return xnn_define_static_constant_pad(s, pre.data(), post.data(), fill, in, id, 0);
       });
  set(n, out);
}

void Builder::op_resize_bilinear(const TfjsNode& n) {
  const Tensor* input = tensor_or_null(n, 0);
  if (!input) throw Unsupported("ResizeBilinear of a constant");
  const std::uint32_t in = nhwc(*input, n);
  const auto size = ints(n, 1);
  if (size.size() != 2 || size[0] < 1 || size[1] < 1 || size[0] > 16384 || size[1] > 16384)
    throw ShapeMismatch("ResizeBilinear size " + shape_text(size));
  const TfjsAttr* align = n.find("align_corners");
  const TfjsAttr* half = n.find("half_pixel_centers");
  const bool align_corners = align && align->b, half_pixel = half && half->b;
  if (align_corners && half_pixel) throw Unsupported("ResizeBilinear with both corner modes");
  // XNNPACK's default is TensorFlow's half_pixel_centers; "legacy" is TF's original mode.
  const std::uint32_t flags = align_corners ? XNN_FLAG_ALIGN_CORNERS
                              : half_pixel  ? 0
                                            : XNN_FLAG_TENSORFLOW_LEGACY_MODE;
  const auto in_shape = input->layout.logical_shape();
  const std::vector<std::int64_t> out_shape = {in_shape[0], size[0], size[1], in_shape[3]};
  Tensor out{define_tensor(std::vector<std::size_t>(out_shape.begin(), out_shape.end())),
             identity_layout(out_shape)};
  emit(n, "a bilinear resize", {in}, out.id,
       [in, flags, h = static_cast<std::size_t>(size[0]), w = static_cast<std::size_t>(size[1]),
        id = out.id](xnn_subgraph_t s) {
         return xnn_define_static_resize_bilinear_2d(s, h, w, in, id, flags);
       });
  set(n, out);
}

// A split along the physical channel axis of a 4-D value: one 1×1 convolution per part whose
// weights pick that part's channels (exact: every output is 1·x plus zeros).
void Builder::op_split(const TfjsNode& n) {
  const bool v2 = n.op == "SplitV";
  const std::size_t data_input = v2 ? 0 : 1;
  const Tensor* input = tensor_or_null(n, data_input);
  if (!input) throw Unsupported(n.op + " of a constant");
  const Layout& l = input->layout;
  const auto axis_value = ints(n, v2 ? 2 : 0);
  if (axis_value.size() != 1) throw ShapeMismatch(n.op + " axis is not a scalar");
  const auto axis = static_cast<std::size_t>(normalise_axis(axis_value[0], l.groups.size()));
  const std::int64_t total = l.logical_shape()[axis];
  std::vector<std::int64_t> sizes;
  if (v2) {
    sizes = ints(n, 1);
    std::int64_t known = 0;
    int unknown = -1;
    for (std::size_t i = 0; i < sizes.size(); ++i) {
      if (sizes[i] == -1 && unknown < 0)
        unknown = static_cast<int>(i);
      else if (sizes[i] < 0)
        throw ShapeMismatch("SplitV size " + std::to_string(sizes[i]));
      else
        known += sizes[i];
    }
    if (unknown >= 0) sizes[static_cast<std::size_t>(unknown)] = total - known;
  } else {
    const TfjsAttr* num = n.find("num_split");
    const std::int64_t parts = num ? num->i : 0;
    if (parts < 1 || total % parts) throw ShapeMismatch("Split into " + std::to_string(parts));
    sizes.assign(static_cast<std::size_t>(parts), total / parts);
  }
  if (std::accumulate(sizes.begin(), sizes.end(), std::int64_t{0}) != total)
    throw ShapeMismatch(n.op + " sizes do not add up to " + std::to_string(total));
  if (l.physical.size() != 4 || l.groups[axis].size() != 1 || l.groups[axis][0] != 3)
    throw Unsupported(n.op + " along an axis other than the channels");
  const std::size_t channels = l.physical[3];
  std::size_t offset = 0;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    const auto size = static_cast<std::size_t>(sizes[k]);
    std::vector<float> pick(size * channels, 0.0f);
    for (std::size_t o = 0; o < size; ++o) pick[o * channels + offset + o] = 1.0f;
    offset += size;
    const std::vector<std::size_t> filter_dims = {size, 1, 1, channels};
    const std::uint32_t filter = define_static(std::move(pick), filter_dims);
    const std::vector<std::size_t> bias_dims = {size};
    const std::uint32_t bias = define_static(std::vector<float>(size, 0.0f), bias_dims);
    Layout layout = l;
    layout.physical[3] = size;
    Tensor out{define_tensor(layout.physical), layout};
    emit(n, "a channel selection", {input->id}, out.id,
         [=, in = input->id, id = out.id](xnn_subgraph_t s) {
           return xnn_define_convolution_2d(s, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, channels, size,
                                            -kInf, kInf, in, filter, bias, id, 0);
         });
    set(n, out, static_cast<int>(k));
  }
}

// ---- ops: constants only ----------------------------------------------------------------------

void Builder::op_sparse_to_dense(const TfjsNode& n) {
  const Const& indices = constant(n, 0);
  const auto shape = ints(n, 1);
  const Const& values = constant(n, 2);
  const Const& fill = constant(n, 3);
  if (fill.v.size() != 1 || product(shape) > (1u << 24))
    throw ShapeMismatch("SparseToDense default or shape");
  Const out{shape, std::vector<double>(product(shape), fill.v[0]), values.is_int};
  const std::size_t rank = shape.size();
  const std::size_t count = indices.shape.empty() ? 1 : static_cast<std::size_t>(indices.shape[0]);
  const auto strides = row_major_strides(shape);
  for (std::size_t i = 0; i < count; ++i) {
    std::size_t offset = 0;
    for (std::size_t a = 0; a < rank; ++a) {
      const std::size_t at = i * rank + a;
      if (at >= indices.v.size()) throw ShapeMismatch("SparseToDense indices");
      const auto index = static_cast<std::int64_t>(indices.v[at]);
      if (index < 0 || index >= shape[a]) throw ShapeMismatch("SparseToDense index out of range");
      offset += strides[a] * static_cast<std::size_t>(index);
    }
    const double v = values.v.size() == 1 ? values.v[0] : i < values.v.size() ? values.v[i] : 0;
    out.v[offset] = v;
  }
  set(n, std::move(out));
}

void Builder::op_gather(const TfjsNode& n) {
  const Const& params = constant(n, 0);
  const Const& indices = constant(n, 1);
  const auto axis_value = ints(n, 2);
  if (axis_value.size() != 1) throw ShapeMismatch("GatherV2 axis is not a scalar");
  const auto axis = static_cast<std::size_t>(normalise_axis(axis_value[0], params.shape.size()));
  Const out{{}, {}, params.is_int};
  out.shape.assign(params.shape.begin(), params.shape.begin() + static_cast<long>(axis));
  out.shape.insert(out.shape.end(), indices.shape.begin(), indices.shape.end());
  out.shape.insert(out.shape.end(), params.shape.begin() + static_cast<long>(axis) + 1,
                   params.shape.end());
  const auto strides = row_major_strides(params.shape);
  for_each_index(out.shape, [&](std::size_t, std::span<const std::int64_t> idx) {
    std::size_t index_offset = 0;
    for (std::size_t a = 0; a < indices.shape.size(); ++a)
      index_offset = index_offset * static_cast<std::size_t>(indices.shape[a]) +
                     static_cast<std::size_t>(idx[axis + a]);
    const auto picked = static_cast<std::int64_t>(indices.v.at(index_offset));
    if (picked < 0 || picked >= params.shape[axis]) throw ShapeMismatch("GatherV2 index");
    std::size_t offset = 0;
    for (std::size_t a = 0; a < params.shape.size(); ++a) {
      const std::int64_t i = a < axis    ? idx[a]
                             : a == axis ? picked
                                         : idx[a - 1 + indices.shape.size()];
      offset += strides[a] * static_cast<std::size_t>(i);
    }
    out.v.push_back(params.v[offset]);
  });
  set(n, std::move(out));
}

// ---- build ------------------------------------------------------------------------------------

BuiltGraph Builder::build() {
  xnn_subgraph_t raw = nullptr;
  if (xnn_create_subgraph(0, 0, &raw) != xnn_status_success)
    throw std::runtime_error("XNNPACK could not create a subgraph (not initialised?)");
  out_.subgraph.reset(raw);
  const auto order = topological_order();
  count_consumers(order);
  plan_bias_folds(order);
  for (const TfjsNode* n : order) {
    try {
      if (n->name == input_node_) {
        op_placeholder(*n);
        continue;
      }
      const auto handler = handlers().find(n->op);
      if (handler == handlers().end()) throw Unsupported("operation " + n->op);
      (this->*handler->second)(*n);
    } catch (const ShapeMismatch& e) {
      throw std::invalid_argument("input " + shape_text(input_shape_) + " does not fit " +
                                  model_.file.string() + " at node '" + n->name + "' (" + n->op +
                                  "): " + e.what());
    } catch (const NeedsTranspose&) {
      if (!nchw_input_ && input_shape_.size() == 4) throw;  // build_subgraph retries
      fail_model(model_.file, "the XNNPACK runtime cannot run node '" + n->name + "' (" + n->op +
                                  "): its input would need a transpose");
    } catch (const ModelError&) {
      throw;
    } catch (const std::invalid_argument&) {
      throw;
    } catch (const std::exception& e) {
      fail_model(model_.file, "the XNNPACK runtime cannot run node '" + n->name + "' (" + n->op +
                                  "): " + e.what());
    }
  }
  for (const std::string& output : outputs_) {
    const auto* t = std::get_if<Tensor>(&value(output));
    if (!t)
      fail_model(model_.file, "output '" + output + "' is a constant, not computed by the network");
    // A copy into a value of its own, marked as an output (the producing value was defined
    // before anyone knew it would be one).
    const std::uint32_t id =
        define_tensor(t->layout.physical, nullptr, XNN_VALUE_FLAG_EXTERNAL_OUTPUT);
    const TfjsNode& node = *by_name_.at(tfjs_base_name(output));
    emit(node, "the copy of output '" + output + "'", {t->id}, id,
         [dims = t->layout.physical, in = t->id, id](xnn_subgraph_t s) {
           return xnn_define_static_reshape(s, dims.size(), dims.data(), in, id, 0);
         });
    external_outputs_.push_back(id);
    out_.output_ids.push_back(id);
    out_.output_layouts.push_back(t->layout);
  }
  define_live_nodes();
  return std::move(out_);
}

}  // namespace

std::vector<std::int64_t> Layout::logical_shape() const {
  std::vector<std::int64_t> shape;
  for (const auto& group : groups) {
    std::int64_t size = 1;
    for (const int p : group)
      size *= static_cast<std::int64_t>(physical[static_cast<std::size_t>(p)]);
    shape.push_back(size);
  }
  return shape;
}

BuiltGraph build_subgraph(const TfjsModel& model, const GraphCut& cut,
                          std::span<const std::int64_t> input_shape) {
  try {
    return Builder(model, cut, input_shape, false).build();
  } catch (const NeedsTranspose&) {
    return Builder(model, cut, input_shape, true).build();
  }
}

GraphCut make_cut(const TfjsModel& model, std::span<const std::string> outputs,
                  const std::string& requested_input) {
  const std::string input_node = tfjs_resolve(model, requested_input);
  GraphCut cut{{outputs.begin(), outputs.end()}, input_node};
  const std::set<std::string> keep = tfjs_ancestors(model, outputs, input_node);
  if (!input_node.empty() && !keep.contains(input_node))
    fail_model(model.file, "the outputs do not depend on the input node '" + input_node + "'");
  for (const TfjsNode& n : model.nodes) {
    if (n.op != "Placeholder" || !keep.contains(n.name) || n.name == input_node) continue;
    if (!cut.input.empty())
      fail_model(model.file, "the outputs need two inputs ('" + cut.input + "', '" + n.name +
                                 "'); the runtime feeds one");
    cut.input = n.name;
  }
  if (cut.input.empty()) fail_model(model.file, "the outputs depend on no input placeholder");
  return cut;
}

void check_supported(const TfjsModel& model, const GraphCut& cut) {
  const std::set<std::string> keep = tfjs_ancestors(model, cut.outputs, cut.input);
  std::map<std::string, std::string> refused;  // what -> first node
  for (const TfjsNode& n : model.nodes) {
    if (!keep.contains(n.name) || n.name == cut.input) continue;
    if (!Builder::handlers().contains(n.op)) {
      refused.try_emplace(n.op, n.name);
      continue;
    }
    const TfjsAttr* format = n.find("data_format");
    if (format && format->kind == TfjsAttr::Kind::s && format->s != "NHWC")
      refused.try_emplace(n.op + " in " + format->s + " layout", n.name);
    if (n.op != "_FusedConv2D" && n.op != "FusedDepthwiseConv2dNative") continue;
    const auto ops = tfjs_fused_ops(n);
    const bool ok =
        !ops.empty() && ops.size() <= 2 && ops[0] == "BiasAdd" &&
        (ops.size() == 1 || ops[1] == "Relu" || ops[1] == "Relu6" || ops[1] == "LeakyRelu");
    if (!ok) {
      std::string list;
      for (const auto& op : ops) list += (list.empty() ? "" : ",") + op;
      refused.try_emplace(n.op + " fusing [" + list + "]", n.name);
    }
  }
  if (refused.empty()) return;
  std::string what = "unsupported operation(s) on the way to the requested outputs:";
  for (const auto& [reason, name] : refused) what += " " + reason + " (node '" + name + "');";
  fail_model(model.file, what +
                             " the XNNPACK runtime converts the operations of MoveNet "
                             "(MultiPose, Lightning, Thunder), nanodet and mb3-centernet");
}

}  // namespace mocap::detect::xnn
