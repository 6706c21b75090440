#pragma once
/// \file commands.h
/// The commands of the `remesh` tool and the helpers they share. Each command takes its own
/// arguments (without the program and command names) and returns the exit code; errors are thrown
/// and mapped to exit codes by main(): UsageError/ParamsError -> 2, MeshError/LimitError -> 3,
/// anything else -> 1.

#include <iosfwd>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dual/dual_stats.h"
#include "io/mesh_io.h"

namespace remesh::cli {

int run_info(const std::vector<std::string>& args);
int run_convert(const std::vector<std::string>& args);
int run_dual(const std::vector<std::string>& args);
int run_remesh(const std::vector<std::string>& args);

/// Throws UsageError unless `path` names an existing regular file.
void require_input_file(const std::string& path);
/// The format to write `path` in, from its extension. Throws UsageError for an unknown extension,
/// and when the directory of `path` does not exist.
Format require_output_format(const std::string& path);
/// Throws UsageError unless a file can be written at `path`: its directory exists and takes a new
/// file, and `path` is no directory.
void require_writable(const std::string& path);
/// An output of a command: what names it on the command line ("OUT", "--dual") and its path, if given.
using NamedOutput = std::pair<std::string, std::optional<std::string>>;
/// Throws UsageError when two of `outputs` name the same file, however spelled ("a.obj",
/// "./a.obj", "dir/../a.obj", a symbolic or hard link): the later write would replace the earlier.
void require_distinct_outputs(const std::vector<NamedOutput>& outputs);
/// Throws UsageError when `path` (an output named `name` on the command line) is the file IN names,
/// however spelled: the dual or the statistics written over the input mesh lose it. (OUT of the
/// remeshing and converting commands may replace IN: IN is read before anything is written.)
void require_not_input(const std::string& in, const std::string& name, const std::optional<std::string>& path);
/// The prologue of commands that read IN and write OUT: checks IN exists and OUT's format and
/// directory before reading (so no work is wasted on a bad OUT), then reads IN.
LoadedMesh read_input_for(const std::string& in, const std::string& out, bool weld);
/// One line per repair ("  kind (count): detail"); nothing when there were none.
void print_repairs(std::ostream& out, const std::vector<Repair>& repairs);
/// The dual's summary lines: atoms, bonds and rings by size; bond lengths; with an interval
/// (DualStats::bond_max > 0), the bonds inside it.
void print_dual_stats(std::ostream& out, const DualStats& s);

}  // namespace remesh::cli
