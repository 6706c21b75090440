#include "remesh/geometry.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/parallel.h"

namespace remesh::geom {

double min_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double la = (b - c).sqrnorm(), lb = (c - a).sqrnorm(), lc = (a - b).sqrnorm();
  const double area2 = cross_normal(a, b, c).norm();
  if (!(area2 > 0) || la == 0 || lb == 0 || lc == 0) return 0;
  // The smallest angle is opposite the shortest side: sin(angle) = area2 / (|x| |y|).
  double angle;
  if (la <= lb && la <= lc) {
    angle = std::atan2(area2, (b - a) | (c - a));
  } else if (lb <= la && lb <= lc) {
    angle = std::atan2(area2, (a - b) | (c - b));
  } else {
    angle = std::atan2(area2, (a - c) | (b - c));
  }
  return angle;
}

bool below_min_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  // The smallest angle lies opposite the shortest side, between the two longer ones, and is at
  // most 60 degrees, where the sine grows with the angle: area2 / (|x| |y|) is its sine. Well
  // above sin(kMinAngle) (a relative margin far beyond rounding) the angle is above kMinAngle;
  // else min_angle() decides, so that the answer is always min_angle()'s.
  static const double sin_min = std::sin(kMinAngle) * (1 + 1e-6);
  const double la = (b - c).sqrnorm(), lb = (c - a).sqrnorm(), lc = (a - b).sqrnorm();
  const double longer = la <= lb && la <= lc ? lb * lc : (lb <= lc ? la * lc : la * lb);
  if (longer > 0 && cross_normal(a, b, c).norm() > sin_min * std::sqrt(longer)) return false;
  return min_angle(a, b, c) < kMinAngle;
}

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab | ap, d2 = ac | ap;
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab | bp, d4 = ac | bp;
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab | cp, d6 = ac | cp;
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = va + vb + vc;
  if (!(denom > 0)) return a;  // degenerate triangle
  const double v = vb / denom, w = vc / denom;
  return a + ab * v + ac * w;
}

Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double l2 = ab.sqrnorm();
  if (!(l2 > 0)) return a;
  const double t = std::clamp(((p - a) | ab) / l2, 0.0, 1.0);
  return a + ab * t;
}

bool normals_agree(const Vec3& before, const Vec3& after, double min_cos) {
  const double nb = before.norm(), na = after.norm();
  if (!(nb > 0) || !(na > 0)) return false;
  return (before | after) > min_cos * nb * na;
}

bool adjacent_ok(const Vec3& f_before, const Vec3& g_before, const Vec3& f_after, const Vec3& g_after,
                 double min_cos) {
  const double na = f_after.norm() * g_after.norm();
  if (!(na > 0)) return false;
  if ((f_after | g_after) >= 0) return true;  // cos_after >= 0 >= min_cos
  const double cos_after = (f_after | g_after) / na;
  if (cos_after >= min_cos) return true;
  const double nb = f_before.norm() * g_before.norm();
  return nb > 0 && cos_after >= (f_before | g_before) / nb;
}

void face_vertices(const TriMesh& mesh, OpenMesh::FaceHandle f, OpenMesh::VertexHandle out[3]) {
  auto h = mesh.halfedge_handle(f);
  out[0] = mesh.to_vertex_handle(h);
  h = mesh.next_halfedge_handle(h);
  out[1] = mesh.to_vertex_handle(h);
  h = mesh.next_halfedge_handle(h);
  out[2] = mesh.to_vertex_handle(h);
}

Vec3 face_normal(const TriMesh& mesh, OpenMesh::FaceHandle f) {
  OpenMesh::VertexHandle v[3];
  face_vertices(mesh, f, v);
  return cross_normal(mesh.point(v[0]), mesh.point(v[1]), mesh.point(v[2]));
}

Vec3 vertex_normal(const TriMesh& mesh, OpenMesh::VertexHandle v) {
  Vec3 n(0, 0, 0);
  for (auto f : mesh.vf_range(v)) n += face_normal(mesh, f);
  const double len = n.norm();
  return len > 0 ? n / len : Vec3(0, 0, 0);
}

std::vector<Vec3> face_normals(const TriMesh& mesh, unsigned threads) {
  std::vector<Vec3> normals(mesh.n_faces(), Vec3(0, 0, 0));
  parallel_for(mesh.n_faces(), threads, [&](std::size_t i) {
    const auto f = mesh.face_handle(static_cast<unsigned>(i));
    if (!mesh.status(f).deleted()) normals[i] = face_normal(mesh, f);
  });
  return normals;
}

