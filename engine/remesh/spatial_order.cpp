#include "remesh/spatial_order.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/parallel.h"

namespace remesh {

namespace {

/// The bits of x (21 of them) spread to every third bit.
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

/// Old index of each vertex in Morton order of the positions (21 bits a coordinate over the
/// bounding box; ties by old index).
std::vector<unsigned> morton_order(const TriMesh& mesh, unsigned threads) {
  const std::size_t n = mesh.n_vertices();
  constexpr double kBig = std::numeric_limits<double>::max();
  Vec3 lo(kBig, kBig, kBig), hi(-kBig, -kBig, -kBig);
  for (auto v : mesh.vertices()) lo.minimize(mesh.point(v)), hi.maximize(mesh.point(v));
  const Vec3 extent = hi - lo;
  const double largest = std::max({extent[0], extent[1], extent[2]});
  const double scale = largest > 0 ? 2097151.0 / largest : 0.0;  // 2^21 - 1
  std::vector<std::pair<std::uint64_t, unsigned>> keys(n);
  parallel_for(n, threads, [&](std::size_t i) {
    const Vec3 q = (mesh.point(mesh.vertex_handle(static_cast<unsigned>(i))) - lo) * scale;
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double c = q[k] >= 0 ? std::min(q[k], 2097151.0) : 0.0;  // (a NaN goes to 0)
      code |= spread_bits(static_cast<std::uint64_t>(c)) << k;
    }
    keys[i] = {code, static_cast<unsigned>(i)};
  });
  std::sort(keys.begin(), keys.end());
  std::vector<unsigned> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keys[i].second;
  return order;
}

/// The mesh as plain arrays under its new numbers: about 110 bytes a vertex, against a TriMesh's
/// ~180, so that the old mesh can be freed before the new one is built.
struct Numbered {
  struct Halfedge {
    unsigned next, face, vertex;  ///< face: kNone on the boundary
  };
  static constexpr unsigned kNone = std::numeric_limits<unsigned>::max();
  std::vector<Vec3> points;
  std::vector<Halfedge> halfedges;  ///< each edge's halfedge 0 still its halfedge 0
  std::vector<unsigned> face_halfedge, vertex_halfedge;  ///< vertex_halfedge: kNone when isolated
  std::vector<unsigned> new_vertex;  ///< the new index of each old vertex
};

/// Vertices along the curve; faces by their lowest new corner (ties: old order); edges as the faces
/// in their new order first use them.
Numbered numbered(const TriMesh& mesh, unsigned threads) {
  const std::size_t nv = mesh.n_vertices(), ne = mesh.n_edges(), nf = mesh.n_faces();
  constexpr unsigned kNone = Numbered::kNone;
  Numbered out;
  const std::vector<unsigned> vertex_order = morton_order(mesh, threads);
  std::vector<unsigned>& new_vertex = out.new_vertex;
  new_vertex.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) new_vertex[vertex_order[i]] = static_cast<unsigned>(i);
  // Faces by a counting sort on their lowest corner, stable in their old order.
  std::vector<unsigned> lowest(nf, kNone), face_order(nf), first(nv + 1, 0);
  parallel_for(nf, threads, [&](std::size_t f) {
    for (auto v : mesh.fv_range(mesh.face_handle(static_cast<unsigned>(f))))
      lowest[f] = std::min(lowest[f], new_vertex[v.idx()]);
  });
  for (unsigned l : lowest) ++first[l + 1];
  for (std::size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
  for (std::size_t f = 0; f < nf; ++f) face_order[first[lowest[f]]++] = static_cast<unsigned>(f);
  std::vector<unsigned> new_face(nf), new_edge(ne, kNone);
  unsigned edges = 0;
  for (std::size_t i = 0; i < nf; ++i) {
    const auto f = mesh.face_handle(face_order[i]);
    new_face[f.idx()] = static_cast<unsigned>(i);
    for (auto h : mesh.fh_range(f))
      if (unsigned& e = new_edge[mesh.edge_handle(h).idx()]; e == kNone) e = edges++;
  }
  // Edges no face holds (none in a valid triangle mesh) keep their relative order at the end.
  for (unsigned& e : new_edge)
    if (e == kNone) e = edges++;

  auto renumbered = [&](OpenMesh::HalfedgeHandle h) {
    return static_cast<unsigned>(2 * new_edge[h.idx() / 2] + (h.idx() & 1));
  };
  // Each loop writes each element once, at its new index.
  out.halfedges.resize(2 * ne);
  parallel_for(2 * ne, threads, [&](std::size_t i) {
    const OpenMesh::HalfedgeHandle h(static_cast<int>(i));
    const auto f = mesh.face_handle(h);
    out.halfedges[renumbered(h)] = {renumbered(mesh.next_halfedge_handle(h)),
                                    f.is_valid() ? new_face[f.idx()] : kNone,
                                    new_vertex[mesh.to_vertex_handle(h).idx()]};
  });
  out.face_halfedge.resize(nf);
  parallel_for(nf, threads, [&](std::size_t f) {
    out.face_halfedge[new_face[f]] = renumbered(mesh.halfedge_handle(mesh.face_handle(static_cast<unsigned>(f))));
  });
  out.vertex_halfedge.assign(nv, kNone);
  out.points.resize(nv);
  parallel_for(nv, threads, [&](std::size_t i) {
    const auto v = mesh.vertex_handle(vertex_order[i]);
    if (const auto h = mesh.halfedge_handle(v); h.is_valid()) out.vertex_halfedge[i] = renumbered(h);
    out.points[i] = mesh.point(v);
  });
  return out;
}

}  // namespace

