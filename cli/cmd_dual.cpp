/// \file cmd_dual.cpp
/// `remesh dual IN OUT`: the trivalent dual of a mesh as it is (centroids lie on the triangles, so
/// no projection is needed).

#include <iostream>

#include "args.h"
#include "commands.h"
#include "dual/trivalent_dual.h"

namespace remesh::cli {
namespace {

const std::vector<OptionSpec> kSpec = {
    {"weld", "", "weld duplicate vertices at the same position while reading"},
    {"quiet", "", "do not report counts"},
};

}  // namespace

int run_dual(const std::vector<std::string>& args) {
  if (wants_help(args)) {
    std::cout << format_help("remesh dual IN OUT [--weld]",
                             "Writes the trivalent dual of IN: one vertex per triangle (its centroid), one\n"
                             "polygon per interior vertex, oriented like IN; boundary vertices give no face.\n"
                             "OUT by extension: .obj/.off/.ply (polygons), .glb/.gltf (triangle fans plus a\n"
                             "LINES primitive of the polygon edges), .stl (fans), .xyz (one carbon atom per vertex),\n"
                             ".lammps/.lmp/.data (LAMMPS data file: a carbon atom per vertex, a bond per edge).",
                             kSpec);
    return 0;
  }
  const Args a = parse_args(args, kSpec, 2, 2);
  const std::string& out = a.positional[1];
  require_not_input(a.positional[0], "OUT", out);
  const LoadedMesh loaded = read_input_for(a.positional[0], out, a.has("weld"));
  const PolyMesh dual = trivalent_dual(loaded.mesh);
  write_mesh_file(to_soup(dual), out);
  if (!a.has("quiet")) {
    print_repairs(std::cerr, loaded.repairs);
    std::cerr << "wrote " << out << ":\n";
    print_dual_stats(std::cerr, dual_stats(dual));
  }
  return 0;
}

}  // namespace remesh::cli
