/// \file cmd_convert.cpp
/// `remesh convert IN OUT [--weld] [--quiet]`: read (validate, repair), write in the format of OUT's extension.

#include <iostream>

#include "args.h"
#include "commands.h"

namespace remesh::cli {
namespace {

const std::vector<OptionSpec> kSpec = {
    {"weld", "", "weld duplicate vertices at the same position while reading"},
    {"quiet", "", "do not report repairs and counts"},
};

}  // namespace

int run_convert(const std::vector<std::string>& args) {
  if (wants_help(args)) {
    std::cout << format_help("remesh convert IN OUT [--weld] [--quiet]",
                             "Reads IN (obj, off, ply, stl, gltf, glb), repairs it as 'remesh info' reports,\n"
                             "and writes OUT in the format of its extension: .obj, .off, .ply (binary),\n"
                             ".stl (binary), .glb (binary glTF), .gltf (text glTF, its buffer inside as\n"
                             "base64), .xyz (one atom per vertex) or .lammps (.lmp, .data: a LAMMPS data\n"
                             "file, an atom per vertex and a bond per edge).",
                             kSpec);
    return 0;
  }
  const Args a = parse_args(args, kSpec, 2, 2);
  const std::string& out = a.positional[1];
  const LoadedMesh loaded = read_input_for(a.positional[0], out, a.has("weld"));
  write_mesh_file(to_soup(loaded.mesh), out);
  if (!a.has("quiet")) {
    print_repairs(std::cerr, loaded.repairs);
    std::cerr << "wrote " << out << ": " << loaded.mesh.n_vertices() << " vertices, " << loaded.mesh.n_faces()
              << " faces\n";
  }
  return 0;
}

}  // namespace remesh::cli
