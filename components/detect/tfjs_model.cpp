#include "detect/tfjs_model.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

namespace mocap::detect {
namespace {

using nlohmann::json;

std::string read_file(const std::filesystem::path& path, const std::filesystem::path& model) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_model(model, "cannot read " + path.string());
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

// protobuf-JSON AttrValue (exactly one of its fields set).
TfjsAttr read_attr(const std::string& key, const json& value) {
  TfjsAttr a;
  if (value.contains("list")) {
    a.kind = TfjsAttr::Kind::list;
    const json& list = value["list"];
    for (const json& s : list.value("s", json::array()))
      a.list_s.push_back(base64_decode(s.get<std::string>()));
    for (const json& i : list.value("i", json::array())) a.list_i.push_back(to_int64(i));
    for (const json& f : list.value("f", json::array())) a.list_f.push_back(f.get<float>());
    for (const json& t : list.value("type", json::array()))
      a.list_type.push_back(dtype_code(t.get<std::string>()));
  } else if (value.contains("s")) {
    a.kind = TfjsAttr::Kind::s;
    a.s = base64_decode(value["s"].get<std::string>());
  } else if (value.contains("i")) {
    a.kind = TfjsAttr::Kind::i;
    a.i = to_int64(value["i"]);
  } else if (value.contains("f")) {
    a.kind = TfjsAttr::Kind::f;
    a.f = value["f"].get<float>();
  } else if (value.contains("b")) {
    a.kind = TfjsAttr::Kind::b;
    a.b = value["b"].get<bool>();
  } else if (value.contains("type")) {
    a.kind = TfjsAttr::Kind::type;
    a.type = dtype_code(value["type"].get<std::string>());
  } else if (value.contains("shape")) {
    a.kind = TfjsAttr::Kind::shape;
    const json& shape = value["shape"];
    a.unknown_rank = shape.value("unknownRank", false);
    for (const json& dim : shape.value("dim", json::array()))
      a.shape.push_back(to_int64(dim.value("size", json("0"))));
  } else if (value.contains("tensor")) {
    a.kind = TfjsAttr::Kind::tensor;
  } else {
    throw std::runtime_error("attribute '" + key + "' has a form the loader does not convert");
  }
  return a;
}

std::vector<TfjsNode> read_nodes(const json& topology) {
  std::vector<TfjsNode> nodes;
  for (const json& n : topology.at("node")) {
    TfjsNode node{n.at("name"), n.at("op"), n.value("input", std::vector<std::string>{}), {}};
    const json attr = n.value("attr", json::object());
    for (const auto& [key, value] : attr.items()) node.attr.emplace(key, read_attr(key, value));
    nodes.push_back(std::move(node));
  }
  return nodes;
}

// Element count of a weight shape, refusing negative dimensions and counts beyond `limit` (the
// bytes left in the weight data bound every honest count).
std::size_t element_count(const std::vector<std::int64_t>& shape, std::size_t limit,
                          const std::string& name, const std::filesystem::path& model) {
  std::size_t n = 1;
  for (const std::int64_t d : shape) {
    if (d < 0) fail_model(model, "weight '" + name + "' has a negative dimension");
    if (d != 0 && n > limit / static_cast<std::size_t>(d))
      fail_model(model, "weight data shorter than its manifest (weight '" + name + "')");
    n *= static_cast<std::size_t>(d);
  }
  return n;
}

// Reads one manifest entry from `data` at `offset`, advancing it.
TfjsWeight read_weight(const json& spec, std::string_view data, std::size_t& offset,
                       const std::filesystem::path& model) {
  TfjsWeight w;
  const std::string name = spec.at("name");
  w.shape = spec.at("shape").get<std::vector<std::int64_t>>();
  const std::string dtype = spec.at("dtype");
  const std::string stored =
      spec.contains("quantization") ? spec["quantization"].at("dtype").get<std::string>() : dtype;
  const std::size_t width = stored == "float16" ? 2 : 4;
  const std::size_t n = element_count(w.shape, (data.size() - offset) / width, name, model);
  const std::size_t bytes = n * width;
  if (offset + bytes > data.size()) fail_model(model, "weight data shorter than its manifest");
  const char* src = data.data() + offset;
  offset += bytes;
  if (dtype == "int32" && stored == "int32") {
    w.is_int = true;
    w.ints.resize(n);
    if (bytes > 0) std::memcpy(w.ints.data(), src, bytes);  // an empty tensor has no buffer
  } else if (dtype == "float32" && stored == "float32") {
    w.floats.resize(n);
    if (bytes > 0) std::memcpy(w.floats.data(), src, bytes);
  } else if (dtype == "float32" && stored == "float16") {
    w.floats.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      std::uint16_t h;
      std::memcpy(&h, src + 2 * i, 2);
      w.floats[i] = half_to_float(h);
    }
  } else {
    fail_model(model, "weight '" + name + "' is " + dtype + " stored as " + stored +
                          ", which the loader does not read");
  }
  return w;
}

// `data`: every weight file of the manifest, concatenated in manifest order.
std::unordered_map<std::string, TfjsWeight> read_weights(const json& manifest,
                                                         std::string_view data,
                                                         const std::filesystem::path& model) {
  std::unordered_map<std::string, TfjsWeight> weights;
  std::size_t offset = 0;
  for (const json& group : manifest)
    for (const json& spec : group.at("weights"))
      weights[spec.at("name")] = read_weight(spec, data, offset, model);
  if (offset != data.size()) fail_model(model, "weight files longer than their manifest");
  return weights;
}

// The scalar int32 value of a Const weight, or `fallback`.
std::int64_t const_scalar(const std::unordered_map<std::string, TfjsWeight>& weights,
                          const std::string& name, std::int64_t fallback) {
  const auto it = weights.find(name);
  if (it == weights.end() || !it->second.is_int || it->second.ints.size() != 1) return fallback;
  return it->second.ints[0];
}

// True for Unpack(axis 0, num 1) and Squeeze(squeeze_dims [0]): both drop a leading axis of one.
bool drops_leading_unit_axis(const TfjsNode& n) {
  const TfjsAttr* axis = n.find("axis");
  const TfjsAttr* num = n.find("num");
  const TfjsAttr* dims = n.find("squeeze_dims");
  if (n.op == "Unpack") return num && num->i == 1 && (!axis || axis->i == 0);
  return n.op == "Squeeze" && dims && dims->list_i == std::vector<std::int64_t>{0};
}

// ExpandDims(axis 0) of such a node is its input again: consumers read that input directly.
void bypass_batch_of_one_noops(TfjsModel& model) {
  std::unordered_map<std::string, const TfjsNode*> by_name;
  for (const TfjsNode& n : model.nodes) by_name[n.name] = &n;
  std::unordered_map<std::string, std::string> replacement;
  for (const TfjsNode& n : model.nodes) {
    if (n.op != "ExpandDims" || n.inputs.size() != 2 ||
        const_scalar(model.weights, tfjs_base_name(n.inputs[1]), -1) != 0)
      continue;
    const auto src = by_name.find(n.inputs[0]);  // output 0 only
    if (src == by_name.end() || !drops_leading_unit_axis(*src->second) ||
        src->second->inputs.empty())
      continue;
    replacement[n.name] = src->second->inputs[0];
  }
  const auto resolve = [&](std::string name) {
    for (int hops = 0; hops < 64; ++hops) {  // chains of bypasses; 64 bounds a cycle
      const auto it = replacement.find(name);
      if (it == replacement.end()) break;
      name = it->second;
    }
    return name;
  };
  for (TfjsNode& n : model.nodes)
    for (std::string& input : n.inputs) input = resolve(input);
  for (const auto& [name, target] : replacement) model.bypassed[name] = resolve(target);
}

json parse_json(std::string_view text, const std::filesystem::path& name) {
  json model;
  try {
    model = json::parse(text);
  } catch (const json::exception& e) {
    fail_model(name, std::string("not valid JSON: ") + e.what());
  }
  if (!model.is_object() || !model.contains("modelTopology") || !model.contains("weightsManifest"))
    fail_model(name, "not a TF.js graph model (no modelTopology or weightsManifest)");
  return model;
}

// Runs `f`, giving errors that do not name the file yet (JSON structure, numbers, data types) its
// name.
template <class F>
auto naming(const std::filesystem::path& name, F f) {
  try {
    return f();
  } catch (const ModelError&) {
    throw;
  } catch (const std::exception& e) {
    fail_model(name, e.what());
  }
}

TfjsModel build_model(const json& model, std::string_view weights,
                      const std::filesystem::path& name) {
  return naming(name, [&] {
    TfjsModel out;
    out.file = name;
    out.nodes = read_nodes(model.at("modelTopology"));
    out.weights = read_weights(model.at("weightsManifest"), weights, name);
    out.producer = model["modelTopology"].value("versions", json::object()).value("producer", 808);
    bypass_batch_of_one_noops(out);
    return out;
  });
}

}  // namespace

