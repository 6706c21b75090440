/// \file trivalent_dual.cpp
/// Builds the dual directly with add_vertex/add_face (OpenMesh's Dualizer orients faces inward).

#include "dual/trivalent_dual.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "core/errors.h"

#ifdef REMESH_DUAL_HAS_REFERENCE
#include "remesh/reference_surface.h"
#endif

namespace remesh {
namespace {

bool has_deleted_elements(const TriMesh& mesh) {
  for (auto v : mesh.all_vertices())
    if (mesh.status(v).deleted()) return true;
  for (auto e : mesh.all_edges())
    if (mesh.status(e).deleted()) return true;
  for (auto f : mesh.all_faces())
    if (mesh.status(f).deleted()) return true;
  return false;
}

/// Unit normal of a triangle from its corner positions (zero for a degenerate triangle).
Vec3 triangle_normal(const TriMesh& mesh, OpenMesh::FaceHandle f) {
  auto h = mesh.halfedge_handle(f);
  const Vec3& a = mesh.point(mesh.from_vertex_handle(h));
  const Vec3& b = mesh.point(mesh.to_vertex_handle(h));
  const Vec3& c = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
  Vec3 n = OpenMesh::cross(b - a, c - a);
  const double len = n.norm();
  return len > 0 ? n / len : Vec3(0, 0, 0);
}

Vec3 centroid(const TriMesh& mesh, OpenMesh::FaceHandle f) {
  Vec3 sum(0, 0, 0);
  int n = 0;
  for (auto v : mesh.fv_range(f)) {
    sum += mesh.point(v);
    ++n;
  }
  return n > 0 ? sum / n : sum;
}

Vec3 dual_point(const TriMesh& mesh, OpenMesh::FaceHandle f, const ReferenceSurface* reference) {
  const Vec3 c = centroid(mesh, f);
  if (reference == nullptr) return c;
#ifdef REMESH_DUAL_HAS_REFERENCE
  return reference->closest_point(c, triangle_normal(mesh, f));
#else
  (void)triangle_normal;
  throw std::logic_error("trivalent_dual: built without the remesher's ReferenceSurface");
#endif
}

/// The faces around interior vertex v, counter-clockwise seen from the side its normal points to.
/// Walking from an outgoing halfedge h (whose face lies to its left) to opposite(prev(h)) turns
/// counter-clockwise in a consistently oriented mesh.
void faces_ccw(const TriMesh& mesh, OpenMesh::VertexHandle v, std::vector<PolyMesh::VertexHandle>& out) {
  out.clear();
  const auto start = mesh.halfedge_handle(v);
  auto h = start;
  do {
    out.emplace_back(mesh.face_handle(h).idx());
    h = mesh.opposite_halfedge_handle(mesh.prev_halfedge_handle(h));
  } while (h != start && out.size() <= mesh.n_halfedges());
}

PolyMesh build_dual(const TriMesh& primal, const ReferenceSurface* reference) {
  PolyMesh dual;
  dual.reserve(primal.n_faces(), primal.n_edges(), primal.n_vertices());
  for (auto f : primal.faces()) dual.add_vertex(dual_point(primal, f, reference));

  std::vector<PolyMesh::VertexHandle> ring;
  for (auto v : primal.vertices()) {
    if (primal.is_isolated(v) || primal.is_boundary(v)) continue;
    faces_ccw(primal, v, ring);
    if (ring.size() < 3)
      throw MeshError("trivalent_dual: interior vertex " + std::to_string(v.idx()) + " has only " +
                      std::to_string(ring.size()) + " incident faces");
    if (!dual.add_face(ring).is_valid())
      throw MeshError("trivalent_dual: the dual face of vertex " + std::to_string(v.idx()) +
                      " is not manifold (the primal is not a valid oriented 2-manifold)");
  }
  dual.update_normals();
  return dual;
}

}  // namespace

PolyMesh trivalent_dual(const TriMesh& primal, const ReferenceSurface* reference) {
  if (!has_deleted_elements(primal)) return build_dual(primal, reference);
  TriMesh compact = primal;
  collect_garbage(compact);
  return build_dual(compact, reference);
}

}  // namespace remesh
