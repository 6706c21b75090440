/// \file cmd_info.cpp
/// `remesh info MESH [--json] [--weld]`: the summary of a mesh, its faces that cross each other,
/// and every repair made reading it.

#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "args.h"
#include "commands.h"
#include "io/summary.h"
#include "api/json_codec.h"
#include "remesh/self_intersections.h"

namespace remesh::cli {
namespace {

const std::vector<OptionSpec> kSpec = {
    {"json", "", "print one JSON object instead of text"},
    {"weld", "", "weld duplicate vertices at the same position while reading"},
};

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string point(const Vec3& p) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", p[0], p[1], p[2]);
  return buf;
}

/// The mesh's pairs of faces that cross each other (find_input_self_intersections), or nullopt when
/// too many of its faces overlap to count them. A mesh that crosses itself is no
/// valid solid for finite elements or a simulation box, and its remeshed surface crosses itself
/// where it does.
using Crossing = std::optional<std::size_t>;

void print_summary(std::ostream& out, const std::string& file, const LoadedMesh& loaded, const MeshSummary& s,
                   const Crossing& crossing) {
  out << file << " (" << format_name(loaded.format) << ")\n";
  out << "  vertices        " << s.vertices << "\n";
  out << "  faces           " << s.faces << "\n";
  out << "  edges           " << s.edges << "\n";
  out << "  components      " << s.components << "\n";
  out << "  boundary loops  " << s.boundary_loops << " (" << s.boundary_edges << " boundary edges)\n";
  out << "  Euler           " << s.euler << "\n";
  constexpr std::size_t kMaxListed = 20;
  for (std::size_t i = 0; i < s.per_component.size() && i < kMaxListed; ++i) {
    const auto& c = s.per_component[i];
    out << "  component " << i << ": " << c.vertices << " vertices, " << c.faces << " faces, ";
    if (c.closed)
      out << "closed, genus " << c.genus;
    else
      out << "open, " << c.boundary_loops << " boundary loop" << (c.boundary_loops == 1 ? "" : "s");
    out << ", Euler " << c.euler << "\n";
  }
  if (s.per_component.size() > kMaxListed)
    out << "  ... " << s.per_component.size() - kMaxListed << " more components\n";
  out << "  bbox            " << point(s.bbox_min) << " - " << point(s.bbox_max) << ", diagonal "
      << fmt(s.bbox_diagonal) << "\n";
  out << "  edge length     mean " << fmt(s.mean_edge) << ", min " << fmt(s.min_edge) << ", max "
      << fmt(s.max_edge) << "\n";
  out << "  area            " << fmt(s.area) << "\n";
  if (!crossing)
    out << "  crossing faces  not counted: too many faces overlap (the surface lies over itself throughout, as a "
           "part duplicated in place does, or is made of long slivers)\n";
  else
    out << "  crossing faces  " << *crossing << " pairs"
        << (*crossing ? " (faces passing through each other: the surface crosses itself)" : "") << "\n";
  if (loaded.repairs.empty()) {
    out << "repairs: none\n";
  } else {
    out << "repairs (" << loaded.repairs.size() << "):\n";
    print_repairs(out, loaded.repairs);
  }
}

/// The API's summary JSON (same field names as remeshd), plus the file, its format and the
/// per-component details the text output shows.
std::string info_json(const std::string& file, const LoadedMesh& loaded, const MeshSummary& s,
                      const Crossing& crossing) {
  nlohmann::json j = summary_json(s, loaded.repairs);
  j["file"] = file;
  j["crossing_pairs"] = crossing ? nlohmann::json(*crossing) : nlohmann::json(nullptr);
  j["layered"] = !crossing;
  j["format"] = std::string(format_name(loaded.format));
  nlohmann::json components = nlohmann::json::array();
  for (const auto& c : s.per_component)
    components.push_back({{"vertices", c.vertices}, {"faces", c.faces}, {"edges", c.edges},
                          {"boundary_loops", c.boundary_loops}, {"euler", c.euler}, {"genus", c.genus},
                          {"closed", c.closed}});
  j["per_component"] = components;
  return j.dump(2);
}

}  // namespace

int run_info(const std::vector<std::string>& args) {
  if (wants_help(args)) {
    std::cout << format_help("remesh info MESH [--json] [--weld]",
                             "Reads MESH (obj, off, ply, stl, gltf, glb), validates and repairs it, and prints\n"
                             "its summary: counts, components, boundary loops, Euler characteristic, genus of\n"
                             "each closed component, bounding box, edge lengths, the pairs of faces that cross\n"
                             "each other, and every repair made.",
                             kSpec);
    return 0;
  }
  const Args a = parse_args(args, kSpec, 1, 1);
  const std::string& file = a.positional[0];
  require_input_file(file);
  ReadOptions options;
  options.weld = a.has("weld");
  const LoadedMesh loaded = read_mesh_file(file, options);
  const MeshSummary summary = summarize(loaded.mesh);
  Crossing crossing;
  if (const auto pairs = find_input_self_intersections(loaded.mesh, 0)) crossing = pairs->size();
  if (a.has("json"))
    std::cout << info_json(file, loaded, summary, crossing) << "\n";
  else
    print_summary(std::cout, file, loaded, summary, crossing);
  return 0;
}

}  // namespace remesh::cli