void fail_model(const std::filesystem::path& file, const std::string& what) {
  throw ModelError("TF.js model " + file.string() + ": " + what);
}

const TfjsAttr* TfjsNode::find(std::string_view key) const {
  const auto it = attr.find(key);
  return it == attr.end() ? nullptr : &it->second;
}

TfjsModel read_tfjs_model(const std::filesystem::path& model_json) {
  const json model = parse_json(read_file(model_json, model_json), model_json);
  const std::string weights = naming(model_json, [&] {
    std::string data;
    for (const json& group : model.at("weightsManifest"))
      for (const json& path : group.at("paths"))
        data += read_file(model_json.parent_path() / path.get<std::string>(), model_json);
    return data;
  });
  return build_model(model, weights, model_json);
}

TfjsModel parse_tfjs_model(std::string_view model_json, std::string_view weights,
                           const std::filesystem::path& name) {
  return build_model(parse_json(model_json, name), weights, name);
}

TfjsModel tfjs_with_input_size(TfjsModel model, std::int64_t height, std::int64_t width) {
  const auto fail = [&](const std::string& why) {
    return ModelError(model.file.string() + ": cannot take a " + std::to_string(height) + " x " +
                      std::to_string(width) + " input: " + why);
  };
  TfjsAttr* declared = nullptr;
  for (TfjsNode& n : model.nodes) {
    if (n.op != "Placeholder") continue;
    const auto shape = n.attr.find("shape");
    if (declared || shape == n.attr.end() || shape->second.shape.size() != 4)
      throw fail("not one 4-D input");
    declared = &shape->second;
  }
  if (!declared || declared->shape[1] < 1 || declared->shape[2] < 1 || height < 1 || width < 1)
    throw fail("no input of a known size");
  const std::int64_t h0 = declared->shape[1], w0 = declared->shape[2];
  declared->shape[1] = height;
  declared->shape[2] = width;
  std::set<std::string> scaled;  // a size shared by several resizes is scaled once
  for (const TfjsNode& n : model.nodes) {
    if (n.op != "ResizeBilinear" || n.inputs.size() < 2) continue;
    const std::string name = tfjs_base_name(n.inputs[1]);
    const auto size = model.weights.find(name);
    // A size computed from the input's shape scales by itself.
    if (size == model.weights.end() || !scaled.insert(name).second) continue;
    auto& ints = size->second.ints;
    if (!size->second.is_int || ints.size() != 2) throw fail(n.name + ": a size not of 2 ints");
    if (ints[0] * height % h0 != 0 || ints[1] * width % w0 != 0)
      throw fail(n.name + ": its size does not scale to whole pixels");
    ints[0] = static_cast<std::int32_t>(ints[0] * height / h0);
    ints[1] = static_cast<std::int32_t>(ints[1] * width / w0);
  }
  return model;
}

