#pragma once
// Typed node parameters: declared by a node's contract (type, default, range, one-line doc),
// given in graph files or on the command line as text, checked before any node starts.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>

namespace mocap::graph {

enum class ParamType { boolean, integer, number, string };

using ParamValue = std::variant<bool, std::int64_t, double, std::string>;

std::string_view name(ParamType type);
std::string to_text(const ParamValue& value);

template <class T>
constexpr ParamType param_type_of() {
  if constexpr (std::is_same_v<T, bool>) {
    return ParamType::boolean;
  } else if constexpr (std::is_integral_v<T>) {
    return ParamType::integer;
  } else if constexpr (std::is_floating_point_v<T>) {
    return ParamType::number;
  } else {
    static_assert(std::is_convertible_v<T, std::string>,
                  "parameters are bool, integer, number or string");
    return ParamType::string;
  }
}

struct Range {
  std::optional<double> min, max;  // inclusive; numbers and integers only
};

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::string;
  std::optional<ParamValue> fallback;  // empty: the parameter is required
  Range range;
  std::string doc;

  bool required() const { return !fallback.has_value(); }
};

// Parses `text` as the declared type and checks the range. Throws std::invalid_argument with a
// message that names the parameter and says what was expected.
ParamValue parse_param(const ParamSpec& spec, std::string_view text);
// Checks an already typed value (a default) against the range; same errors as parse_param.
void check_range(const ParamSpec& spec, const ParamValue& value);

}  // namespace mocap::graph
