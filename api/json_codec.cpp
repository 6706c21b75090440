#include "json_codec.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <limits>

#include "dual/dual_stats.h"

namespace remesh {

using nlohmann::json;

namespace {

json vec3(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }

/// One IterationStats field: its name and how to read/write it as double or integer.
struct StatsField {
  const char* name;
  double IterationStats::*real = nullptr;
  std::size_t IterationStats::*count = nullptr;
  int IterationStats::*integer = nullptr;
};

const std::vector<StatsField>& stats_fields() {
  static const std::vector<StatsField> fields = {
      {"iteration", nullptr, nullptr, &IterationStats::iteration},
      {"vertices", nullptr, &IterationStats::vertices},
      {"edges", nullptr, &IterationStats::edges},
      {"mean", &IterationStats::mean},
      {"deviation", &IterationStats::deviation},
      {"regular_percent", &IterationStats::regular_percent},
      {"small", nullptr, &IterationStats::small},
      {"big", nullptr, &IterationStats::big},
      {"inside_fraction", &IterationStats::inside_fraction},
      {"splits", nullptr, &IterationStats::splits},
      {"collapses", nullptr, &IterationStats::collapses},
      {"flips", nullptr, &IterationStats::flips},
      {"seconds", &IterationStats::seconds},
      {"max_projection_distance", &IterationStats::max_projection_distance},
  };
  return fields;
}

enum class Kind { Real, Integer, Boolean };

struct ParamSpec {
  const char* name;
  Kind kind;
  bool required;
};

const std::vector<ParamSpec>& param_specs() {
  static const std::vector<ParamSpec> specs = {
      {"emin", Kind::Real, true},           {"emax", Kind::Real, true},
      {"iterations", Kind::Integer, false}, {"rings", Kind::Integer, false},
      {"relax_every", Kind::Integer, false}, {"flip_factor", Kind::Real, false},
      {"run_all_iterations", Kind::Boolean, false}, {"protect_tips", Kind::Boolean, false},
      {"keep_creases", Kind::Boolean, false},       {"relax_dual", Kind::Boolean, false},
      {"more_regular", Kind::Boolean, false},       {"weld", Kind::Boolean, false},
      {"bond_min", Kind::Real, false},              {"bond_max", Kind::Real, false},
  };
  return specs;
}

/// A parsed value before it is stored into Params.
struct Value {
  double real = 0;
  long long integer = 0;
  bool boolean = false;
};

void store(ParsedParams& out, std::string_view name, const Value& v) {
  Params& p = out.params;
  if (name == "emin") p.e_min = v.real;
  else if (name == "emax") p.e_max = v.real;
  else if (name == "iterations") p.iterations = static_cast<int>(v.integer);
  else if (name == "rings") p.rings = static_cast<int>(v.integer);
  else if (name == "relax_every") p.relax_every = static_cast<int>(v.integer);
  else if (name == "flip_factor") p.flip_factor = v.real;
  else if (name == "run_all_iterations") p.run_all_iterations = v.boolean;
  else if (name == "protect_tips") p.protect_tips = v.boolean;
  else if (name == "keep_creases") p.keep_creases = v.boolean;
  else if (name == "relax_dual") p.relax_dual = v.boolean;
  else if (name == "more_regular") p.more_regular = v.boolean;
  else if (name == "weld") out.weld = v.boolean;
  else if (name == "bond_min") out.bonds.value().min = v.real;
  else if (name == "bond_max") out.bonds.value().max = v.real;
}

const char* kind_message(Kind k) {
  switch (k) {
    case Kind::Real: return "must be a finite number";
    case Kind::Integer: return "must be an integer, at most 2147483647 in magnitude";
    case Kind::Boolean: return "must be true or false";
  }
  return "has a wrong type";
}

constexpr long long kIntLimit = std::numeric_limits<int>::max();

/// JSON value -> Value; false on a type error.
bool parse_json_value(const json& j, Kind kind, Value& v) {
  switch (kind) {
    case Kind::Real:
      if (!j.is_number()) return false;
      v.real = j.get<double>();
      return std::isfinite(v.real);
    case Kind::Integer: {
      if (j.is_number_integer()) {
        if (j.is_number_unsigned() && j.get<unsigned long long>() > static_cast<unsigned long long>(kIntLimit))
          return false;
        v.integer = j.get<long long>();
      } else if (j.is_number_float()) {
        double d = j.get<double>();
        if (!std::isfinite(d) || d != std::floor(d)) return false;
        v.integer = static_cast<long long>(d);
      } else {
        return false;
      }
      return v.integer >= -kIntLimit && v.integer <= kIntLimit;
    }
    case Kind::Boolean:
      if (!j.is_boolean()) return false;
      v.boolean = j.get<bool>();
      return true;
  }
  return false;
}

/// String -> Value; false on a syntax error.
bool parse_text_value(std::string_view s, Kind kind, Value& v) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const char* end = s.data() + s.size();
  switch (kind) {
    case Kind::Real: {
      if (s.empty()) return false;
      auto [ptr, ec] = std::from_chars(s.data(), end, v.real);
      return ec == std::errc() && ptr == end && std::isfinite(v.real);
    }
    case Kind::Integer: {
      if (s.empty()) return false;
      auto [ptr, ec] = std::from_chars(s.data(), end, v.integer);
      if (ec == std::errc() && ptr == end) return v.integer >= -kIntLimit && v.integer <= kIntLimit;
      double d = 0;  // "10.0" and "1e2" are integers too
      auto [p2, e2] = std::from_chars(s.data(), end, d);
      if (e2 != std::errc() || p2 != end || !std::isfinite(d) || d != std::floor(d)) return false;
      if (std::fabs(d) > static_cast<double>(kIntLimit)) return false;
      v.integer = static_cast<long long>(d);
      return true;
    }
    case Kind::Boolean: {
      std::string t(s);
      for (char& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (t.empty() || t == "true" || t == "1" || t == "yes" || t == "on") v.boolean = true;
      else if (t == "false" || t == "0" || t == "no" || t == "off") v.boolean = false;
      else return false;
      return true;
    }
  }
  return false;
}

/// Shared driver: `has(name)` says whether a key is present, `parse` reads its value.
/// The interval is emin and emax, or bond_min and bond_max (ParsedParams::bonds), never both.
template <class Has, class Parse>
ParsedParams parse_with(Has has, Parse parse) {
  ParsedParams out;
  const bool edges = has("emin") || has("emax");
  if (has("bond_min") || has("bond_max")) out.bonds.emplace();
  for (const ParamSpec& spec : param_specs()) {
    if (!has(spec.name)) {
      // With bonds the edge fields are not required: a missing bond field is (below).
      if (spec.required && !out.bonds)
        out.errors.push_back({spec.name, "is required (or give bond_min and bond_max, the dual's bond lengths)"});
      continue;
    }
    out.given.emplace_back(spec.name);
    Value v;
    if (parse(spec.name, spec.kind, v)) store(out, spec.name, v);
    else out.errors.push_back({spec.name, kind_message(spec.kind)});
  }
  if (!out.bonds) return out;
  if (edges) {
    out.errors.push_back({has("bond_min") ? "bond_min" : "bond_max",
                          "give either emin and emax (edge lengths) or bond_min and bond_max (the dual's bond "
                          "lengths), not both"});
    out.bonds.reset();
    out.interval_unknown = true;
    return out;
  }
  if (!has("bond_min")) out.errors.push_back({"bond_min", "is required with bond_max"});
  if (!has("bond_max")) out.errors.push_back({"bond_max", "is required with bond_min"});
  out.interval_unknown = !has("bond_min") || !has("bond_max");
  out.params.e_min = edge_for_bond(out.bonds->min);
  out.params.e_max = edge_for_bond(out.bonds->max);
  // A bond past the largest double / sqrt(3) has no edge length (check() would call it not finite).
  for (const auto& [name, edge] : {std::pair{"bond_min", out.params.e_min}, std::pair{"bond_max", out.params.e_max}})
    if (has(name) && !std::isfinite(edge) &&
        std::none_of(out.errors.begin(), out.errors.end(), [&](const FieldError& e) { return e.field == name; }))
      out.errors.push_back({name, "is too large: its edges, bond * sqrt(3), are past the largest number"});
  return out;
}

bool is_param(const std::string& key) {
  for (const ParamSpec& s : param_specs())
    if (key == s.name) return true;
  return false;
}

}  // namespace

void to_json(json& j, const MeshSummary& s) {
  json genus = json::array();
  for (const ComponentSummary& c : s.per_component)
    if (c.closed) genus.push_back(c.genus);
  j = json{{"vertices", s.vertices},
           {"faces", s.faces},
           {"edges", s.edges},
           {"components", s.components},
           {"boundary_loops", s.boundary_loops},
           {"boundary_edges", s.boundary_edges},
           {"euler", s.euler},
           {"genus", genus},
           {"bbox", {{"min", vec3(s.bbox_min)}, {"max", vec3(s.bbox_max)}, {"diagonal", s.bbox_diagonal}}},
           {"edge_length", {{"mean", s.mean_edge}, {"min", s.min_edge}, {"max", s.max_edge}}},
           {"area", s.area}};
}

void to_json(json& j, const Repair& r) {
  j = json{{"kind", r.kind}, {"count", r.count}, {"detail", r.detail}};
}

void to_json(json& j, const IterationStats& s) {
  j = json::object();
  for (const StatsField& f : stats_fields()) {
    if (f.real) j[f.name] = s.*(f.real);
    else if (f.count) j[f.name] = s.*(f.count);
    else j[f.name] = s.*(f.integer);
  }
}

void from_json(const json& j, IterationStats& s) {
  s = IterationStats{};
  for (const StatsField& f : stats_fields()) {
    auto it = j.find(f.name);
    if (it == j.end() || it->is_null()) continue;
    if (f.real) s.*(f.real) = it->get<double>();
    else if (f.count) s.*(f.count) = it->get<std::size_t>();
    else s.*(f.integer) = it->get<int>();
  }
}

void to_json(json& j, const Params& p) {
  j = json{{"emin", p.e_min},
           {"emax", p.e_max},
           {"iterations", p.iterations},
           {"rings", p.rings},
           {"relax_every", p.relax_every},
           {"flip_factor", p.flip_factor},
           {"run_all_iterations", p.run_all_iterations},
           {"protect_tips", p.protect_tips},
           {"keep_creases", p.keep_creases},
           {"more_regular", p.more_regular},
           {"relax_dual", p.relax_dual}};
}

void to_json(json& j, const FieldError& e) { j = json{{"field", e.field}, {"message", e.message}}; }

json summary_json(const MeshSummary& s, const std::vector<Repair>& repairs) {
  json j = s;
  j["repairs"] = repairs;
  return j;
}

const std::vector<std::string>& param_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const ParamSpec& s : param_specs()) n.emplace_back(s.name);
    return n;
  }();
  return names;
}

