#pragma once
// Turns a TensorFlow.js graph model (model.json + its weight files) into the bytes of a
// TensorFlow GraphDef that OpenCV's TF importer (cv::dnn::readNetFromTensorflow) reads.
//
// Why a GraphDef and not cv::dnn::Net::addLayer: a TF.js model.json *is* a GraphDef written as
// protobuf-JSON, so rewriting it node for node keeps the model's own graph, and OpenCV's importer
// then does the delicate parts it already gets right and that a hand-built net would have to
// repeat: TF's asymmetric SAME padding of stride-2 convolutions, HWIO -> OIHW weight reordering,
// folding BiasAdd into the convolution, and turning the Shape -> StridedSlice -> Mul ->
// ResizeBilinear chains into one size-independent ×2 Resize layer.
//
// The rewrite keeps only the ancestors of the requested outputs, writes every weight as a float32
// Const (float16-quantised weights dequantised), feeds the input as float (a Cast from the int32
// input placeholder is dropped) and splits the ops the TF.js converter fuses and OpenCV does not
// know (_FusedConv2D, FusedDepthwiseConv2dNative) into Conv2D/DepthwiseConv2dNative -> BiasAdd
// [-> Relu | Relu6]. Any other op outside the short list it has been checked with is refused by
// name, before OpenCV sees the graph.

#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "detect/tfjs_model.hpp"

namespace mocap::detect {

// Throws std::runtime_error naming the file and the problem: unreadable or inconsistent files,
// an output missing from the graph, or every unsupported operation the outputs need.
// `input_node` (empty: the placeholder) is fed from outside instead, as a float placeholder of
// that name; what it depends on is left out.
std::string tfjs_to_graphdef(const std::filesystem::path& model_json,
                             std::span<const std::string> outputs,
                             std::string_view input_node = {});
std::string tfjs_to_graphdef(const TfjsModel& model, std::span<const std::string> outputs,
                             std::string_view input_node = {});

// The cv::dnn layer that produces the result of a split _FusedConv2D node without activation
// (OpenCV names a Conv2D + BiasAdd pair after the Conv2D node).
std::string fused_conv_layer_name(std::string_view fused_node);

}  // namespace mocap::detect
