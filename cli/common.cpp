/// \file common.cpp
/// Helpers shared by the commands.

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <ostream>

#include "args.h"
#include "commands.h"

namespace remesh::cli {

void require_input_file(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw UsageError("input file not found: " + path);
  if (std::filesystem::is_directory(status)) throw UsageError("input is a directory, not a mesh file: " + path);
}

Format require_output_format(const std::string& path) {
  auto format = parse_format(path);
  if (!format)
    throw UsageError("cannot tell the output format from '" + path +
                     "' (use .obj, .off, .ply, .stl, .glb, .gltf, .xyz or .lammps)");
  require_writable(path);
  return *format;
}

void require_writable(const std::string& path) {
  // Checked now, not after a long run: the directory the output goes to must exist.
  const auto dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!dir.empty() && !std::filesystem::is_directory(dir, ec))
    throw UsageError("output directory does not exist: " + dir.string());
  if (std::filesystem::is_directory(path, ec)) throw UsageError("output is a directory: " + path);
  // A name longer than the file system takes (the probe below has a short name of its own).
  const std::string name = std::filesystem::path(path).filename().string();
  const long name_max = ::pathconf(dir.empty() ? "." : dir.c_str(), _PC_NAME_MAX);
  if (name_max > 0 && name.size() > static_cast<std::size_t>(name_max))
    throw UsageError("output file name too long (" + std::to_string(name.size()) + " bytes, the file system takes " +
                     std::to_string(name_max) + "): " + path);
  // An existing file must take writing (opened without truncating it: it stays as it is).
  if (std::filesystem::is_regular_file(path, ec)) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) {
      const int error = errno;
      throw UsageError("cannot write " + path + ": " + std::strerror(error));
    }
    ::close(fd);
  }
  // ... and the directory take a file: a file created there and removed at once (a read-only or
  // special file system, or a directory without write permission, refused the output only after
  // the run).
  const std::string probe =
      ((dir.empty() ? std::filesystem::path(".") : dir) / (".remesh-probe-" + std::to_string(::getpid()))).string();
  if (std::FILE* f = std::fopen(probe.c_str(), "wx")) {
    std::fclose(f);
    std::remove(probe.c_str());
  } else {
    const int error = errno;
    throw UsageError("cannot write to the output directory " + (dir.empty() ? std::string(".") : dir.string()) +
                     ": " + std::strerror(error));
  }
}

namespace {

/// The file `path` names: absolute, with "." and ".." and the symbolic links on the way resolved.
std::filesystem::path resolved(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) return fs::path(path).lexically_normal();
  fs::path canonical = fs::weakly_canonical(p, ec);
  p = ec ? p.lexically_normal() : canonical;
  // weakly_canonical stops at a link whose target does not exist yet, but writing through that
  // link creates the target: follow it (a bounded number of hops, links may form a loop).
  for (int hop = 0; hop < 40 && fs::is_symlink(fs::symlink_status(p, ec)); ++hop) {
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) break;
    canonical = fs::weakly_canonical(p.parent_path() / target, ec);  // an absolute target replaces the parent
    if (ec) break;
    p = canonical;
  }
  return p;
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  // equivalent() also catches hard links; it is false (with ec set) while either file is missing.
  return std::filesystem::equivalent(a, b, ec) || resolved(a) == resolved(b);
}

}  // namespace

void require_distinct_outputs(const std::vector<NamedOutput>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const auto& [name, path] = outputs[i];
      const auto& [earlier_name, earlier_path] = outputs[j];
      if (!path || !earlier_path || !same_file(*path, *earlier_path)) continue;
      throw UsageError(name + " names the same file as " + earlier_name + ": " + *path +
                       (*path == *earlier_path ? "" : " and " + *earlier_path));
    }
  }
}

void require_not_input(const std::string& in, const std::string& name, const std::optional<std::string>& path) {
  if (path && same_file(in, *path))
    throw UsageError(name + " names the input file " + in + ": writing it would replace the input mesh");
}

void print_repairs(std::ostream& out, const std::vector<Repair>& repairs) {
  for (const auto& r : repairs) out << "  " << r.kind << " (" << r.count << "): " << r.detail << "\n";
}

void print_dual_stats(std::ostream& out, const DualStats& s) {
  out << "  dual:                 " << s.atoms << " atoms, " << s.bonds << " bonds; rings:";
  bool first = true;
  for (const auto& [sides, count] : s.rings) {
    out << (first ? " " : ", ") << count << " of " << sides << (first ? " sides" : "");
    first = false;
  }
  if (first) out << " none";
  out << "\n";
  char line[256];
  std::snprintf(line, sizeof line, "  bond length:          mean %.6g, deviation %.4g, min %.6g, max %.6g\n", s.mean,
                s.deviation, s.min, s.max);
  out << line;
  if (s.bond_max > 0) {
    std::snprintf(line, sizeof line,
                  "  bonds inside [%.6g, %.6g] = [e_min, e_max] / sqrt(3): %.3f %% (%zu short, %zu long)\n",
                  s.bond_min, s.bond_max, 100.0 * s.inside_fraction(), s.short_bonds, s.long_bonds);
    out << line;
  }
}

LoadedMesh read_input_for(const std::string& in, const std::string& out, bool weld) {
  require_input_file(in);
  require_output_format(out);
  ReadOptions options;
  options.weld = weld;
  return read_mesh_file(in, options);
}

}  // namespace remesh::cli
