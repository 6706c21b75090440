#pragma once
/// \file json_out.h
/// JSON for `remesh info --json` and `--stats FILE.json`. Field names follow the engine's structs
/// (and the HTTP API's codecs, which use the same names).

#include <string>
#include <vector>

#include "io/mesh_io.h"
#include "io/summary.h"
#include "remesh/equalize.h"

namespace remesh::cli {

/// One JSON object: file, format, the summary's fields, and "repairs": [{kind, count, detail}].
std::string info_json(const std::string& file, Format format, const MeshSummary& summary,
                      const std::vector<Repair>& repairs);

/// A JSON array of statistics rows, one object per iteration with the stable field names.
std::string stats_json(const std::vector<IterationStats>& rows);

/// CSV with a header line of the stable field names and one line per iteration.
std::string stats_csv(const std::vector<IterationStats>& rows);

}  // namespace remesh::cli
