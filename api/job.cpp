#include "job.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <ctime>
#include <random>
#include <stdexcept>

#include "json_codec.h"

namespace remesh {

/// The job's "triangles" (triangle_quality.h): its fields by their own names. Angles in degrees;
/// below_30 and above_90 are fractions of the faces.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(TriangleQuality, faces, min_angle, max_angle, below_30, above_90,
                                   min_radius_ratio, mean_radius_ratio)

}  // namespace remesh

namespace remesh::api {

using nlohmann::json;

namespace {

constexpr std::string_view kStates[] = {"queued",     "running",   "succeeded",
                                        "failed",     "cancelling", "cancelled"};

json time_or_null(const std::optional<double>& t) { return t ? json(iso8601(*t)) : json(nullptr); }

/// Parses what iso8601() writes; throws std::runtime_error otherwise.
double parse_iso8601(const std::string& s) {
  std::tm tm{};
  int ms = 0;
  char z = 0;
  if (std::sscanf(s.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d.%3d%c", &tm.tm_year, &tm.tm_mon, &tm.tm_mday,
                  &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &ms, &z) != 8 || z != 'Z')
    throw std::runtime_error("bad timestamp '" + s + "'");
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return static_cast<double>(timegm(&tm)) + ms / 1000.0;
}

std::optional<double> opt_time(const json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return std::nullopt;
  return parse_iso8601(it->get<std::string>());
}

/// The links of `mesh`'s files in `formats`, but those in `unwritable` ("dual.glb").
json format_links(const std::string& base, const std::string& mesh, const std::vector<std::string>& formats,
                  const std::vector<std::string>& unwritable) {
  json links = json::object();
  auto cannot = [&](const std::string& f) {
    return std::find(unwritable.begin(), unwritable.end(), mesh + "." + f) != unwritable.end();
  };
  // Text glTF stores float32 as GLB does: a mesh GLB cannot hold, it cannot either (the runner
  // names both; a job stored before glTF was added names only the GLB).
  for (const std::string& f : formats)
    if (!cannot(f) && !(f == "gltf" && cannot("glb"))) links[f] = base + "/result?mesh=" + mesh + "&format=" + f;
  return links;
}

/// {hausdorff, relative, result_to_input, input_to_result, diagonal} (SurfaceDistance).
json distance_to_json(const SurfaceDistance& d) {
  return {{"hausdorff", d.hausdorff()},
          {"relative", d.relative()},
          {"result_to_input", d.result_to_input},
          {"input_to_result", d.input_to_result},
          {"diagonal", d.diagonal}};
}

/// {stellar, ..., setup, other, total} (kPhaseFields): other = total minus the steps.
json step_seconds_to_json(const JobRecord::StepSeconds& s) {
  json j = json::object();
  for (const PhaseField& f : kPhaseFields) j[f.name] = s.steps.*f.seconds;
  j["other"] = other_seconds(s.steps, s.total);
  j["total"] = s.total;
  return j;
}

JobRecord::StepSeconds step_seconds_from_json(const json& j) {
  JobRecord::StepSeconds s;
  for (const PhaseField& f : kPhaseFields) s.steps.*f.seconds = j.at(f.name).get<double>();
  s.total = j.at("total").get<double>();
  return s;
}

/// {outside, in_thin_parts, limit, at_irregular_vertices, at_kept_creases, vertices: {limit, thinner: {vertices,
/// regular}, thicker: {vertices, regular}, sampled}} (thin_parts.h).
json thin_parts_to_json(const ThinParts& t) {
  return json{{"outside", t.outside},
              {"in_thin_parts", t.in_thin_parts},
              {"limit", t.limit},
              {"at_irregular_vertices", t.at_irregular},
              {"at_kept_creases", t.at_creases},
              {"vertices",
               {{"limit", t.vertex_limit},
                {"thinner", {{"vertices", t.vertices_thinner}, {"regular", t.regular_thinner}}},
                {"thicker", {{"vertices", t.vertices_thicker}, {"regular", t.regular_thicker}}},
                {"sampled", t.sampled}}}};
}

/// {atoms, bonds, rings: {"5": n, "6": n, ...}, bond_length: {mean, deviation, min, max},
/// bond_interval: [min, max], short_bonds, long_bonds, bonds_inside_fraction}.
json dual_to_json(const DualStats& d) {
  json rings = json::object();
  for (const auto& [sides, count] : d.rings) rings[std::to_string(sides)] = count;
  return json{{"atoms", d.atoms},
              {"bonds", d.bonds},
              {"rings", rings},
              {"bond_length", {{"mean", d.mean}, {"deviation", d.deviation}, {"min", d.min}, {"max", d.max}}},
              {"bond_interval", json::array({d.bond_min, d.bond_max})},
              {"short_bonds", d.short_bonds},
              {"long_bonds", d.long_bonds},
              {"bonds_inside_fraction", d.inside_fraction()}};
}

DualStats dual_from_json(const json& j) {
  DualStats d;
  d.atoms = j.at("atoms").get<std::size_t>();
  d.bonds = j.at("bonds").get<std::size_t>();
  for (const auto& [sides, count] : j.at("rings").items()) {
    std::size_t n = 0;
    const auto [end, ec] = std::from_chars(sides.data(), sides.data() + sides.size(), n);
    if (ec != std::errc() || end != sides.data() + sides.size()) throw std::runtime_error("bad dual.rings key");
    d.rings[n] = count.get<std::size_t>();
  }
  const json& length = j.at("bond_length");
  d.mean = length.at("mean").get<double>();
  d.deviation = length.at("deviation").get<double>();
  d.min = length.at("min").get<double>();
  d.max = length.at("max").get<double>();
  const json& interval = j.at("bond_interval");
  d.bond_min = interval.at(0).get<double>();
  d.bond_max = interval.at(1).get<double>();
  d.short_bonds = j.at("short_bonds").get<std::size_t>();
  d.long_bonds = j.at("long_bonds").get<std::size_t>();
  return d;
}

}  // namespace

std::string_view state_name(JobState s) { return kStates[static_cast<int>(s)]; }

std::optional<JobState> parse_state(std::string_view s) {
  for (int i = 0; i < 6; ++i)
    if (kStates[i] == s) return static_cast<JobState>(i);
  return std::nullopt;
}

bool is_final(JobState s) {
  return s == JobState::Succeeded || s == JobState::Failed || s == JobState::Cancelled;
}

double now_seconds() {
  using namespace std::chrono;
  return duration<double>(system_clock::now().time_since_epoch()).count();
}

std::string iso8601(double unix_seconds) {
  double whole = std::floor(unix_seconds);
  int ms = static_cast<int>(std::lround((unix_seconds - whole) * 1000));
  if (ms >= 1000) {
    whole += 1;
    ms -= 1000;
  }
  std::time_t t = static_cast<std::time_t>(whole);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1,
                tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
  return buf;
}

std::string_view outcome_name(Outcome o) { return remesh::outcome_name(o); }

const std::vector<std::string>& remeshed_formats() {
  static const std::vector<std::string> f = {"obj", "glb", "gltf", "ply", "off", "stl", "lammps"};
  return f;
}

const std::vector<std::string>& dual_formats() {
  static const std::vector<std::string> f = {"obj", "glb", "gltf", "ply", "off", "xyz", "lammps"};
  return f;
}

bool made_on_request(std::string_view format) { return format == "gltf"; }

json job_to_json(const JobRecord& job, std::string_view prefix, double now) {
  const std::string base = std::string(prefix) + "/jobs/" + job.id;
  double queued_end = job.started_at ? *job.started_at : (job.finished_at ? *job.finished_at : now);
  double run_seconds = job.started_at ? (job.finished_at ? *job.finished_at : now) - *job.started_at : 0.0;
  json params = job.params;
  params["weld"] = job.weld;
  json links = {{"self", base},
                {"events", base + "/events"},
                {"stats", base + "/stats"},
                {"input", base + "/result?mesh=input&format=glb"}};
  if (job.state == JobState::Succeeded)
    links["results"] = {{"remeshed", format_links(base, "remeshed", remeshed_formats(), job.unwritable)},
                        {"dual", format_links(base, "dual", dual_formats(), job.unwritable)}};
  return json{
      {"id", job.id},
      {"state", state_name(job.state)},
      {"created_at", iso8601(job.created_at)},
      {"started_at", time_or_null(job.started_at)},
      {"finished_at", time_or_null(job.finished_at)},
      {"params", params},
      {"input",
       {{"filename", job.filename},
        {"format", job.format},
        {"bytes", job.bytes},
        {"summary", job.summary},
        {"repairs", job.repairs}}},
      {"progress", {{"iteration", job.iteration}, {"iterations", job.params.iterations}}},
      {"latest", job.latest ? json(*job.latest) : json(nullptr)},
      {"outcome", job.outcome ? json(*job.outcome) : json(nullptr)},
      {"thin_parts", job.thin_parts ? thin_parts_to_json(*job.thin_parts) : json(nullptr)},
      {"crossing_pairs", job.crossing_pairs ? json(*job.crossing_pairs) : json(nullptr)},
      // Known once the run has succeeded, as crossing_pairs (null before: it read false, "no layers").
      {"layered", job.state == JobState::Succeeded ? json(job.layered) : json(nullptr)},
      {"unwritable", job.unwritable},
      {"triangles", job.triangles ? json(*job.triangles) : json(nullptr)},
      {"seconds_by_step", job.seconds_by_step ? step_seconds_to_json(*job.seconds_by_step) : json(nullptr)},
      {"dual", job.dual ? dual_to_json(*job.dual) : json(nullptr)},
      {"distance_to_input", job.distance_to_input ? distance_to_json(*job.distance_to_input) : json(nullptr)},
      {"error", job.error ? json(*job.error) : json(nullptr)},
      {"attempts", job.attempts},
      {"timings",
       {{"queued_seconds", std::max(0.0, queued_end - job.created_at)},
        {"run_seconds", std::max(0.0, run_seconds)}}},
      {"links", links},
  };
}

JobRecord job_from_json(const json& j) {
  try {
    JobRecord job;
    job.id = j.at("id").get<std::string>();
    if (!is_valid_job_id(job.id)) throw std::runtime_error("bad id");
    auto state = parse_state(j.at("state").get<std::string>());
    if (!state) throw std::runtime_error("bad state");
    job.state = *state;
    job.created_at = parse_iso8601(j.at("created_at").get<std::string>());
    job.started_at = opt_time(j, "started_at");
    job.finished_at = opt_time(j, "finished_at");
    ParsedParams parsed = params_from_json(j.at("params"));
    if (!parsed.ok()) throw std::runtime_error("bad params: " + parsed.errors.front().field);
    job.params = parsed.params;
    job.weld = parsed.weld;
    const json& in = j.at("input");
    job.filename = in.at("filename").get<std::string>();
    job.format = in.at("format").get<std::string>();
    job.bytes = in.at("bytes").get<std::size_t>();
    job.summary = in.at("summary");
    job.repairs = in.at("repairs");
    job.iteration = j.at("progress").at("iteration").get<int>();
    if (!j.at("latest").is_null()) job.latest = j.at("latest").get<IterationStats>();
    if (!j.at("outcome").is_null()) job.outcome = j.at("outcome").get<std::string>();
    // Absent in documents written before the field existed.
    if (const auto t = j.find("thin_parts"); t != j.end() && !t->is_null()) {
      job.thin_parts = ThinParts{t->at("outside").get<std::size_t>(), t->at("in_thin_parts").get<std::size_t>(),
                                 t->at("limit").get<double>()};
      // Absent in documents written before the counts existed: 0 there.
      job.thin_parts->at_irregular = t->value("at_irregular_vertices", std::size_t{0});
      job.thin_parts->at_creases = t->value("at_kept_creases", std::size_t{0});
      if (const auto v = t->find("vertices"); v != t->end() && v->is_object()) {
        ThinParts& p = *job.thin_parts;
        p.vertex_limit = v->at("limit").get<double>();
        p.vertices_thinner = v->at("thinner").at("vertices").get<std::size_t>();
        p.regular_thinner = v->at("thinner").at("regular").get<std::size_t>();
        p.vertices_thicker = v->at("thicker").at("vertices").get<std::size_t>();
        p.regular_thicker = v->at("thicker").at("regular").get<std::size_t>();
        p.sampled = v->at("sampled").get<bool>();
      }
    }
    // Absent in documents written before the field existed.
    if (const auto c = j.find("crossing_pairs"); c != j.end() && !c->is_null())
      job.crossing_pairs = c->get<std::size_t>();
    if (const auto l = j.find("layered"); l != j.end() && l->is_boolean()) job.layered = l->get<bool>();
    if (const auto u = j.find("unwritable"); u != j.end() && u->is_array())
      for (const json& name : *u)
        if (name.is_string()) job.unwritable.push_back(name.get<std::string>());
    // Absent in documents written before the field existed.
    if (const auto t = j.find("triangles"); t != j.end() && !t->is_null()) job.triangles = t->get<TriangleQuality>();
    if (const auto t = j.find("seconds_by_step"); t != j.end() && !t->is_null())
      job.seconds_by_step = step_seconds_from_json(*t);
    // Absent in documents written before the field existed.
    if (const auto d = j.find("dual"); d != j.end() && !d->is_null()) job.dual = dual_from_json(*d);
    // Absent in documents written before the field existed. A side JSON could not hold (infinity
    // is written as null: a side without triangles) leaves the field out, not the job.
    if (const auto d = j.find("distance_to_input"); d != j.end() && d->is_object()) {
      const auto number = [&](const char* name) { return d->contains(name) && d->at(name).is_number(); };
      if (number("result_to_input") && number("input_to_result") && number("diagonal"))
        job.distance_to_input = SurfaceDistance{d->at("result_to_input").get<double>(),
                                                d->at("input_to_result").get<double>(), d->at("diagonal").get<double>()};
    }
    if (!j.at("error").is_null()) job.error = j.at("error").get<std::string>();
    job.attempts = j.value("attempts", 0);  // absent in documents written before the field existed
    return job;
  } catch (const json::exception& e) {
    throw std::runtime_error(std::string("job document: ") + e.what());
  }
}

std::string new_job_id() {
  static thread_local std::random_device rd;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string id;
  id.reserve(32);
  for (int i = 0; i < 4; ++i) {
    std::uint32_t v = rd();
    for (int k = 0; k < 8; ++k) id += kHex[(v >> (4 * k)) & 0xF];
  }
  return id;
}

bool is_valid_job_id(std::string_view id) {
  if (id.size() != 32) return false;
  for (char c : id)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

}  // namespace remesh::api
