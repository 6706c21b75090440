#include <algorithm>
#include <cctype>
#include <cstdio>
#include <set>

#include "dual/dual_stats.h"
#include "json_codec.h"

namespace remesh {

std::vector<FieldError> renamed(std::vector<FieldError> errors, const std::vector<Rename>& names) {
  // A name counts as a word between characters that cannot be part of a parameter's name.
  auto boundary = [](char c) { return !std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-'; };
  for (FieldError& e : errors) {
    if (const auto name = std::find_if(names.begin(), names.end(), [&](const Rename& n) { return e.field == n.first; });
        name != names.end())
      e.field = name->second;
    std::string out;
    const std::string& text = e.message;
    for (std::size_t at = 0; at < text.size();) {
      const auto name = std::find_if(names.begin(), names.end(), [&](const Rename& n) {
        return text.compare(at, n.first.size(), n.first) == 0 && (at == 0 || boundary(text[at - 1])) &&
               (at + n.first.size() == text.size() || boundary(text[at + n.first.size()]));
      });
      if (name == names.end()) {
        out += text[at++];
      } else {
        out += name->second;
        at += name->first.size();
      }
    }
    e.message = std::move(out);
  }
  return errors;
}

std::vector<FieldError> in_bond_terms(std::vector<FieldError> errors) {
  return renamed(std::move(errors), {{"emin", "bond_min"}, {"emax", "bond_max"}});
}

std::vector<FieldError> validate_params(ParsedParams& parsed, int max_iterations) {
  std::vector<FieldError> errors = parsed.errors;
  // The fields already reported, by the engine's names: a bad bond_min is a bad emin, a bad
  // bond_max a bad emax. A missing one, or one given beside emin or emax, leaves the interval
  // unknown: no range error about either follows.
  std::set<std::string> bad;
  for (const FieldError& e : errors) {
    bad.insert(e.field);
    if (e.field == "bond_min") bad.insert("emin");
    if (e.field == "bond_max") bad.insert("emax");
  }
  if (parsed.interval_unknown) bad.insert({"emin", "emax"});
  if (max_iterations > 0) {
    parsed.params.max_iterations = max_iterations;
    bool given = std::find(parsed.given.begin(), parsed.given.end(), "iterations") != parsed.given.end();
    if (!given) parsed.params.iterations = std::min(parsed.params.iterations, max_iterations);
  }
  // Only range-check what parsed; a field already reported is not reported twice. A bad bound gets
  // a valid stand-in so that the other fields still get checked.
  Params probe = parsed.params;
  if (bad.count("emin")) probe.e_min = bad.count("emax") ? 1.0 : probe.e_max / 2;
  if (bad.count("emax")) probe.e_max = bad.count("emin") ? 2.0 : probe.e_min * 2;
  std::vector<FieldError> range = check(probe);
  for (const FieldError& e : range)
    if (!bad.count(e.field)) {
      bad.insert(e.field);
      errors.push_back(parsed.bonds ? in_bond_terms({e}).front() : e);
    }
  return errors;
}

std::vector<FieldError> check_interval_against(const TriMesh& mesh, const Params& params, bool bonds) {
  std::vector<FieldError> errors = check_against(mesh, params);
  if (!bonds) return errors;
  for (FieldError& e : errors) {
    if (e.field != "emin") continue;
    char text[200];
    std::snprintf(text, sizeof text,
                  "must be shorter than %.6g, the mesh's bounding-box diagonal / sqrt(3): its edges, bond_min * "
                  "sqrt(3) or longer, must fit on its surface",
                  bond_for_edge(bounding_box_diagonal(mesh)));
    e.message = text;
  }
  return in_bond_terms(std::move(errors));
}

}  // namespace remesh
