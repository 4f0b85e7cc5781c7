#include "cli_args.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>
#include <sstream>

#include "core/input_error.hpp"

namespace mocap::cli {

Args::Args(std::string usage, std::string summary)
    : usage_(std::move(usage)), summary_(std::move(summary)) {
  flag("help", "show this help and exit");
}

Args& Args::option(const std::string& name, const std::string& value_name, const std::string& help,
                   std::optional<std::string> fallback, bool repeatable) {
  if (!specs_.count(name)) order_.push_back(name);
  specs_[name] = Spec{value_name, help, std::move(fallback), false, repeatable};
  return *this;
}

Args& Args::flag(const std::string& name, const std::string& help) {
  if (!specs_.count(name)) order_.push_back(name);
  specs_[name] = Spec{"", help, std::nullopt, true, false};
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
    if (s.fallback) out << " (default: " << *s.fallback << ")";
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

double Args::number(const std::string& name) const {
  const std::string text = get(name);
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    throw InputError("--" + name, "expected a number, got '" + text + "'");
  }
  return value;
}

long Args::integer(const std::string& name) const {
  const std::string text = get(name);
  long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) {
    throw InputError("--" + name, "expected a whole number, got '" + text + "'");
  }
  return value;
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
