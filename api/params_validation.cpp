#include <algorithm>
#include <set>

#include "json_codec.h"

namespace remesh {

std::vector<FieldError> validate_params(ParsedParams& parsed, int max_iterations) {
  std::vector<FieldError> errors = parsed.errors;
  std::set<std::string> bad;
  for (const FieldError& e : errors) bad.insert(e.field);
  if (max_iterations > 0) {
    parsed.params.max_iterations = max_iterations;
    bool given = std::find(parsed.given.begin(), parsed.given.end(), "iterations") != parsed.given.end();
    if (!given) parsed.params.iterations = std::min(parsed.params.iterations, max_iterations);
  }
  // Only range-check what parsed; a field already reported is not reported twice.
  if (!bad.count("emin") && !bad.count("emax")) {
    for (const FieldError& e : check(parsed.params))
      if (!bad.count(e.field)) {
        errors.push_back(e);
        bad.insert(e.field);
      }
  } else {
    // Fill in a valid stand-in for the bad bound so the other fields still get checked.
    Params probe = parsed.params;
    if (bad.count("emin")) probe.e_min = bad.count("emax") ? 1.0 : probe.e_max / 2;
    if (bad.count("emax")) probe.e_max = bad.count("emin") ? 2.0 : probe.e_min * 2;
    for (const FieldError& e : check(probe))
      if (!bad.count(e.field)) {
        errors.push_back(e);
        bad.insert(e.field);
      }
  }
  return errors;
}

}  // namespace remesh
