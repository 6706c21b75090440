#include "upload.h"

#include <algorithm>
#include <cctype>

#include "io/summary.h"
#include "remesh/self_intersections.h"

namespace remesh::api {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

}  // namespace

std::optional<Format> format_from_content_type(std::string_view content_type) {
  std::string t = lower(trim(content_type.substr(0, content_type.find(';'))));
  if (t == "model/obj" || t == "application/x-tgif" || t == "text/x-obj") return Format::Obj;
  if (t == "model/stl" || t == "application/sla" || t == "model/x.stl-binary" || t == "model/x.stl-ascii")
    return Format::Stl;
  if (t == "model/gltf-binary") return Format::Glb;
  if (t == "model/gltf+json") return Format::Gltf;
  if (t == "model/ply" || t == "application/ply" || t == "model/x-ply") return Format::Ply;
  if (t == "model/off" || t == "model/x-off" || t == "application/off") return Format::Off;
  return std::nullopt;
}

namespace {

/// Formats the service reads uploads in (XYZ and LAMMPS data are written only).
bool readable(Format f) { return f != Format::Xyz && f != Format::Lammps; }

}  // namespace

std::optional<Format> resolve_format(std::string_view format_param, std::string_view filename,
                                     std::string_view content_type, std::vector<FieldError>& errors) {
  if (!format_param.empty()) {
    auto f = parse_format(format_param);
    if (!f || !readable(*f)) {
      errors.push_back({"format", "unknown mesh format '" + std::string(format_param.substr(0, 40)) +
                                      "' (obj, off, ply, stl, gltf, glb)"});
      return std::nullopt;
    }
    return f;
  }
  if (filename.find('.') != std::string_view::npos) {
    auto f = parse_format(filename);
    if (f && readable(*f)) return f;
  }
  return format_from_content_type(content_type);
}

std::string utf8_prefix(std::string_view text, std::size_t max_bytes) {
  static constexpr std::string_view kReplacement = "\xEF\xBF\xBD";  // U+FFFD
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const auto b = static_cast<unsigned char>(text[i]);
    // The length of the sequence b begins, and the range its second byte must lie in (RFC 3629:
    // no overlong forms, no surrogates, nothing past U+10FFFF).
    std::size_t n = 0;
    unsigned char lo = 0x80, hi = 0xBF;
    if (b < 0x80) n = b < 0x20 || b == 0x7F ? 0 : 1;  // control characters (NUL, CR, LF, ...) too
    else if (b >= 0xC2 && b <= 0xDF) n = 2;
    else if (b >= 0xE0 && b <= 0xEF) n = 3, lo = b == 0xE0 ? 0xA0 : 0x80, hi = b == 0xED ? 0x9F : 0xBF;
    else if (b >= 0xF0 && b <= 0xF4) n = 4, lo = b == 0xF0 ? 0x90 : 0x80, hi = b == 0xF4 ? 0x8F : 0xBF;
    bool valid = n > 0 && i + n <= text.size();
    for (std::size_t k = 1; valid && k < n; ++k) {
      const auto c = static_cast<unsigned char>(text[i + k]);
      valid = k == 1 ? c >= lo && c <= hi : c >= 0x80 && c <= 0xBF;
    }
    const std::string_view piece = valid ? text.substr(i, n) : kReplacement;
    if (out.size() + piece.size() > max_bytes) break;
    out += piece;
    i += valid ? n : 1;
  }
  return out;
}

std::string safe_stem(std::string_view filename) {
  auto slash = filename.find_last_of("/\\");
  if (slash != std::string_view::npos) filename.remove_prefix(slash + 1);
  auto dot = filename.find_last_of('.');
  if (dot != std::string_view::npos && dot > 0) filename = filename.substr(0, dot);
  std::string out;
  for (char c : filename) {
    if (out.size() >= 80) break;
    bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
    out += ok ? c : '_';
  }
  while (!out.empty() && out.front() == '.') out.erase(out.begin());
  return out.empty() ? "mesh" : out;
}

