#pragma once
/// \file upload.h
/// Turning an upload (bytes, file name, Content-Type, parameters) into a validated job: the format
/// is resolved, the mesh read and checked against the limits, the parameters validated. No sockets:
/// remeshd calls this from its POST handler, tests call it directly.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/mesh_io.h"
#include "job.h"
#include "json_codec.h"

namespace remesh::api {

/// The format a Content-Type names: model/obj, model/stl, model/gltf-binary, model/gltf+json,
/// model/ply, model/x-off (parameters after ';' ignored). nullopt for application/octet-stream,
/// text/plain, an empty or unknown type (then the content is sniffed).
std::optional<Format> format_from_content_type(std::string_view content_type);

/// The format of an upload: the explicit `format` parameter if given (unknown -> error on field
/// "format"), else the file name's extension, else the Content-Type; nullopt = sniff the bytes.
std::optional<Format> resolve_format(std::string_view format_param, std::string_view filename,
                                     std::string_view content_type, std::vector<FieldError>& errors);

/// A file name's stem made safe for Content-Disposition: directories and extension dropped, only
/// [A-Za-z0-9._-] kept (others become '_'), at most 80 characters; "mesh" when nothing is left.
std::string safe_stem(std::string_view filename);

/// A Content-Disposition value for a download named after an upload: `disposition` ("attachment",
/// "inline"), filename="<safe_stem><suffix>", and when the stem had characters safe_stem replaced,
/// also filename*=UTF-8''<the stem (utf8_prefix, 80 bytes) and suffix percent-encoded> (RFC 6266,
/// RFC 8187), which browsers prefer: "été.off" downloads as "été-remeshed.obj", not "__t_-...".
std::string content_disposition(std::string_view disposition, std::string_view filename, std::string_view suffix);

/// `text` as valid UTF-8 of at most `max_bytes` bytes: each byte that does not begin a valid
/// sequence becomes U+FFFD, and the text is cut between characters (a job's filename is shown and
/// stored as JSON, which must be UTF-8: "%FF.obj" used to give a 500). ASCII control characters
/// (NUL, CR, LF, ...; a filename had them, then its download's filename* too) become U+FFFD as well.
std::string utf8_prefix(std::string_view text, std::size_t max_bytes);

/// Limits of the service (0 = none).
struct UploadLimits {
  std::size_t max_faces = 0;          ///< faces of the input
  int max_iterations = 0;             ///< iterations parameter
  std::size_t max_output_faces = 0;   ///< estimated faces of the result
};

/// A validated job, ready to queue.
struct PreparedJob {
  JobRecord record;  ///< id, state queued, created_at, params, input info; nothing stored yet
  LoadedMesh mesh;   ///< the repaired input
};

/// Validates parameters (ParamsError with every bad field, before reading), reads the mesh
/// (MeshError with the reader's message), checks faces and estimated output faces (LimitError).
/// An empty `filename` becomes "mesh.<format read>".
PreparedJob prepare_job(std::string_view bytes, std::string_view filename, std::optional<Format> format,
                        ParsedParams params, const UploadLimits& limits);

}  // namespace remesh::api
