#pragma once
/// \file args.h
/// Small command-line option parsing for the `remesh` tool: `--name value`, `--name=value` and flags.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace remesh::cli {

/// A command-line mistake; the tool prints it on one line and exits with code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A malformed or out-of-range option value. what() is the whole line ("--emin: 'abc' is not a
/// number"); option() and problem() are its two halves, so that a command can read every option
/// and report all the bad ones together instead of stopping at the first.
class ValueError : public UsageError {
 public:
  ValueError(const std::string& option, const std::string& problem)
      : UsageError("--" + option + ": " + problem), option_(option), problem_(problem) {}
  const std::string& option() const { return option_; }  ///< without the dashes, e.g. "emin"
  const std::string& problem() const { return problem_; }

 private:
  std::string option_, problem_;
};

/// One option a command accepts. `value_name` empty = a flag without a value.
struct OptionSpec {
  std::string name;        ///< without the dashes, e.g. "emin"
  std::string value_name;  ///< e.g. "A"; empty for flags
  std::string help;        ///< one line
};

/// The parsed command line of one command.
class Args {
 public:
  std::vector<std::string> positional;

  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::optional<std::string> get(const std::string& name) const;
  /// The value of `--name` as a finite number; throws ValueError naming the option if malformed.
  std::optional<double> get_double(const std::string& name) const;
  /// The value of `--name` as an integer in [lo, hi]; throws ValueError if malformed or out of range.
  std::optional<long long> get_int(const std::string& name, long long lo, long long hi) const;

  void set(const std::string& name, std::string value) { values_[name] = std::move(value); }

 private:
  std::map<std::string, std::string> values_;
};

/// True if `--help` or `-h` is among the arguments (checked before anything else is parsed).
bool wants_help(const std::vector<std::string>& args);

/// Parses `args` (the command's arguments, without the program and command names). Throws
/// UsageError for an unknown option, a missing value, a repeated option, or a positional count
/// outside [min_positional, max_positional]. Only the first of these is reported: once a word is
/// not an option we know, we cannot tell whether the word after it is its value or a file, so
/// whatever follows would be misread.
Args parse_args(const std::vector<std::string>& args, const std::vector<OptionSpec>& spec,
                std::size_t min_positional, std::size_t max_positional);

/// The help text: usage line, description, then one line per option.
std::string format_help(const std::string& usage, const std::string& description,
                        const std::vector<OptionSpec>& spec);

}  // namespace remesh::cli
