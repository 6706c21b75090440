/// \file args.cpp
#include "args.h"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <sstream>

namespace remesh::cli {

std::optional<std::string> Args::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

std::optional<double> Args::get_double(const std::string& name) const {
  auto text = get(name);
  if (!text) return std::nullopt;
  double value = 0;
  const char* end = text->data() + text->size();
  auto [ptr, ec] = std::from_chars(text->data(), end, value);
  // A number past the doubles' range (1e400, or 1e-400: from_chars reads neither) is one.
  if (!text->empty() && ec == std::errc::result_out_of_range && ptr == end)
    throw ValueError(name, *text + " is beyond the range of double-precision numbers");
  if (text->empty() || ec != std::errc() || ptr != end || !std::isfinite(value))
    throw ValueError(name, "'" + *text + "' is not a number");
  return value;
}

std::optional<long long> Args::get_int(const std::string& name, long long lo, long long hi) const {
  auto text = get(name);
  if (!text) return std::nullopt;
  long long value = 0;
  const char* end = text->data() + text->size();
  auto [ptr, ec] = std::from_chars(text->data(), end, value);
  if (!text->empty() && ec == std::errc::result_out_of_range && ptr == end)
    throw ValueError(name, *text + " is far too " + (text->front() == '-' ? "small" : "large"));
  if (text->empty() || ec != std::errc() || ptr != end)
    throw ValueError(name, "'" + *text + "' is not an integer");
  // A range that only keeps the value an int (the option's own rule follows): say which way it is out.
  if (value < lo || value > hi)
    throw ValueError(name, lo <= INT_MIN && hi >= INT_MAX ? *text + " is far too " + (value > hi ? "large" : "small")
                                                          : *text + " is outside " + std::to_string(lo) + ".." +
                                                                std::to_string(hi));
  return value;
}

bool wants_help(const std::vector<std::string>& args) {
  return std::any_of(args.begin(), args.end(),
                     [](const std::string& a) { return a == "--help" || a == "-h"; });
}

Args parse_args(const std::vector<std::string>& args, const std::vector<OptionSpec>& spec,
                std::size_t min_positional, std::size_t max_positional) {
  Args out;
  auto find_option = [&spec](const std::string& name) {
    return std::find_if(spec.begin(), spec.end(), [&](const OptionSpec& s) { return s.name == name; });
  };
  bool options_done = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (options_done || a.size() < 2 || a[0] != '-' || a == "-") {
      out.positional.push_back(a);
      continue;
    }
    if (a == "--") {
      options_done = true;
      continue;
    }
    if (a.rfind("--", 0) != 0) throw UsageError("unknown option '" + a + "'");
    std::string name = a.substr(2);
    std::optional<std::string> inline_value;
    if (auto eq = name.find('='); eq != std::string::npos) {
      inline_value = name.substr(eq + 1);
      name.resize(eq);
    }
    auto it = find_option(name);
    if (it == spec.end()) throw UsageError("unknown option '--" + name + "'");
    if (out.has(name)) throw UsageError("option '--" + name + "' given twice");
    if (it->value_name.empty()) {
      if (inline_value) throw UsageError("option '--" + name + "' takes no value");
      out.set(name, "");
    } else if (inline_value) {
      out.set(name, *inline_value);
    } else {
      if (i + 1 >= args.size()) throw UsageError("option '--" + name + "' needs a value (" + it->value_name + ")");
      // An option where the value should be is a value left out, not the value: "--dual --stats
      // s.csv" said "unexpected argument 's.csv'", and "--emin --emax 0.3" that --emax was missing.
      // (A value that starts with "--" is given as --name=value.)
      const std::string& next = args[i + 1];
      if (next.rfind("--", 0) == 0) {
        std::string next_name = next.substr(2);
        next_name.resize(std::min(next_name.size(), next_name.find('=')));
        if (next == "--" || find_option(next_name) != spec.end())
          throw UsageError("option '--" + name + "' needs a value (" + it->value_name + "), but is followed by '" + next +
                           "' (a value that starts with -- goes as --" + name + "=VALUE)");
      }
      out.set(name, args[++i]);
    }
  }
  if (out.positional.size() < min_positional)
    throw UsageError("expected " + std::to_string(min_positional) + " file argument" +
                     (min_positional == 1 ? "" : "s") + ", got " + std::to_string(out.positional.size()));
  if (out.positional.size() > max_positional)
    throw UsageError("unexpected argument '" + out.positional[max_positional] + "'");
  return out;
}

std::string format_help(const std::string& usage, const std::string& description,
                        const std::vector<OptionSpec>& spec) {
  std::ostringstream s;
  s << "Usage: " << usage << "\n\n" << description << "\n";
  if (!spec.empty()) s << "\nOptions:\n";
  for (const auto& o : spec) {
    std::string left = "  --" + o.name + (o.value_name.empty() ? "" : " " + o.value_name);
    if (left.size() < 26) left.resize(26, ' ');
    else left += "  ";
    s << left << o.help << "\n";
  }
  s << "  --help                  show this help\n";
  return s.str();
}

}  // namespace remesh::cli
