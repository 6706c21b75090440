#pragma once
/// \file json_codec.h
/// JSON (nlohmann) and CSV views of the engine's value types, and parameter parsing from JSON or a
/// string map (query string, command line). Shared by remeshd and the `remesh` CLI.
///
/// Parameter names (API, CLI, JSON): emin, emax, iterations, rings, relax_every, flip_factor,
/// run_all_iterations, protect_tips, keep_creases, more_regular, relax_dual; `weld` is a read option carried
/// alongside (ParsedParams::weld); bond_min and bond_max give the interval as the dual's bond lengths
/// instead of emin and emax (ParsedParams::bonds).

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "io/mesh_io.h"
#include "io/summary.h"
#include "remesh/equalize.h"
#include "remesh/params.h"

namespace remesh {

// ---- engine values -> JSON (ADL hooks, so `nlohmann::json j = summary;` works) ----------------

/// {vertices, faces, edges, components, boundary_loops, boundary_edges, euler,
///  genus: [genus of each closed component], bbox {min:[x,y,z], max:[x,y,z], diagonal},
///  edge_length {mean, min, max}, area}
void to_json(nlohmann::json& j, const MeshSummary& s);
/// {kind, count, detail}
void to_json(nlohmann::json& j, const Repair& r);
/// Every IterationStats field under its struct name, in struct order.
void to_json(nlohmann::json& j, const IterationStats& s);
/// Reads a row written by to_json; missing fields stay 0. Throws nlohmann::json::exception on
/// wrong types.
void from_json(const nlohmann::json& j, IterationStats& s);
/// {emin, emax, iterations, rings, relax_every, flip_factor, run_all_iterations, protect_tips,
/// keep_creases, more_regular, relax_dual}
void to_json(nlohmann::json& j, const Params& p);
/// {field, message}
void to_json(nlohmann::json& j, const FieldError& e);

/// Summary JSON with the repairs added under "repairs" (the CLI's `--summary` output).
nlohmann::json summary_json(const MeshSummary& s, const std::vector<Repair>& repairs);

// ---- parameters ---------------------------------------------------------------------------------

/// An interval given as the trivalent dual's bond lengths (atom lattices: carbon's 1.42 angstrom).
/// For equilateral triangles of side a the dual edge is a / sqrt(3) (ALGORITHM.md), so bonds in
/// [min, max] ask for edges in [min, max] * sqrt(3) (edge_for_bond, dual/dual_stats.h).
struct BondInterval {
  double min = 0, max = 0;  ///< as given; 0 where missing or unreadable
};

/// The result of parsing parameters: the values that parsed, and every bad field.
struct ParsedParams {
  Params params;                   ///< defaults where a field was absent or bad
  bool weld = false;               ///< read option: weld duplicate vertices
  /// Set when the interval was given as bond_min and bond_max (or one of them) instead of emin and
  /// emax: params.e_min and e_max then hold the bonds times sqrt(3), and errors about the interval
  /// name the bond fields (validate_params, check_interval_against).
  std::optional<BondInterval> bonds;
  /// A bond field is missing, or bonds and edges were both given: the interval is unknown, and
  /// validate_params() adds no range error about it.
  bool interval_unknown = false;
  std::vector<FieldError> errors;  ///< empty when every field parsed (range checks: check())
  std::vector<std::string> given;  ///< names of the parameters present in the input
  bool ok() const { return errors.empty(); }
};

/// Parameter names accepted by params_from_json / params_from_query, in documentation order.
const std::vector<std::string>& param_names();

/// Parses a JSON object. Reports type errors ("must be a number"), missing emin/emax ("is
/// required"), unknown keys ("unknown parameter") and a non-object document. Does not range-check:
/// call validate_params() (or remesh::check) on the result.
ParsedParams params_from_json(const nlohmann::json& j);

/// Parses string values (query string, CLI options): numbers in C locale, integers without
/// fraction, booleans as true/false/1/0/yes/no/on/off (empty = true). Keys listed in `ignore`
/// (e.g. "format") are skipped; other unknown keys are errors. Does not range-check.
ParsedParams params_from_query(const std::map<std::string, std::string>& values,
                               const std::vector<std::string>& ignore = {});

/// Parsing errors plus the engine's range checks (remesh::check) for fields that parsed, and
/// `iterations` against `max_iterations` (the service's limit, 0 = engine default). When
/// `iterations` was not given, the default is lowered to `max_iterations` if above it. Defined in
/// params_validation.cpp (links the remesher library).
std::vector<FieldError> validate_params(ParsedParams& parsed, int max_iterations = 0);

/// check_against(mesh, params) (remesh/equalize.h: emin against the mesh's size), its errors said
/// in bond lengths when the interval was given so (`bonds`): field bond_min, the bound divided by
/// sqrt(3).
std::vector<FieldError> check_interval_against(const TriMesh& mesh, const Params& params, bool bonds);

/// A parameter's name and the name it is given instead (renamed()).
using Rename = std::pair<std::string_view, std::string_view>;

/// `errors` with parameters named otherwise: each field named `first` becomes `second`, and so does
/// each whole word `first` in the messages (not "emin" within "bond_emin"). For the bond fields, the
/// CLI's options, ...
std::vector<FieldError> renamed(std::vector<FieldError> errors, const std::vector<Rename>& names);

/// Errors about emin and emax said as the bond fields gave them: the fields emin and emax become
/// bond_min and bond_max, in the field names and in the messages ("must be greater than bond_min").
std::vector<FieldError> in_bond_terms(std::vector<FieldError> errors);

// ---- statistics as CSV --------------------------------------------------------------------------

/// "iteration,vertices,edges,mean,..." (IterationStats field names in struct order), no newline.
std::string stats_csv_header();
/// One row, values in header order, shortest round-trip decimal form, no newline.
std::string stats_csv_row(const IterationStats& s);
/// Header and rows, each line ending in '\n'.
std::string stats_to_csv(const std::vector<IterationStats>& rows);

/// Shortest decimal text that reads back as exactly `v` ("0.1", "1e-07"); "null" for NaN/inf.
std::string format_double(double v);

}  // namespace remesh
