#pragma once
// Internal to mocap_detect (only xnnpack_runner.cpp includes it): an XNNPACK subgraph built from a
// TF.js graph model for one input shape.
//
// XNNPACK's subgraph API (Debian's 2022 build) has fixed shapes, NHWC convolutions and no
// transpose, concatenate or slice, so the builder keeps a layout per tensor: how the TensorFlow
// (logical) tensor lies in the XNNPACK value (which physical axes, in which order, make each
// logical axis). Transpose, Reshape, ExpandDims, Squeeze and Unpack of unit axes then only relabel
// axes; an NCHW input (nanodet) is fed transposed to NHWC so that its convolutions see NHWC; the
// outputs are gathered into TensorFlow's row-major order on the host. Concatenation is zero
// padding plus addition (exact), a channel split a 1×1 selection convolution (exact for finite
// values). Shape arithmetic (Shape -> StridedSlice -> Mul of the upsampling chains, the
// SparseToDense reshapes of nanodet) is folded on the host.

#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <xnnpack.h>

#include "detect/tfjs_model.hpp"

namespace mocap::detect::xnn {

// How a logical tensor lies in an XNNPACK value: logical axis a is the row-major combination of
// the physical axes groups[a] (empty: an axis of size one).
struct Layout {
  std::vector<std::size_t> physical;
  std::vector<std::vector<int>> groups;

  std::vector<std::int64_t> logical_shape() const;
};

struct SubgraphDeleter {
  void operator()(xnn_subgraph* s) const { xnn_delete_subgraph(s); }
};
using SubgraphPtr = std::unique_ptr<xnn_subgraph, SubgraphDeleter>;

struct BuiltGraph {
  SubgraphPtr subgraph;
  std::uint32_t input_id = 0;
  Layout input_layout;  // of the fed tensor; feed in physical order
  std::vector<std::uint32_t> output_ids;
  std::vector<Layout> output_layouts;  // gather each into logical row-major order
  // Static data the subgraph points to (weights reordered, constants broadcast): must outlive
  // every runtime made from it.
  std::deque<std::vector<float>> arena;
};

// Which part of the model runs: from `input` (a node fed from outside: the placeholder, or a
// node cut there) to `outputs`.
struct GraphCut {
  std::vector<std::string> outputs;
  std::string input;
};

// The cut for `outputs`, fed at `input_node` or, when empty, at the one placeholder they need.
GraphCut make_cut(const TfjsModel& model, std::span<const std::string> outputs,
                  const std::string& input_node);

// The ops the builder converts: fails naming every op (and a node using it) it does not, and
// fused ops or attributes outside what it handles.
void check_supported(const TfjsModel& model, const GraphCut& cut);

// Builds the subgraph for `input_shape` (every size known). Throws std::invalid_argument when the
// shape does not fit the graph (naming the node), ModelError for what the builder cannot express.
BuiltGraph build_subgraph(const TfjsModel& model, const GraphCut& cut,
                          std::span<const std::int64_t> input_shape);

}  // namespace mocap::detect::xnn
