#pragma once
// A small command-line parser shared by every `mocap` subcommand: declared options produce the
// --help text, so help can never drift from what the command accepts.

#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::cli {

class Args {
 public:
  Args(std::string usage, std::string summary);

  // Declares an option taking a value (`--name VALUE` or `--name=VALUE`); `fallback` is shown in
  // --help and returned by get() when the option is absent. Repeatable options keep every value.
  Args& option(const std::string& name, const std::string& value_name, const std::string& help,
               std::optional<std::string> fallback = std::nullopt, bool repeatable = false);
  Args& flag(const std::string& name, const std::string& help);
  Args& positional(const std::string& name, const std::string& help, bool many = false,
                   bool required = true);

  // Parses argv (without the program and subcommand names). Returns false after printing help
  // (when asked for) or an error; `exit_code` then says what to return.
  bool parse(int argc, char** argv, int& exit_code);

  std::string get(const std::string& name) const;
  std::vector<std::string> all(const std::string& name) const;
  bool has(const std::string& name) const;
  double number(const std::string& name) const;  // throws InputError naming the option
  long integer(const std::string& name) const;   // likewise
  const std::vector<std::string>& positionals() const { return positionals_; }
  std::string help() const;

 private:
  struct Spec {
    std::string value_name, help;
    std::optional<std::string> fallback;
    bool is_flag = false, repeatable = false;
  };
  struct Positional {
    std::string name, help;
    bool many = false, required = true;
  };
  std::string usage_, summary_;
  std::vector<std::string> order_;
  std::map<std::string, Spec> specs_;
  std::vector<Positional> positional_specs_;
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<std::string> positionals_;
};

// A command with subcommands (`mocap db build|info|query`): runs the one named by argv[0] with the
// arguments after it; prints the usage for --help, no subcommand (exit 2) or an unknown one (2).
struct Subcommand {
  std::string_view name;
  std::string_view summary;
  int (*run)(int argc, char** argv);
};
int run_subcommand(std::string_view command, std::span<const Subcommand> subcommands, int argc,
                   char** argv);

}  // namespace mocap::cli