std::string tfjs_resolve(const TfjsModel& model, const std::string& name) {
  const auto it = model.bypassed.find(name);
  return it == model.bypassed.end() ? name : it->second;
}

std::string tfjs_base_name(std::string_view input) {
  if (!input.empty() && input.front() == '^') input.remove_prefix(1);
  const auto colon = input.find(':');
  return std::string(input.substr(0, colon));
}

int tfjs_output_index(std::string_view input) {
  const auto colon = input.find(':');
  if (colon == std::string_view::npos) return 0;
  int index = 0;
  for (const char c : input.substr(colon + 1)) {
    if (c < '0' || c > '9' || index > 1'000'000) return -1;
    index = index * 10 + (c - '0');
  }
  return index;
}

std::set<std::string> tfjs_ancestors(const TfjsModel& model, std::span<const std::string> outputs,
                                     std::string_view input_node) {
  std::unordered_map<std::string, const TfjsNode*> by_name;
  for (const TfjsNode& n : model.nodes) by_name[n.name] = &n;
  std::set<std::string> keep;
  std::vector<std::string> todo;
  for (const std::string& out : outputs) todo.push_back(tfjs_base_name(out));
  while (!todo.empty()) {
    const std::string name = todo.back();
    todo.pop_back();
    if (!keep.insert(name).second) continue;
    const auto it = by_name.find(name);
    if (it == by_name.end()) fail_model(model.file, "the graph has no node '" + name + "'");
    if (name == input_node) continue;  // fed from outside
    for (const std::string& input : it->second->inputs) todo.push_back(tfjs_base_name(input));
  }
  return keep;
}

std::vector<std::string> tfjs_fused_ops(const TfjsNode& node) {
  const TfjsAttr* ops = node.find("fused_ops");
  return ops ? ops->list_s : std::vector<std::string>{};
}

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

}  // namespace mocap::detect
