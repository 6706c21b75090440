#include "remesh/mesh_snapshot.h"

#include <stdexcept>

#include "remesh/geometry.h"

namespace remesh {

MeshSnapshot::MeshSnapshot(const TriMesh& mesh) {
  std::vector<std::uint32_t> index(mesh.n_vertices(), UINT32_MAX);
  points_.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    if (mesh.status(v).deleted()) continue;
    index[v.idx()] = static_cast<std::uint32_t>(points_.size());
    points_.push_back(mesh.point(v));
  }
  faces_.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    if (mesh.status(f).deleted()) continue;
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(mesh, f, c);
    faces_.push_back({index[c[0].idx()], index[c[1].idx()], index[c[2].idx()]});
  }
}

void MeshSnapshot::rebuild(TriMesh& mesh) const {
  free_mesh(mesh);
  mesh.reserve(points_.size(), faces_.size() * 3 / 2 + 3, faces_.size());
  for (const Vec3& p : points_) mesh.add_vertex(p);
  for (const auto& t : faces_) {
    const auto f = mesh.add_face(mesh.vertex_handle(t[0]), mesh.vertex_handle(t[1]), mesh.vertex_handle(t[2]));
    // The faces came from a valid mesh, so this cannot happen; say so if it ever does.
    if (!f.is_valid()) throw std::logic_error("a mesh snapshot could not be rebuilt");
  }
}

}  // namespace remesh
