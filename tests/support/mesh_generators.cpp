#include "support/mesh_generators.h"

#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>
#include <tuple>
#include <vector>

namespace remesh::test {
namespace {

using VH = TriMesh::VertexHandle;

void add_tri(TriMesh& m, VH a, VH b, VH c) {
  if (!m.add_face(a, b, c).is_valid()) throw std::logic_error("generator produced a non-manifold face");
}

}  // namespace

TriMesh make_icosphere(int subdiv, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> pts = {{-1, t, 0}, {1, t, 0},   {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> tris = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : pts) p.normalize();
  for (int s = 0; s < subdiv; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      pts.push_back(((pts[a] + pts[b]) * 0.5).normalize());
      return mid[key] = int(pts.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (auto [a, b, c] : tris) {
      int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
    }
    tris = std::move(next);
  }
  TriMesh m;
  std::vector<VH> vh;
  for (const auto& p : pts) vh.push_back(m.add_vertex(p * radius));
  for (auto [a, b, c] : tris) add_tri(m, vh[a], vh[b], vh[c]);
  m.update_normals();
  return m;
}

TriMesh make_torus(int nu, int nv, double R, double r) {
  TriMesh m;
  std::vector<VH> vh(std::size_t(nu) * nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
      vh[i * nv + j] = m.add_vertex(
          Vec3((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)));
    }
  auto at = [&](int i, int j) { return vh[((i + nu) % nu) * nv + (j + nv) % nv]; };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      add_tri(m, at(i, j), at(i + 1, j), at(i + 1, j + 1));
      add_tri(m, at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  m.update_normals();
  return m;
}

TriMesh make_open_grid(int nx, int ny, double spacing) {
  TriMesh m;
  std::vector<VH> vh;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) vh.push_back(m.add_vertex(Vec3(i * spacing, j * spacing, 0)));
  auto at = [&](int i, int j) { return vh[j * (nx + 1) + i]; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if ((i + j) % 2 == 0) {
        add_tri(m, at(i, j), at(i + 1, j), at(i + 1, j + 1));
        add_tri(m, at(i, j), at(i + 1, j + 1), at(i, j + 1));
      } else {
        add_tri(m, at(i, j), at(i + 1, j), at(i, j + 1));
        add_tri(m, at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
    }
  m.update_normals();
  return m;
}

TriMesh make_box(int n) {
  TriMesh mesh;
  std::map<std::array<int, 3>, OpenMesh::VertexHandle> at;
  auto vertex = [&](std::array<int, 3> c) {
    auto it = at.find(c);
    if (it != at.end()) return it->second;
    return at[c] = mesh.add_vertex(Vec3(c[0], c[1], c[2]));
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const int u = (axis + 1) % 3, w = (axis + 2) % 3;
          auto corner = [&](int di, int dj) {
            std::array<int, 3> c{};
            c[axis] = side * n, c[u] = i + di, c[w] = j + dj;
            return vertex(c);
          };
          const auto a = corner(0, 0), b = corner(1, 0), c = corner(1, 1), d = corner(0, 1);
          if (side == 1) mesh.add_face(a, b, c), mesh.add_face(a, c, d);
          else mesh.add_face(a, c, b), mesh.add_face(a, d, c);
        }
  return mesh;
}

TriMesh make_fan(int sectors, double radius) {
  TriMesh m;
  const VH centre = m.add_vertex(Vec3(0, 0, 0));
  std::vector<VH> rim;
  for (int i = 0; i < sectors; ++i) {
    const double a = 2 * M_PI * i / sectors;
    rim.push_back(m.add_vertex(Vec3(radius * std::cos(a), radius * std::sin(a), 0)));
  }
  for (int i = 0; i < sectors; ++i) add_tri(m, centre, rim[i], rim[(i + 1) % sectors]);
  m.update_normals();
  return m;
}

namespace {

/// A cylinder's side as one row of slivers from rim to rim: its rim vertices (bottom and top,
/// added in turn) into `lo` and `hi`.
void add_sliver_side(TriMesh& m, int segments, double radius, double height, std::vector<VH>& lo,
                     std::vector<VH>& hi) {
  for (int i = 0; i < segments; ++i) {
    const double a = 2 * M_PI * i / segments;
    lo.push_back(m.add_vertex(Vec3(radius * std::cos(a), radius * std::sin(a), 0)));
    hi.push_back(m.add_vertex(Vec3(radius * std::cos(a), radius * std::sin(a), height)));
  }
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    add_tri(m, lo[i], lo[j], hi[j]);
    add_tri(m, lo[i], hi[j], hi[i]);
  }
}

}  // namespace

TriMesh make_sliver_cylinder(int segments, double radius, double height) {
  TriMesh m;
  const VH bottom = m.add_vertex(Vec3(0, 0, 0)), top = m.add_vertex(Vec3(0, 0, height));
  std::vector<VH> lo, hi;
  add_sliver_side(m, segments, radius, height, lo, hi);
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    add_tri(m, bottom, lo[j], lo[i]);
    add_tri(m, top, hi[i], hi[j]);
  }
  m.update_normals();
  return m;
}

TriMesh make_rim_fanned_cylinder(int segments, double radius, double height) {
  TriMesh m;
  std::vector<VH> lo, hi;
  add_sliver_side(m, segments, radius, height, lo, hi);
  for (int i = 1; i + 1 < segments; ++i) {
    add_tri(m, lo[0], lo[i + 1], lo[i]);
    add_tri(m, hi[0], hi[i], hi[i + 1]);
  }
  m.update_normals();
  return m;
}

TriMesh make_hex_lattice_patch(int rows, int cols, double spacing) {
  TriMesh m;
  std::vector<VH> vh;
  const double h = spacing * std::sqrt(3.0) / 2.0;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i)
      vh.push_back(m.add_vertex(Vec3(i * spacing + (j % 2) * spacing / 2, j * h, 0)));
  auto at = [&](int i, int j) { return vh[j * cols + i]; };
  for (int j = 0; j + 1 < rows; ++j)
    for (int i = 0; i + 1 < cols; ++i) {
      if (j % 2 == 0) {
        add_tri(m, at(i, j), at(i + 1, j), at(i, j + 1));
        add_tri(m, at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      } else {
        add_tri(m, at(i, j), at(i + 1, j + 1), at(i, j + 1));
        add_tri(m, at(i, j), at(i + 1, j), at(i + 1, j + 1));
      }
    }
  m.update_normals();
  return m;
}

TriMesh make_plate_with_holes(int holes, double cell, int sub) {
  if (holes < 0 || sub < 1) throw std::invalid_argument("make_plate_with_holes");
  // Voxels: a (2*holes+1) x 3 x 1 slab; voxel (2k+1, 1) removed for each hole.
  const int nx = 2 * holes + 1, ny = 3;
  auto solid = [&](int x, int y, int z) {
    if (x < 0 || y < 0 || z != 0 || x >= nx || y >= ny) return false;
    return !(y == 1 && x % 2 == 1);
  };
  TriMesh m;
  std::map<std::tuple<long, long, long>, VH> index;  // grid points in units of cell / sub
  auto vertex = [&](long gx, long gy, long gz) {
    auto key = std::make_tuple(gx, gy, gz);
    auto it = index.find(key);
    if (it != index.end()) return it->second;
    VH v = m.add_vertex(Vec3(gx, gy, gz) * (cell / sub));
    index.emplace(key, v);
    return v;
  };
  // For each solid voxel face whose neighbour is empty: an outward quad split into sub x sub cells.
  const int dirs[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int x = 0; x < nx; ++x)
    for (int y = 0; y < ny; ++y) {
      if (!solid(x, y, 0)) continue;
      for (const auto& d : dirs) {
        if (solid(x + d[0], y + d[1], d[2])) continue;
        const int axis = d[0] ? 0 : d[1] ? 1 : 2;
        const int sign = d[axis];
        const int ua = (axis + 1) % 3, va = (axis + 2) % 3;  // (ua, va, axis) right-handed
        long base[3] = {long(x) * sub, long(y) * sub, 0};
        if (sign > 0) base[axis] += sub;
        for (int a = 0; a < sub; ++a)
          for (int b = 0; b < sub; ++b) {
            auto corner = [&](int da, int db) {
              long g[3] = {base[0], base[1], base[2]};
              g[ua] += a + da;
              g[va] += b + db;
              return vertex(g[0], g[1], g[2]);
            };
            VH p00 = corner(0, 0), p10 = corner(1, 0), p11 = corner(1, 1), p01 = corner(0, 1);
            if (sign > 0) {
              add_tri(m, p00, p10, p11);
              add_tri(m, p00, p11, p01);
            } else {
              add_tri(m, p00, p11, p10);
              add_tri(m, p00, p01, p11);
            }
          }
      }
    }
  m.update_normals();
  return m;
}

TriMesh make_double_torus(double cell, int sub) { return make_plate_with_holes(2, cell, sub); }

TriMesh stacked_copies(const TriMesh& mesh, int copies, const Vec3& offset) {
  TriMesh out;
  for (int c = 0; c < copies; ++c) {
    std::vector<OpenMesh::VertexHandle> added;
    for (auto v : mesh.vertices()) added.push_back(out.add_vertex(mesh.point(v) + double(c) * offset));
    for (auto f : mesh.faces()) {
      std::vector<OpenMesh::VertexHandle> corners;
      for (auto v : mesh.fv_range(f)) corners.push_back(added[v.idx()]);
      out.add_face(corners);
    }
  }
  return out;
}

std::string check_mesh_valid(const TriMesh& mesh, double area_eps, double fold_cos) {
  double total_area = 0;
  std::size_t faces = 0;
  for (auto f : mesh.faces()) {
    if (mesh.status(f).deleted()) return "deleted face " + std::to_string(f.idx()) + " left in the mesh";
    auto h = mesh.halfedge_handle(f);
    if (mesh.next_halfedge_handle(mesh.next_halfedge_handle(mesh.next_halfedge_handle(h))) != h)
      return "face " + std::to_string(f.idx()) + " is not a triangle";
    total_area += mesh.calc_face_area(f);
    ++faces;
  }
  if (faces == 0) return "no faces";
  const double mean_area = total_area / double(faces);
  for (auto f : mesh.faces())
    if (!(mesh.calc_face_area(f) > area_eps * mean_area))
      return "degenerate face " + std::to_string(f.idx());
  for (auto v : mesh.vertices()) {
    if (mesh.status(v).deleted()) return "deleted vertex " + std::to_string(v.idx()) + " left in the mesh";
    if (!mesh.is_manifold(v)) return "non-manifold vertex " + std::to_string(v.idx());
  }
  for (auto e : mesh.edges()) {
    if (mesh.status(e).deleted()) return "deleted edge " + std::to_string(e.idx()) + " left in the mesh";
    if (mesh.is_boundary(e)) continue;
    auto n0 = mesh.calc_face_normal(mesh.face_handle(mesh.halfedge_handle(e, 0)));
    auto n1 = mesh.calc_face_normal(mesh.face_handle(mesh.halfedge_handle(e, 1)));
    if (OpenMesh::dot(n0, n1) < -fold_cos) return "folded triangles at edge " + std::to_string(e.idx());
  }
  return {};
}

std::size_t count_components(const TriMesh& mesh) {
  std::vector<int> parent(mesh.n_vertices());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<char> used(mesh.n_vertices(), 0);
  for (auto e : mesh.edges()) {
    if (mesh.status(e).deleted()) continue;
    int a = mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    int b = mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    used[a] = used[b] = 1;
    parent[find(a)] = find(b);
  }
  std::set<int> roots;
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v)
    if (used[v]) roots.insert(find(int(v)));
  return roots.size();
}

std::size_t count_boundary_loops(const TriMesh& mesh) {
  std::vector<char> seen(mesh.n_halfedges(), 0);
  std::size_t loops = 0;
  for (auto h : mesh.halfedges()) {
    if (mesh.status(mesh.edge_handle(h)).deleted() || !mesh.is_boundary(h) || seen[h.idx()]) continue;
    ++loops;
    auto c = h;
    do {
      seen[c.idx()] = 1;
      c = mesh.next_halfedge_handle(c);
    } while (c != h && !seen[c.idx()]);
  }
  return loops;
}

long euler_characteristic(const TriMesh& mesh) {
  long v = 0, e = 0, f = 0;
  for (auto vh : mesh.vertices())
    if (!mesh.status(vh).deleted() && !mesh.is_isolated(vh)) ++v;
  for (auto eh : mesh.edges())
    if (!mesh.status(eh).deleted()) ++e;
  for (auto fh : mesh.faces())
    if (!mesh.status(fh).deleted()) ++f;
  return v - e + f;
}

}  // namespace remesh::test
