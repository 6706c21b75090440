#include "bench_common.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <stdexcept>
#include <vector>

#include <OpenMesh/Core/IO/MeshIO.hh>

#include "core/parallel.h"
#ifdef REMESH_BENCH_HAS_IO
#include "io/mesh_io.h"
#endif
#include "remesh/geometry.h"
#include "remesh/statistics.h"
#include "remesh/triangle_bvh.h"

namespace remesh::bench {

TriMesh subdivide_midpoints(const TriMesh& mesh) {
  TriMesh out;
  out.reserve(mesh.n_vertices() + mesh.n_edges(), 2 * mesh.n_edges() + 3 * mesh.n_faces(), 4 * mesh.n_faces());
  for (auto v : mesh.vertices()) out.add_vertex(mesh.point(v));
  const std::size_t first_mid = mesh.n_vertices();
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    out.add_vertex(0.5 * (mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h))));
  }
  for (auto f : mesh.faces()) {
    OpenMesh::VertexHandle c[3], m[3];
    int k = 0;
    for (auto h : mesh.fh_range(f)) {  // halfedge k runs from corner k to corner k + 1
      c[k] = OpenMesh::VertexHandle(mesh.from_vertex_handle(h).idx());
      m[k] = OpenMesh::VertexHandle(static_cast<int>(first_mid) + mesh.edge_handle(h).idx());
      ++k;
    }
    out.add_face(c[0], m[0], m[2]);
    out.add_face(m[0], c[1], m[1]);
    out.add_face(m[2], m[1], c[2]);
    out.add_face(m[0], m[1], m[2]);
  }
  return out;
}

TriMesh load_mesh(const std::string& path) {
#ifdef REMESH_BENCH_HAS_IO
  return read_mesh_file(path).mesh;  // the product's reader: validated and repaired
#endif
  TriMesh mesh;
  OpenMesh::IO::Options options;
  if (!OpenMesh::IO::read_mesh(mesh, path, options)) throw std::runtime_error("cannot read mesh " + path);
  if (mesh.n_faces() == 0) throw std::runtime_error("mesh has no faces: " + path);
  // Drop unreferenced vertices (scans carry some).
  for (auto v : mesh.vertices())
    if (mesh.is_isolated(v)) mesh.delete_vertex(v, false);
  collect_garbage(mesh);
  return mesh;
}

void write_off(const TriMesh& mesh, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << std::setprecision(17) << "OFF\n" << mesh.n_vertices() << ' ' << mesh.n_faces() << " 0\n";
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    out << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  }
  for (auto f : mesh.faces()) {
    out << "3";
    for (auto v : mesh.fv_range(f)) out << ' ' << v.idx();
    out << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

double scale_to_mean_edge(TriMesh& mesh, double mean_edge) {
  const double factor = mean_edge / mean_edge_length(mesh, 0);
  for (auto v : mesh.vertices()) mesh.point(v) *= factor;
  return factor;
}

Topology topology_of(const TriMesh& mesh) {
  Topology t;
  std::size_t nv = 0, ne = 0, nf = 0;
  for (auto v : mesh.vertices()) nv += mesh.is_isolated(v) ? 0 : 1;
  ne = mesh.n_edges();
  nf = mesh.n_faces();
  t.euler = static_cast<long>(nv) - static_cast<long>(ne) + static_cast<long>(nf);
  std::vector<char> seen(mesh.n_halfedges(), 0);
  for (auto h : mesh.halfedges()) {
    if (seen[h.idx()] || !mesh.is_boundary(h)) continue;
    ++t.boundary_loops;
    for (auto g = h; !seen[g.idx()]; g = mesh.next_halfedge_handle(g)) seen[g.idx()] = 1;
  }
  std::vector<char> done(mesh.n_vertices(), 0);
  std::vector<OpenMesh::VertexHandle> stack;
  for (auto v : mesh.vertices()) {
    if (done[v.idx()] || mesh.is_isolated(v)) continue;
    ++t.components;
    stack.assign(1, v);
    done[v.idx()] = 1;
    while (!stack.empty()) {
      auto u = stack.back();
      stack.pop_back();
      for (auto w : mesh.vv_range(u))
        if (!done[w.idx()]) done[w.idx()] = 1, stack.push_back(w);
    }
  }
  return t;
}

namespace {

/// Largest distance from the samples of `from` to the surface `to`.
double one_sided(const TriMesh& from, const TriangleBvh& to, std::size_t samples, unsigned threads) {
  double area = 0;
  for (auto f : from.faces()) area += from.calc_face_area(f);
  const double per_area = area > 0 ? static_cast<double>(samples) / area : 0;
  std::vector<OpenMesh::FaceHandle> faces(from.faces().begin(), from.faces().end());
  constexpr std::size_t kBlock = 256;
  std::vector<double> face_max(block_count(faces.size(), kBlock), 0.0);
  parallel_blocks(faces.size(), kBlock, threads, [&](std::size_t b, std::size_t e, std::size_t block) {
    double worst = 0;
    for (std::size_t i = b; i < e; ++i) {
      Vec3 c[3];
      int k = 0;
      for (auto v : from.fv_range(faces[i])) c[k++] = from.point(v);
      // Barycentric grid of n x n subdivisions: (n+1)(n+2)/2 points, about n^2 / 2 per face.
      const double want = from.calc_face_area(faces[i]) * per_area;
      const int n = std::max(1, static_cast<int>(std::ceil(std::sqrt(2.0 * want))));
      for (int u = 0; u <= n; ++u)
        for (int w = 0; u + w <= n; ++w) {
          const double a = double(u) / n, bb = double(w) / n;
          const Vec3 p = c[0] * (1 - a - bb) + c[1] * a + c[2] * bb;
          worst = std::max(worst, to.distance(p));
        }
    }
    face_max[block] = worst;
  });
  return *std::max_element(face_max.begin(), face_max.end());
}

}  // namespace

double hausdorff_distance(const TriMesh& a, const TriMesh& b, std::size_t samples, unsigned threads) {
  const TriangleBvh ra(a), rb(b);
  return std::max(one_sided(a, rb, samples, threads), one_sided(b, ra, samples, threads));
}

std::vector<double> thickness_at(const TriMesh& surface, const std::vector<Vec3>& points,
                                 const std::vector<Vec3>& normals, unsigned threads) {
  struct Face {
    Vec3 a, b, c, n;
  };
  std::vector<Face> faces;
  faces.reserve(surface.n_faces());
  for (auto f : surface.faces()) {
    const Vec3 n = geom::face_normal(surface, f);
    const double l = n.norm();
    if (!(l > 0)) continue;
    Vec3 c[3];
    int k = 0;
    for (auto v : surface.fv_range(f)) c[k++] = surface.point(v);
    faces.push_back({c[0], c[1], c[2], n / l});
  }
  std::vector<double> out(points.size(), std::numeric_limits<double>::infinity());
  parallel_for(points.size(), threads, [&](std::size_t i) {
    double best = std::numeric_limits<double>::infinity();
    for (const Face& f : faces) {
      if ((f.n | normals[i]) > -0.3) continue;
      best = std::min(best, (geom::closest_point_on_triangle(points[i], f.a, f.b, f.c) - points[i]).sqrnorm());
    }
    out[i] = std::sqrt(best);
  }, 1);
  return out;
}

double peak_rss_mib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

}  // namespace remesh::bench
