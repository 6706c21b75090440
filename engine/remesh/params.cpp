#include "remesh/params.h"

#include <cmath>
#include <string>

namespace remesh {

namespace {
bool finite(double x) { return std::isfinite(x); }
}  // namespace

std::vector<FieldError> check(const Params& p) {
  std::vector<FieldError> errors;
  const bool emin_ok = finite(p.e_min) && p.e_min > 0;
  const bool emax_ok = finite(p.e_max) && p.e_max > 0;
  if (!emin_ok) errors.push_back({"emin", "must be a finite number > 0"});
  if (!emax_ok) errors.push_back({"emax", "must be a finite number > 0"});
  if (emin_ok && emax_ok && !(p.e_min < p.e_max))
    errors.push_back({"emax", "must be greater than emin"});
  if (p.rings < 1 || p.rings > 4) errors.push_back({"rings", "must be in 1..4"});
  if (p.max_iterations < 1) {
    errors.push_back({"iterations", "max_iterations must be >= 1"});
  } else if (p.iterations < 1 || p.iterations > p.max_iterations) {
    errors.push_back({"iterations", "must be in 1.." + std::to_string(p.max_iterations)});
  }
  if (p.relax_every < 0) errors.push_back({"relax_every", "must be >= 0 (0 = never)"});
  if (!finite(p.flip_factor) || p.flip_factor < 0 || p.flip_factor > 1)
    errors.push_back({"flip_factor", "must be a finite number in 0..1"});
  if (p.threads > 1024) errors.push_back({"threads", "must be in 0..1024 (0 = all cores)"});
  return errors;
}

}  // namespace remesh
