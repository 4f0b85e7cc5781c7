#pragma once
// Typed node parameters: declared by a node's contract (type, default, range or allowed values,
// one-line doc), given in graph files or on the command line as text, checked before any node
// starts. A parameter is a single value or a list of values of one type (a YAML sequence in a
// graph file, a comma list on the command line); a string parameter may be limited to a fixed set
// of choices.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

namespace mocap::graph {

enum class ParamType { boolean, integer, number, string };

using ParamValue = std::variant<bool, std::int64_t, double, std::string, std::vector<std::int64_t>,
                                std::vector<double>, std::vector<std::string>>;

std::string_view name(ParamType type);
// Single values as written in a graph file; lists as a comma list ("1,2,3").
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
  std::optional<double> min, max;  // inclusive; numbers and integers only (each item of a list)
};

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::string;  // of the value, or of each item of a list
  bool list = false;
  std::vector<std::string> choices{};  // strings only: the allowed values; empty: any
  std::optional<ParamValue> fallback;  // empty: the parameter is required
  Range range{};
  std::string doc{};

  bool required() const { return !fallback.has_value(); }
  // "int", "choice of live, full, off", "list of number", ...
  std::string type_text() const;
};

// Parses `text` as the declared type and checks the range or the choices; a list parameter takes
// a comma list. Throws std::invalid_argument with a message that names the parameter and says
// what was expected (for a choice, the allowed values and the nearest one to what was written).
ParamValue parse_param(const ParamSpec& spec, std::string_view text);
// A list parameter given as separate items (a YAML sequence); same checks and errors.
ParamValue parse_param_items(const ParamSpec& spec, const std::vector<std::string>& items);
// Checks an already typed value (a default) against the range and choices; same errors.
void check_value(const ParamSpec& spec, const ParamValue& value);

// The candidate nearest to `word` by edit distance when it is a likely typo (at most a third of
// the word's letters differ), else empty: for "did you mean" in error messages.
std::string nearest(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace mocap::graph