std::vector<unsigned> spatial_order(TriMesh& mesh, unsigned threads) {
  Numbered plain = numbered(mesh, threads);
  free_mesh(mesh);  // before the new one is built
  const std::size_t nv = plain.points.size(), ne = plain.halfedges.size() / 2, nf = plain.face_halfedge.size();
  // Room for the splits of the iterations until the next numbering (a few % of the vertices each,
  // once a refinement nears its size): without it the first split doubles each of OpenMesh's
  // arrays, copying them while the old ones are still held. Measured (Table 4.2 setup, peak RSS):
  // nefertiti 105.1 -> 94.5 MB, armadillo 103.0 -> 86.1 MB, kitten 25.7 -> 23.7 MB; nefertiti
  // at 415 000 vertices 358 -> 343 MB; 1.2-1.3 did about as well, 1.5 worse (nefertiti 116 MB).
  constexpr double kRoom = 1.15;
  auto room = [](std::size_t n) { return static_cast<std::size_t>(kRoom * static_cast<double>(n)); };
  mesh.reserve(room(nv), room(ne), room(nf));
  for (const Vec3& p : plain.points) mesh.add_vertex(p);
  std::vector<Vec3>().swap(plain.points);
  for (std::size_t e = 0; e < ne; ++e)
    mesh.new_edge(OpenMesh::VertexHandle(static_cast<int>(plain.halfedges[2 * e + 1].vertex)),
                  OpenMesh::VertexHandle(static_cast<int>(plain.halfedges[2 * e].vertex)));
  for (std::size_t i = 0; i < nf; ++i) mesh.new_face();
  for (std::size_t h = 0; h < plain.halfedges.size(); ++h) {
    const OpenMesh::HalfedgeHandle g(static_cast<int>(h));
    mesh.set_next_halfedge_handle(g, OpenMesh::HalfedgeHandle(static_cast<int>(plain.halfedges[h].next)));
    if (const unsigned f = plain.halfedges[h].face; f != Numbered::kNone)
      mesh.set_face_handle(g, OpenMesh::FaceHandle(static_cast<int>(f)));
  }
  for (std::size_t f = 0; f < nf; ++f)
    mesh.set_halfedge_handle(OpenMesh::FaceHandle(static_cast<int>(f)),
                             OpenMesh::HalfedgeHandle(static_cast<int>(plain.face_halfedge[f])));
  for (std::size_t v = 0; v < nv; ++v)
    if (const unsigned h = plain.vertex_halfedge[v]; h != Numbered::kNone)
      mesh.set_halfedge_handle(OpenMesh::VertexHandle(static_cast<int>(v)), OpenMesh::HalfedgeHandle(static_cast<int>(h)));
  return std::move(plain.new_vertex);
}

}  // namespace remesh