std::string content_disposition(std::string_view disposition, std::string_view filename, std::string_view suffix) {
  const std::string ascii = safe_stem(filename);
  std::string out = std::string(disposition) + "; filename=\"" + ascii + std::string(suffix) + "\"";
  auto slash = filename.find_last_of("/\\");
  if (slash != std::string_view::npos) filename.remove_prefix(slash + 1);
  auto dot = filename.find_last_of('.');
  if (dot != std::string_view::npos && dot > 0) filename = filename.substr(0, dot);
  std::string stem = utf8_prefix(filename, 80);
  while (!stem.empty() && stem.front() == '.') stem.erase(stem.begin());
  if (stem.empty() || stem == ascii) return out;
  // RFC 8187 attr-char: ALPHA / DIGIT / "!#$&+-.^_`|~"; every other byte percent-encoded.
  static constexpr std::string_view kAttr = "!#$&+-.^_`|~";
  static constexpr char kHex[] = "0123456789ABCDEF";
  out += "; filename*=UTF-8''";
  for (char ch : stem + std::string(suffix)) {
    const auto c = static_cast<unsigned char>(ch);
    if (std::isalnum(c) || kAttr.find(ch) != std::string_view::npos) {
      out += ch;
    } else {
      out += '%';
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

PreparedJob prepare_job(std::string_view bytes, std::string_view filename, std::optional<Format> format,
                        ParsedParams params, const UploadLimits& limits) {
  std::vector<FieldError> errors = validate_params(params, limits.max_iterations);
  if (!errors.empty()) throw ParamsError(std::move(errors));
  if (limits.max_output_faces > 0) params.params.max_output_faces = limits.max_output_faces;

  ReadOptions options;
  options.format = format;
  options.weld = params.weld;
  options.max_faces = limits.max_faces;
  LoadedMesh loaded = read_mesh(bytes, options);
  if (limits.max_faces > 0 && loaded.mesh.n_faces() > limits.max_faces)
    throw LimitError("the mesh has " + std::to_string(loaded.mesh.n_faces()) + " faces, more than the limit of " +
                     std::to_string(limits.max_faces));
  check_mesh_size(loaded.mesh);
  check_vertex_stars(loaded.mesh);
  if (auto mesh_errors = check_interval_against(loaded.mesh, params.params, params.bonds.has_value());
      !mesh_errors.empty())
    throw ParamsError(std::move(mesh_errors));
  std::size_t estimate = estimate_output_faces(loaded.mesh, params.params);
  if (params.params.max_output_faces > 0 && estimate > params.params.max_output_faces)
    // An estimate at its cap is a bound, not a count (1e-300 as emax said "about 1000000000000000000").
    throw LimitError("the result would have " + std::string(estimate >= kMaxFaceEstimate ? "over " : "about ") +
                     std::to_string(estimate) + " faces, more than the limit of " +
                     std::to_string(params.params.max_output_faces) +
                     (params.bonds ? "; raise bond_min/bond_max" : "; raise emin/emax"));

  PreparedJob job{JobRecord{}, std::move(loaded)};
  JobRecord& r = job.record;
  r.id = new_job_id();
  r.state = JobState::Queued;
  r.created_at = now_seconds();
  // As the run takes them (e_max at most the bounding-box diagonal), so that the document says what
  // ran: an e_max of 1e300 showed as such, and the dual's bond interval as [0.29, 5.8e299].
  r.params = as_run(job.mesh.mesh, params.params);
  r.weld = params.weld;
  r.format = std::string(format_name(job.mesh.format));
  // An upload without a name is named by the format it was read in (from the Content-Type or its
  // bytes): "mesh.stl".
  r.filename = filename.empty() ? "mesh." + r.format : utf8_prefix(filename, 200);
  r.bytes = bytes.size();
  r.summary = summarize(job.mesh.mesh);
  // The input's faces that cross each other (remesh info's line), on the request's own thread
  // (the cores are the running jobs'): nefertiti's 100 000 faces about 0.1 s, beside its reading.
  const auto crossing = find_input_self_intersections(job.mesh.mesh, 1);
  r.summary["crossing_pairs"] = crossing ? nlohmann::json(crossing->size()) : nlohmann::json(nullptr);
  r.summary["layered"] = !crossing;
  r.repairs = job.mesh.repairs;
  return job;
}

}  // namespace remesh::api
