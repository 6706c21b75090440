/// \file summary.cpp
/// summarize(): counts, components with their genus, boundary loops, bounding box, edge lengths.

#include "io/summary.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/union_find.h"

namespace remesh {

namespace {

/// |d| without overflow: a mesh 1e300 across has edges and a diagonal a double holds, whose
/// squares it does not (they read "inf"). Its area is another matter: 1e600 is no double.
double length(const Vec3& d) { return std::hypot(d[0], d[1], d[2]); }

/// The triangle's area, infinite rather than not a number where it overflows: corners 3e308 apart
/// overflow their differences to inf, whose cross product mixes inf and 0 into NaN. Such a
/// triangle is measured in coordinates scaled by its largest one.
double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double area = 0.5 * OpenMesh::cross(b - a, c - a).norm();
  if (std::isfinite(area)) return area;
  const double k = std::max({a.max_abs(), b.max_abs(), c.max_abs()});
  return 0.5 * OpenMesh::cross(b / k - a / k, c / k - a / k).norm() * k * k;
}

}  // namespace

MeshSummary summarize(const TriMesh& mesh) {
  MeshSummary s;
  const std::size_t nv = mesh.n_vertices();
  std::vector<std::size_t> parent(nv);
  std::iota(parent.begin(), parent.end(), std::size_t{0});

  double edge_sum = 0;
  s.min_edge = std::numeric_limits<double>::infinity();
  for (auto e : mesh.edges()) {
    ++s.edges;
    const auto h = mesh.halfedge_handle(e, 0);
    const std::size_t a = find_root(parent, static_cast<std::size_t>(mesh.from_vertex_handle(h).idx()));
    const std::size_t b = find_root(parent, static_cast<std::size_t>(mesh.to_vertex_handle(h).idx()));
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
    const double len = length(mesh.point(mesh.to_vertex_handle(h)) - mesh.point(mesh.from_vertex_handle(h)));
    edge_sum += len;
    s.min_edge = std::min(s.min_edge, len);
    s.max_edge = std::max(s.max_edge, len);
    if (mesh.is_boundary(e)) ++s.boundary_edges;
  }
  if (s.edges == 0) s.min_edge = 0;
  else s.mean_edge = edge_sum / static_cast<double>(s.edges);

  // Components numbered in order of their lowest vertex index.
  std::vector<std::size_t> component(nv, SIZE_MAX), id_of_root(nv, SIZE_MAX);
  bool first = true;
  for (auto v : mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    const std::size_t r = find_root(parent, i);
    if (id_of_root[r] == SIZE_MAX) {
      id_of_root[r] = s.per_component.size();
      s.per_component.emplace_back();
    }
    component[i] = id_of_root[r];
    ++s.per_component[component[i]].vertices;
    ++s.vertices;
    const Vec3& p = mesh.point(v);
    if (first) s.bbox_min = s.bbox_max = p, first = false;
    s.bbox_min.minimize(p);
    s.bbox_max.maximize(p);
  }
  s.components = s.per_component.size();
  s.bbox_diagonal = length(s.bbox_max - s.bbox_min);
  auto comp_of = [&](TriMesh::VertexHandle v) -> ComponentSummary& {
    return s.per_component[component[static_cast<std::size_t>(v.idx())]];
  };
  for (auto e : mesh.edges()) ++comp_of(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0))).edges;
  for (auto f : mesh.faces()) {
    ++s.faces;
    const auto h = mesh.halfedge_handle(f);
    ++comp_of(mesh.to_vertex_handle(h)).faces;
    const Vec3 a = mesh.point(mesh.from_vertex_handle(h)), b = mesh.point(mesh.to_vertex_handle(h)),
               c = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
    s.area += triangle_area(a, b, c);
  }
  std::vector<bool> seen(mesh.n_halfedges(), false);
  for (auto h : mesh.halfedges()) {
    if (!mesh.is_boundary(h) || seen[static_cast<std::size_t>(h.idx())]) continue;
    ++s.boundary_loops;
    ++comp_of(mesh.from_vertex_handle(h)).boundary_loops;
    auto g = h;
    do {
      seen[static_cast<std::size_t>(g.idx())] = true;
      g = mesh.next_halfedge_handle(g);
    } while (g != h && g.is_valid() && !seen[static_cast<std::size_t>(g.idx())]);
  }
  s.euler = static_cast<long>(s.vertices) - static_cast<long>(s.edges) + static_cast<long>(s.faces);
  for (ComponentSummary& c : s.per_component) {
    c.euler = static_cast<long>(c.vertices) - static_cast<long>(c.edges) + static_cast<long>(c.faces);
    c.closed = c.boundary_loops == 0;
    c.genus = static_cast<int>((2 - c.euler - static_cast<long>(c.boundary_loops)) / 2);
  }
  return s;
}

}  // namespace remesh