ParsedParams params_from_json(const json& j) {
  if (!j.is_object()) {
    ParsedParams out;
    out.errors.push_back({"params", "must be a JSON object"});
    return out;
  }
  ParsedParams out = parse_with([&](const char* name) { return j.contains(name); },
                                [&](const char* name, Kind kind, Value& v) {
                                  return parse_json_value(j.at(name), kind, v);
                                });
  for (const auto& [key, value] : j.items())
    if (!is_param(key)) out.errors.push_back({key, "unknown parameter"});
  return out;
}

ParsedParams params_from_query(const std::map<std::string, std::string>& values,
                               const std::vector<std::string>& ignore) {
  ParsedParams out = parse_with([&](const char* name) { return values.count(name) > 0; },
                                [&](const char* name, Kind kind, Value& v) {
                                  return parse_text_value(values.at(name), kind, v);
                                });
  for (const auto& [key, value] : values) {
    if (is_param(key)) continue;
    bool ignored = false;
    for (const std::string& i : ignore) ignored = ignored || i == key;
    if (!ignored) out.errors.push_back({key, "unknown parameter"});
  }
  return out;
}

std::string format_double(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, ptr) : std::string("null");
}

std::string stats_csv_header() {
  std::string h;
  for (const StatsField& f : stats_fields()) {
    if (!h.empty()) h += ',';
    h += f.name;
  }
  return h;
}

std::string stats_csv_row(const IterationStats& s) {
  std::string row;
  for (const StatsField& f : stats_fields()) {
    if (!row.empty()) row += ',';
    if (f.real) row += format_double(s.*(f.real));
    else if (f.count) row += std::to_string(s.*(f.count));
    else row += std::to_string(s.*(f.integer));
  }
  return row;
}

std::string stats_to_csv(const std::vector<IterationStats>& rows) {
  std::string out = stats_csv_header() + "\n";
  for (const IterationStats& r : rows) out += stats_csv_row(r) + "\n";
  return out;
}

}  // namespace remesh