std::vector<Vec3> vertex_normals(const TriMesh& mesh, unsigned threads) {
  // Each face's normal once (not once per corner); summed in vertex_normal's order, so the same bits.
  const std::vector<Vec3> faces = face_normals(mesh, threads);
  std::vector<Vec3> normals(mesh.n_vertices(), Vec3(0, 0, 0));
  parallel_for(mesh.n_vertices(), threads, [&](std::size_t i) {
    Vec3 n(0, 0, 0);
    for (auto f : mesh.vf_range(mesh.vertex_handle(static_cast<unsigned>(i)))) n += faces[f.idx()];
    const double len = n.norm();
    normals[i] = len > 0 ? n / len : Vec3(0, 0, 0);
  });
  return normals;
}

double star_min_angle(const TriMesh& mesh, OpenMesh::VertexHandle v) {
  double worst = M_PI;
  for (auto f : mesh.vf_range(v)) {
    OpenMesh::VertexHandle c[3];
    face_vertices(mesh, f, c);
    worst = std::min(worst, min_angle(mesh.point(c[0]), mesh.point(c[1]), mesh.point(c[2])));
  }
  return worst;
}

namespace {
/// Normal of face f with vertex v moved to p.
Vec3 moved_normal(const TriMesh& mesh, OpenMesh::FaceHandle f, OpenMesh::VertexHandle v, const Vec3& p) {
  OpenMesh::VertexHandle c[3];
  face_vertices(mesh, f, c);
  Vec3 q[3];
  for (int k = 0; k < 3; ++k) q[k] = c[k] == v ? p : mesh.point(c[k]);
  return cross_normal(q[0], q[1], q[2]);
}
}  // namespace

double angle_deficit(const TriMesh& mesh, OpenMesh::VertexHandle v) {
  double angles = 0;
  for (auto h : mesh.voh_range(v)) {
    if (mesh.is_boundary(h)) return 0;
    const Vec3 a = mesh.point(mesh.to_vertex_handle(h)) - mesh.point(v);
    const Vec3 b = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h))) - mesh.point(v);
    const double na = a.norm(), nb = b.norm();
    if (!(na > 0) || !(nb > 0)) return 0;
    angles += std::acos(std::clamp((a | b) / (na * nb), -1.0, 1.0));
  }
  return 2 * M_PI - angles;
}

bool move_is_safe(const TriMesh& mesh, OpenMesh::VertexHandle v, const Vec3& p, double min_adjacent_cos) {
  AngleFloor floor([&] { return star_min_angle(mesh, v); });
  // The star's faces with their normals before and after the move, each computed once (the fold
  // checks read each star face's two or three times); kept per thread to spare an allocation.
  struct StarFace {
    OpenMesh::FaceHandle f;
    Vec3 q[3];  ///< corners after the move
    Vec3 before, after;
  };
  thread_local std::vector<StarFace> star;
  star.clear();
  for (auto f : mesh.vf_range(v)) {
    StarFace& s = star.emplace_back();
    s.f = f;
    OpenMesh::VertexHandle c[3];
    face_vertices(mesh, f, c);
    for (int k = 0; k < 3; ++k) s.q[k] = c[k] == v ? p : mesh.point(c[k]);
    s.before = face_normal(mesh, f);
    s.after = cross_normal(s.q[0], s.q[1], s.q[2]);  // moved_normal(mesh, f, v, p)
  }
  auto normals = [&](OpenMesh::FaceHandle g, Vec3& before, Vec3& after) {
    for (const StarFace& s : star)
      if (s.f == g) {
        before = s.before, after = s.after;
        return;
      }
    before = face_normal(mesh, g), after = moved_normal(mesh, g, v, p);
  };
  // No fold between a face of the star and any of its neighbours.
  for (auto h : mesh.voh_range(v)) {
    const auto f = mesh.face_handle(h);
    if (!f.is_valid()) continue;
    Vec3 f_before, f_after;
    normals(f, f_before, f_after);
    for (auto g : {mesh.opposite_face_handle(h), mesh.opposite_face_handle(mesh.next_halfedge_handle(h))}) {
      if (!g.is_valid()) continue;
      Vec3 g_before, g_after;
      normals(g, g_before, g_after);
      if (!adjacent_ok(f_before, g_before, f_after, g_after, min_adjacent_cos)) return false;
    }
  }
  for (const StarFace& s : star) {
    if (!normals_agree(s.before, s.after)) return false;
    if (floor.breaks(s.q[0], s.q[1], s.q[2])) return false;
  }
  return true;
}

}  // namespace remesh::geom
