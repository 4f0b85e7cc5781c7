#pragma once
// A small command-line parser shared by every `mocap` subcommand: declared options produce the
// --help text, so help can never drift from what the command accepts, and a numeric option
// declared with its Range is checked when the line is parsed, so no command forgets a bound.

#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::cli {

// The values a numeric option accepts. NaN and infinities are never accepted; `words` are
// non-numeric values also taken as they are (e.g. "auto").
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool above_min = false;          // min itself excluded (> min)
  bool whole = false;              // whole numbers only
  bool list = false;               // comma-separated numbers, each in range
  bool size = false;               // WIDTHxHEIGHT, each a whole number in range
  std::vector<std::string> words;  // also accepted

  // What is accepted, for messages and --help: "> 0", "1 to 65535", "auto or > 0".
  std::string describe() const;
  // Empty when `text` is accepted, else the message ("expected ..., got '...'").
  std::string check(const std::string& text) const;

  static Range positive();            // > 0
  static Range at_least(double min);  // >= min
  static Range between(double min, double max);
  static Range count(long min, long max = std::numeric_limits<int>::max());  // whole
  static Range positive_list();      // comma-separated, each > 0
  static Range image_size();         // WxH, 1 to 65535 pixels each
  Range& or_word(std::string word);  // also accept `word`
};

// An image size given as WIDTHxHEIGHT.
struct ImageSize {
  int width = 0, height = 0;
};

class Args {
 public:
  Args(std::string usage, std::string summary);

  // Declares an option taking a value (`--name VALUE` or `--name=VALUE`); `fallback` is shown in
  // --help and returned by get() when the option is absent. Repeatable options keep every value.
  Args& option(const std::string& name, const std::string& value_name, const std::string& help,
               std::optional<std::string> fallback = std::nullopt, bool repeatable = false);
  // A numeric option: every value given is checked against `range` by parse() (exit 2 with a
  // message naming the option), and --help shows the range.
  Args& option(const std::string& name, const std::string& value_name, const std::string& help,
               std::optional<std::string> fallback, Range range);
  Args& flag(const std::string& name, const std::string& help);
  Args& positional(const std::string& name, const std::string& help, bool many = false,
                   bool required = true);

  // Parses argv (without the program and subcommand names). Returns false after printing help
  // (when asked for) or an error; `exit_code` then says what to return.
  bool parse(int argc, char** argv, int& exit_code);

  std::string get(const std::string& name) const;
  std::vector<std::string> all(const std::string& name) const;
  bool has(const std::string& name) const;
  // The value as a number, checked against the option's range (throws InputError naming the
  // option when it is not a number or, declared with a range, outside it).
  double number(const std::string& name) const;
  long integer(const std::string& name) const;                 // likewise, a whole number
  std::vector<double> numbers(const std::string& name) const;  // a comma-separated list
  ImageSize image_size(const std::string& name) const;         // WIDTHxHEIGHT
  const std::vector<std::string>& positionals() const { return positionals_; }
  std::string help() const;

 private:
  struct Spec {
    std::string value_name, help;
    std::optional<std::string> fallback;
    bool is_flag = false, repeatable = false;
    std::optional<Range> range;
  };
  const std::string& checked(const std::string& name) const;
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
