#include "cli_args.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>

#include "core/input_error.hpp"

namespace mocap::cli {

namespace {

std::string text_of(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// A whole text as a finite number (from_chars accepts "nan" and "inf": refused here).
std::optional<double> finite_number(std::string_view text) {
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

std::optional<long> whole_number(std::string_view text) {
  long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> items;
  std::size_t start = 0;
  for (std::size_t at; (at = text.find(separator, start)) != std::string::npos; start = at + 1)
    items.push_back(text.substr(start, at - start));
  items.push_back(text.substr(start));
  return items;
}

}  // namespace

Range Range::positive() {
  Range r;
  r.min = 0.0;
  r.above_min = true;
  return r;
}

Range Range::at_least(double min) {
  Range r;
  r.min = min;
  return r;
}

Range Range::between(double min, double max) {
  Range r;
  r.min = min;
  r.max = max;
  return r;
}

Range Range::count(long min, long max) {
  Range r = between(static_cast<double>(min), static_cast<double>(max));
  r.whole = true;
  return r;
}

Range Range::positive_list() {
  Range r = positive();
  r.list = true;
  return r;
}

Range Range::image_size() {
  Range r = count(1, 65535);
  r.size = true;
  return r;
}

Range& Range::or_word(std::string word) {
  words.push_back(std::move(word));
  return *this;
}

std::string Range::describe() const {
  std::string bounds;
  const bool low = std::isfinite(min), high = std::isfinite(max);
  const bool int_max = whole && max >= static_cast<double>(std::numeric_limits<int>::max());
  if (low && high && !int_max) {
    bounds = (above_min ? "> " + text_of(min) + " and up to " : "from " + text_of(min) + " to ") +
             text_of(max);
  } else if (low) {
    bounds = (above_min ? "> " : ">= ") + text_of(min);
  } else if (high) {
    bounds = "<= " + text_of(max);
  }
  std::string what = size    ? "WIDTHxHEIGHT, each a whole number " + bounds
                     : list  ? "comma-separated numbers, each " + bounds
                     : whole ? "a whole number " + bounds
                             : "a number " + bounds;
  for (auto it = words.rbegin(); it != words.rend(); ++it) what = *it + " or " + what;
  return what;
}

std::string Range::check(const std::string& text) const {
  if (std::find(words.begin(), words.end(), text) != words.end()) return {};
  auto in_range = [&](std::string_view item) {
    std::optional<double> value;
    if (whole) {
      if (const auto n = whole_number(item)) value = static_cast<double>(*n);
    } else {
      value = finite_number(item);
    }
    return value && (above_min ? *value > min : *value >= min) && *value <= max;
  };
  bool ok = !text.empty();
  if (size) {
    const auto x = text.find('x');
    ok = x != std::string::npos && in_range(std::string_view(text).substr(0, x)) &&
         in_range(std::string_view(text).substr(x + 1));
  } else if (list) {
    for (const std::string& item : split(text, ',')) ok = ok && in_range(item);
  } else {
    ok = ok && in_range(text);
  }
  return ok ? std::string() : "expected " + describe() + ", got '" + text + "'";
}

Args::Args(std::string usage, std::string summary)
    : usage_(std::move(usage)), summary_(std::move(summary)) {
  flag("help", "show this help and exit");
}

Args& Args::option(const std::string& name, const std::string& value_name, const std::string& help,
                   std::optional<std::string> fallback, bool repeatable) {
  if (!specs_.count(name)) order_.push_back(name);
  specs_[name] = Spec{value_name, help, std::move(fallback), false, repeatable, std::nullopt};
  return *this;
}

Args& Args::option(const std::string& name, const std::string& value_name, const std::string& help,
                   std::optional<std::string> fallback, Range range) {
  option(name, value_name, help, std::move(fallback));
  specs_[name].range = std::move(range);
  return *this;
}

Args& Args::flag(const std::string& name, const std::string& help) {
  if (!specs_.count(name)) order_.push_back(name);
  specs_[name] = Spec{"", help, std::nullopt, true, false, std::nullopt};
  return *this;
}

Args& Args::positional(const std::string& name, const std::string& help, bool many, bool required) {
  positional_specs_.push_back({name, help, many, required});
  return *this;
}

std::string Args::help() const {
  std::ostringstream out;
  out << "usage: " << usage_ << "\n\n" << summary_ << "\n";
  if (!positional_specs_.empty()) {
    out << "\narguments:\n";
    for (const auto& p : positional_specs_) {
      std::string left = "  " + p.name + (p.many ? "..." : "");
      left.resize(std::max<size_t>(left.size() + 2, 26), ' ');
      out << left << p.help << "\n";
    }
  }
  out << "\noptions:\n";
  for (const auto& name : order_) {
    const Spec& s = specs_.at(name);
    std::string left = "  --" + name + (s.is_flag ? "" : " " + s.value_name);
    left.resize(std::max<size_t>(left.size() + 2, 26), ' ');
    out << left << s.help;
    if (s.range && s.fallback) {
      out << " (" << s.range->describe() << "; default: " << *s.fallback << ")";
    } else if (s.range) {
      out << " (" << s.range->describe() << ")";
    } else if (s.fallback) {
      out << " (default: " << *s.fallback << ")";
    }
    if (s.repeatable) out << " (repeatable)";
    out << "\n";
  }
  return out.str();
}

bool Args::parse(int argc, char** argv, int& exit_code) {
  auto fail = [&](const std::string& message) {
    std::cerr << "error: " << message << "\n\nusage: " << usage_ << "\n(see --help)\n";
    exit_code = 2;
    return false;
  };
  bool options_done = false;
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    if (!options_done && arg == "--") {
      options_done = true;
      continue;
    }
    if (options_done || arg.size() < 3 || arg.compare(0, 2, "--") != 0) {
      if (!options_done && arg.size() > 1 && arg[0] == '-' && arg != "-" &&
          !std::isdigit(static_cast<unsigned char>(arg[1])) && arg[1] != '.') {
        return fail("unknown option '" + arg + "'");
      }
      positionals_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2), value;
    bool inline_value = false;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      inline_value = true;
    }
    const auto it = specs_.find(name);
    if (it == specs_.end()) return fail("unknown option '--" + name + "'");
    if (it->second.is_flag) {
      if (inline_value) return fail("option '--" + name + "' takes no value");
      values_[name].push_back("1");
      continue;
    }
    if (!inline_value) {
      if (i + 1 >= argc)
        return fail("option '--" + name + "' needs a value (" + it->second.value_name + ")");
      value = argv[++i];
    }
    if (!it->second.repeatable && values_.count(name))
      return fail("option '--" + name + "' given twice");
    if (it->second.range) {
      if (const std::string problem = it->second.range->check(value); !problem.empty())
        return fail("--" + name + ": " + problem);
    }
    values_[name].push_back(value);
  }
  if (has("help")) {
    std::cout << help();
    exit_code = 0;
    return false;
  }
  size_t required = 0;
  bool many = false;
  for (const auto& p : positional_specs_) {
    required += p.required ? 1 : 0;
    many = many || p.many;
  }
  if (positionals_.size() < required) {
    return fail("missing " + positional_specs_[positionals_.size()].name);
  }
  if (!many && positionals_.size() > positional_specs_.size()) {
    return fail("unexpected argument '" + positionals_[positional_specs_.size()] + "'");
  }
  return true;
}

bool Args::has(const std::string& name) const { return values_.count(name) > 0; }

std::string Args::get(const std::string& name) const {
  if (const auto it = values_.find(name); it != values_.end()) return it->second.back();
  if (const auto it = specs_.find(name); it != specs_.end() && it->second.fallback)
    return *it->second.fallback;
  return {};
}

std::vector<std::string> Args::all(const std::string& name) const {
  if (const auto it = values_.find(name); it != values_.end()) return it->second;
  if (const auto it = specs_.find(name); it != specs_.end() && it->second.fallback)
    return {*it->second.fallback};
  return {};
}

const std::string& Args::checked(const std::string& name) const {
  static const std::string none;
  const auto spec = specs_.find(name);
  const auto given = values_.find(name);
  const std::string& text = given != values_.end()                          ? given->second.back()
                            : spec != specs_.end() && spec->second.fallback ? *spec->second.fallback
                                                                            : none;
  if (spec != specs_.end() && spec->second.range) {
    if (const std::string problem = spec->second.range->check(text); !problem.empty())
      throw InputError("--" + name, problem);
  }
  return text;
}

double Args::number(const std::string& name) const {
  const std::string& text = checked(name);
  const auto value = finite_number(text);
  if (!value) throw InputError("--" + name, "expected a number, got '" + text + "'");
  return *value;
}

long Args::integer(const std::string& name) const {
  const std::string& text = checked(name);
  const auto value = whole_number(text);
  if (!value) throw InputError("--" + name, "expected a whole number, got '" + text + "'");
  return *value;
}

std::vector<double> Args::numbers(const std::string& name) const {
  const std::string& text = checked(name);
  std::vector<double> values;
  for (const std::string& item : split(text, ',')) {
    const auto value = finite_number(item);
    if (!value)
      throw InputError("--" + name, "expected comma-separated numbers, got '" + text + "'");
    values.push_back(*value);
  }
  return values;
}

ImageSize Args::image_size(const std::string& name) const {
  const std::string& text = checked(name);
  const auto x = text.find('x');
  const auto width = whole_number(std::string_view(text).substr(0, std::min(x, text.size())));
  const auto height =
      x == std::string::npos ? std::nullopt : whole_number(std::string_view(text).substr(x + 1));
  if (!width || !height || *width <= 0 || *height <= 0 || *width > 65535 || *height > 65535)
    throw InputError("--" + name,
                     "expected WIDTHxHEIGHT in pixels, e.g. 1920x1080, got '" + text + "'");
  return {static_cast<int>(*width), static_cast<int>(*height)};
}

int run_subcommand(std::string_view command, std::span<const Subcommand> subcommands, int argc,
                   char** argv) {
  std::ostringstream usage;
  usage << "usage: mocap " << command << " ";
  for (std::size_t i = 0; i < subcommands.size(); ++i)
    usage << (i ? "|" : "") << subcommands[i].name;
  usage << " ...\n\n";
  std::size_t width = 0;
  for (const auto& s : subcommands) width = std::max(width, s.name.size());
  for (const auto& s : subcommands)
    usage << "  " << s.name << std::string(width + 2 - s.name.size(), ' ') << s.summary << "\n";
  usage << "\nRun 'mocap " << command << " SUBCOMMAND --help' for options.\n";
  if (argc < 1) {
    std::cerr << usage.str();
    return 2;
  }
  const std::string_view name = argv[0];
  for (const auto& s : subcommands) {
    if (s.name == name) return s.run(argc - 1, argv + 1);
  }
  if (name == "--help" || name == "-h") {
    std::cout << usage.str();
    return 0;
  }
  std::cerr << "mocap " << command << ": unknown subcommand '" << name << "'\n\n" << usage.str();
  return 2;
}

}  // namespace mocap::cli
