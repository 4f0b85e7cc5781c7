// The TF.js graph-model loader on a tiny hand-written model (no download needed): float16
// weights dequantised, the int32 input Cast dropped, _FusedConv2D split so that cv::dnn runs it,
// and a clear error naming every operation it does not convert. Also its protobuf encoder.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/dnn.hpp>

#include "detect/protobuf_writer.hpp"
#include "detect/tfjs_graph.hpp"
#include "tiny_model.hpp"

namespace mocap::detect {
namespace {

TEST(HalfToFloat, DecodesNormalSubnormalAndSpecialValues) {
  EXPECT_EQ(half_to_float(0x3C00), 1.0f);
  EXPECT_EQ(half_to_float(0xC000), -2.0f);
  EXPECT_EQ(half_to_float(0x7BFF), 65504.0f);
  EXPECT_EQ(half_to_float(0x0001), std::ldexp(1.0f, -24));
  EXPECT_EQ(half_to_float(0x3555), 0.333251953125f);
  EXPECT_EQ(half_to_float(0x8000), -0.0f);
  EXPECT_TRUE(std::isinf(half_to_float(0x7C00)));
  EXPECT_TRUE(std::isnan(half_to_float(0x7E00)));
}

TEST(ProtoMessage, EncodesTheWireFormat) {
  ProtoMessage m;
  m.add_varint(1, 300);
  m.add_bytes(2, "ab");
  m.add_float(3, 1.0f);
  m.add_int64(4, -1);
  const std::string want = std::string("\x08\xac\x02", 3) +
                           "\x12\x02"
                           "ab" +
                           std::string("\x1d\x00\x00\x80\x3f", 5) + "\x20" +
                           std::string(9, '\xff') + "\x01";
  EXPECT_EQ(m.bytes(), want);
}

TEST(TfjsGraph, FusedConvolutionRunsInCvDnnWithDequantisedWeights) {
  const TinyModel model;
  const std::vector<std::string> outputs = {"conv"};
  const std::string graph = tfjs_to_graphdef(model.json, outputs);
  cv::dnn::Net net = cv::dnn::readNetFromTensorflow(graph.data(), graph.size());
  // NCHW 1×3×1×2: pixel 0 is RGB (20, 40, 10), pixel 1 is black.
  const int shape[] = {1, 3, 1, 2};
  cv::Mat blob(4, shape, CV_32F);
  const float rgb[] = {20, 0, 40, 0, 10, 0};
  std::copy(std::begin(rgb), std::end(rgb), blob.ptr<float>());
  net.setInput(blob);
  const cv::Mat out = net.forward("conv");
  ASSERT_EQ(out.total(), 4u);
  const float* o = out.ptr<float>();  // NCHW: channel 0 at both pixels, then channel 1
  EXPECT_FLOAT_EQ(o[0], 20.0f);       // 20 + 20 - 10 - 10
  EXPECT_FLOAT_EQ(o[1], 0.0f);        // ReLU of -10
  EXPECT_FLOAT_EQ(o[2], 21.0f);
  EXPECT_FLOAT_EQ(o[3], 1.0f);
}

TEST(TfjsGraph, NamesEveryUnsupportedOperation) {
  const TinyModel model;
  const std::vector<std::string> outputs = {"topk", "pack"};
  try {
    tfjs_to_graphdef(model.json, outputs);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("TopKV2 (node 'topk')"), std::string::npos) << what;
    EXPECT_NE(what.find("Pack (node 'pack')"), std::string::npos) << what;
    EXPECT_NE(what.find("tiny.json"), std::string::npos) << what;
  }
}

TEST(TfjsGraph, RefusesUnknownOutputsAndShortWeights) {
  const std::vector<std::string> missing = {"nothing"};
  EXPECT_THROW(tfjs_to_graphdef(TinyModel().json, missing), std::runtime_error);
  const std::vector<std::string> conv = {"conv"};
  EXPECT_THROW(tfjs_to_graphdef(TinyModel(tiny_weights().substr(0, 6)).json, conv),
               std::runtime_error);
  EXPECT_THROW(tfjs_to_graphdef("/nonexistent/model.json", conv), std::runtime_error);
}

TEST(TfjsGraph, ErrorsInsideTheGraphNameTheFile) {
  std::string text = kTinyModel;
  const std::string conv_type = R"("T": {"type": "DT_FLOAT"}, "strides")";
  text.replace(text.find(conv_type), conv_type.size(),
               R"("T": {"type": "DT_COMPLEX64"}, "strides")");
  const TinyModel model(tiny_weights(), text);
  const std::vector<std::string> conv = {"conv"};
  try {
    tfjs_to_graphdef(model.json, conv);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("tiny.json"), std::string::npos) << what;
    EXPECT_NE(what.find("DT_COMPLEX64"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace mocap::detect
