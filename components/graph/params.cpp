#include "graph/params.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mocap::graph {

std::string_view name(ParamType type) {
  switch (type) {
    case ParamType::boolean:
      return "bool";
    case ParamType::integer:
      return "int";
    case ParamType::number:
      return "number";
    case ParamType::string:
      return "string";
  }
  return "?";
}

std::string to_text(const ParamValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>) {
          return v ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::string>) {
          return v;
        } else {
          std::ostringstream out;
          out << v;
          return out.str();
        }
      },
      value);
}

namespace {

[[noreturn]] void fail(const ParamSpec& spec, std::string_view text, std::string_view expected) {
  throw std::invalid_argument("parameter '" + spec.name + "': expected " + std::string(expected) +
                              ", got '" + std::string(text) + "'");
}

bool parse_bool(const ParamSpec& spec, std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "true" || lower == "yes" || lower == "on" || lower == "1") return true;
  if (lower == "false" || lower == "no" || lower == "off" || lower == "0") return false;
  fail(spec, text, "true or false");
}

template <class T>
T parse_number(const ParamSpec& spec, std::string_view text, std::string_view expected) {
  T value{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) fail(spec, text, expected);
  return value;
}

}  // namespace

void check_range(const ParamSpec& spec, const ParamValue& value) {
  double number = 0;
  if (const auto* i = std::get_if<std::int64_t>(&value)) {
    number = static_cast<double>(*i);
  } else if (const auto* d = std::get_if<double>(&value)) {
    number = *d;
    if (!std::isfinite(number)) fail(spec, to_text(value), "a finite number");
  } else {
    return;
  }
  const bool low = spec.range.min && number < *spec.range.min;
  const bool high = spec.range.max && number > *spec.range.max;
  if (low || high) {
    std::ostringstream expected;
    expected << "a value in [" << (spec.range.min ? std::to_string(*spec.range.min) : "-inf")
             << ", " << (spec.range.max ? std::to_string(*spec.range.max) : "inf") << "]";
    fail(spec, to_text(value), expected.str());
  }
}

ParamValue parse_param(const ParamSpec& spec, std::string_view text) {
  ParamValue value;
  switch (spec.type) {
    case ParamType::boolean:
      value = parse_bool(spec, text);
      break;
    case ParamType::integer:
      value = parse_number<std::int64_t>(spec, text, "a whole number");
      break;
    case ParamType::number:
      value = parse_number<double>(spec, text, "a number");
      break;
    case ParamType::string:
      value = std::string(text);
      break;
  }
  check_range(spec, value);
  return value;
}

}  // namespace mocap::graph
