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

namespace {

std::string scalar_text(bool v) { return v ? "true" : "false"; }
std::string scalar_text(const std::string& v) { return v; }
template <class T>
std::string scalar_text(const T& v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string joined(const std::vector<std::string>& items, std::string_view separator) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : std::string(separator)) + item;
  return text;
}

}  // namespace

std::string to_text(const ParamValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::vector<std::int64_t>> ||
                      std::is_same_v<T, std::vector<double>> ||
                      std::is_same_v<T, std::vector<std::string>>) {
          std::vector<std::string> items;
          for (const auto& item : v) items.push_back(scalar_text(item));
          return joined(items, ",");
        } else {
          return scalar_text(v);
        }
      },
      value);
}

std::string ParamSpec::type_text() const {
  std::string text =
      choices.empty() ? std::string(graph::name(type)) : "choice of " + joined(choices, ", ");
  return list ? "list of " + text : text;
}

std::string nearest(std::string_view word, const std::vector<std::string>& candidates) {
  // Edit distance with adjacent transpositions ("mdoe" -> "mode" is one), case-insensitive.
  const auto distance = [](std::string_view a, std::string_view b) {
    const auto same = [](char x, char y) {
      return std::tolower(static_cast<unsigned char>(x)) ==
             std::tolower(static_cast<unsigned char>(y));
    };
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      for (std::size_t j = 1; j <= b.size(); ++j) {
        d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1,
                            d[i - 1][j - 1] + (same(a[i - 1], b[j - 1]) ? 0 : 1)});
        if (i > 1 && j > 1 && same(a[i - 1], b[j - 2]) && same(a[i - 2], b[j - 1])) {
          d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
      }
    }
    return d[a.size()][b.size()];
  };
  if (word.size() > 200) return {};  // not a typo; keeps the table small for garbage input
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(1, word.size() / 3) + 1;
  for (const std::string& candidate : candidates) {
    const std::size_t d = distance(word, candidate);
    if (d < best_distance) {
      best = candidate;
      best_distance = d;
    }
  }
  return best;
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

void check_number(const ParamSpec& spec, double number, std::string_view text) {
  if (!std::isfinite(number)) fail(spec, text, "a finite number");
  const bool low = spec.range.min && number < *spec.range.min;
  const bool high = spec.range.max && number > *spec.range.max;
  if (low || high) {
    std::ostringstream expected;
    expected << "a value in [" << (spec.range.min ? std::to_string(*spec.range.min) : "-inf")
             << ", " << (spec.range.max ? std::to_string(*spec.range.max) : "inf") << "]";
    fail(spec, text, expected.str());
  }
}

void check_choice(const ParamSpec& spec, const std::string& text) {
  if (spec.choices.empty() ||
      std::find(spec.choices.begin(), spec.choices.end(), text) != spec.choices.end()) {
    return;
  }
  std::string message =
      "parameter '" + spec.name + "': '" + text + "' is not one of " + joined(spec.choices, ", ");
  if (const std::string near = nearest(text, spec.choices); !near.empty()) {
    message += "; did you mean '" + near + "'?";
  }
  throw std::invalid_argument(message);
}

std::string trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return std::string(text.substr(first, last - first + 1));
}

}  // namespace

void check_value(const ParamSpec& spec, const ParamValue& value) {
  std::visit(
      [&](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::int64_t> || std::is_same_v<T, double>) {
          check_number(spec, static_cast<double>(v), scalar_text(v));
        } else if constexpr (std::is_same_v<T, std::string>) {
          check_choice(spec, v);
        } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
          for (const std::string& item : v) check_choice(spec, item);
        } else if constexpr (!std::is_same_v<T, bool>) {
          for (const auto& item : v)
            check_number(spec, static_cast<double>(item), scalar_text(item));
        }
      },
      value);
}

ParamValue parse_param_items(const ParamSpec& spec, const std::vector<std::string>& items) {
  if (!spec.list) {
    throw std::invalid_argument("parameter '" + spec.name + "' takes a single " + spec.type_text() +
                                ", not a list");
  }
  ParamValue value;
  switch (spec.type) {
    case ParamType::integer: {
      std::vector<std::int64_t> numbers;
      for (const std::string& item : items)
        numbers.push_back(parse_number<std::int64_t>(spec, item, "a list of whole numbers"));
      value = std::move(numbers);
      break;
    }
    case ParamType::number: {
      std::vector<double> numbers;
      for (const std::string& item : items)
        numbers.push_back(parse_number<double>(spec, item, "a list of numbers"));
      value = std::move(numbers);
      break;
    }
    default:
      value = items;
      break;
  }
  check_value(spec, value);
  return value;
}

ParamValue parse_param(const ParamSpec& spec, std::string_view text) {
  if (spec.list) {
    std::vector<std::string> items;
    if (!trimmed(text).empty()) {
      for (std::size_t start = 0; start <= text.size();) {
        const std::size_t end = std::min(text.find(',', start), text.size());
        items.push_back(trimmed(text.substr(start, end - start)));
        start = end + 1;
      }
    }
    return parse_param_items(spec, items);
  }
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
  check_value(spec, value);
  return value;
}

}  // namespace mocap::graph
