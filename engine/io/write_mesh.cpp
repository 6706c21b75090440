/// \file write_mesh.cpp
/// to_soup(), write_mesh() dispatch and write_mesh_file().

#include <fstream>
#include <stdexcept>

#include "io/writers.h"

namespace remesh {

namespace {

template <class Mesh>
PolygonSoup soup_of(const Mesh& mesh) {
  PolygonSoup soup;
  std::vector<std::uint32_t> index(mesh.n_vertices(), 0);
  soup.points.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) {  // skips deleted vertices
    index[static_cast<std::size_t>(v.idx())] = static_cast<std::uint32_t>(soup.points.size());
    soup.points.push_back(mesh.point(v));
  }
  soup.offsets.reserve(mesh.n_faces() + 1);
  for (auto f : mesh.faces()) {
    for (auto v : mesh.fv_range(f)) soup.indices.push_back(index[static_cast<std::size_t>(v.idx())]);
    soup.offsets.push_back(static_cast<std::uint32_t>(soup.indices.size()));
  }
  return soup;
}

}  // namespace

PolygonSoup to_soup(const TriMesh& mesh) { return soup_of(mesh); }
PolygonSoup to_soup(const PolyMesh& mesh) { return soup_of(mesh); }

std::string write_mesh(const PolygonSoup& soup, Format format) {
  if (soup.offsets.empty() || soup.offsets.back() != soup.indices.size())
    throw std::invalid_argument("write_mesh: malformed PolygonSoup (offsets do not match indices)");
  for (std::uint32_t i : soup.indices)
    if (i >= soup.points.size()) throw std::invalid_argument("write_mesh: PolygonSoup index out of range");
  switch (format) {
    case Format::Obj: return io::write_obj(soup);
    case Format::Off: return io::write_off(soup);
    case Format::Ply: return io::write_ply(soup);
    case Format::Stl: return io::write_stl(soup);
    case Format::Gltf: return io::write_gltf(soup);
    case Format::Glb: return io::write_glb(soup);
    case Format::Xyz: return io::write_xyz(soup);
    case Format::Lammps: return io::write_lammps(soup);
  }
  throw std::invalid_argument("write_mesh: unsupported format");
}

std::string write_mesh(const TriMesh& mesh, Format format) { return write_mesh(to_soup(mesh), format); }
std::string write_mesh(const PolyMesh& mesh, Format format) { return write_mesh(to_soup(mesh), format); }

void write_mesh_file(const PolygonSoup& soup, const std::string& path) {
  const std::optional<Format> format = parse_format(path);
  if (!format)
    throw MeshError("cannot tell the output format from '" + path + "' (use .obj .off .ply .stl .glb .gltf .xyz .lammps)");
  const std::string bytes = write_mesh(soup, *format);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot open '" + path + "' for writing");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) throw std::runtime_error("cannot write '" + path + "'");
}

}  // namespace remesh
