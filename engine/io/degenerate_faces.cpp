/// \file degenerate_faces.cpp
/// Zero-area triangles repaired on the half-edge mesh by collapses, flips and boundary deletions,
/// each of which keeps the topology (see degenerate_faces.h).

#include "io/degenerate_faces.h"

#include <algorithm>
#include <array>
#include <deque>

namespace remesh::io {

using OpenMesh::EdgeHandle;
using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;

namespace {

/// The edges b - a, c - b, a - c, halved so that no difference overflows and scaled by their
/// largest component so that products neither overflow nor underflow (all 0 if the points
/// coincide). The differences come first: nearby points subtract exactly, so a triangle far
/// smaller than its distance from the origin is measured at its own scale (points scaled first
/// carry a rounding of 1e-16 of their size into it: a collinear triangle 4e-14 across, 1 from the
/// origin, measured 6e-4 of its longest edge squared instead of 0).
std::array<Vec3, 3> scaled_edges(const Vec3& a, const Vec3& b, const Vec3& c) {
  std::array<Vec3, 3> e{b * 0.5 - a * 0.5, c * 0.5 - b * 0.5, a * 0.5 - c * 0.5};
  const double m = std::max({e[0].max_abs(), e[1].max_abs(), e[2].max_abs()});
  if (m > 0)
    for (Vec3& d : e) d /= m;
  return e;
}

}  // namespace

bool zero_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  const std::array<Vec3, 3> e = scaled_edges(a, b, c);
  const double twice_area = OpenMesh::cross(e[0], e[1]).norm();
  const double longest = std::max({e[0].sqrnorm(), e[1].sqrnorm(), e[2].sqrnorm()});
  return !(twice_area > 1e-12 * longest);
}

namespace {

class Repairer {
 public:
  explicit Repairer(TriMesh& mesh) : mesh_(mesh), queued_(mesh.n_faces(), 0) {}

  ZeroAreaRepair run(const std::vector<FaceHandle>& faces) {
    for (const FaceHandle f : faces) enqueue(f);
    // A flip can make a new zero-area face (several collinear points) and a collapse refused now
    // can be allowed after a neighbour's flip: go on while anything succeeds, within a budget
    // that stops flips among collinear points that could undo each other.
    const std::size_t budget = 8 * faces.size() + 64;
    std::size_t operations = 0;
    std::vector<FaceHandle> aside;
    for (;;) {
      const std::size_t before = operations;
      while (!queue_.empty() && operations < budget) {
        const FaceHandle f = queue_.front();
        queue_.pop_front();
        queued_[f.idx()] = 0;
        if (mesh_.status(f).deleted() || !has_zero_area(f)) continue;
        if (repair(f))
          ++operations;
        else
          aside.push_back(f);
      }
      if (operations == before || operations >= budget || aside.empty()) break;
      for (const FaceHandle f : aside) enqueue(f);
      aside.clear();
    }
    for (const FaceHandle f : mesh_.faces())
      if (has_zero_area(f)) result_.left.push_back(f);
    return result_;
  }

 private:
  bool has_zero_area(FaceHandle f) const {
    const HalfedgeHandle h = mesh_.halfedge_handle(f);
    return zero_area(mesh_.point(mesh_.from_vertex_handle(h)),
                     mesh_.point(mesh_.to_vertex_handle(h)),
                     mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h))));
  }

  /// One operation on f; false if none applies.
  bool repair(FaceHandle f) {
    HalfedgeHandle h[3];
    h[0] = mesh_.halfedge_handle(f);
    h[1] = mesh_.next_halfedge_handle(h[0]);
    h[2] = mesh_.next_halfedge_handle(h[1]);
    const std::array<Vec3, 3> e = scaled_edges(mesh_.point(mesh_.from_vertex_handle(h[0])),
                                               mesh_.point(mesh_.from_vertex_handle(h[1])),
                                               mesh_.point(mesh_.from_vertex_handle(h[2])));
    // Squared, of h[k]'s edge.
    const double length[3] = {e[0].sqrnorm(), e[1].sqrnorm(), e[2].sqrnorm()};
    const int shortest = static_cast<int>(std::min_element(length, length + 3) - length);
    const int longest = static_cast<int>(std::max_element(length, length + 3) - length);
    const bool needle = length[shortest] <= 1e-12 * length[longest];
    if (needle && collapse(h[shortest])) return true;
    if (mesh_.is_boundary(mesh_.opposite_halfedge_handle(h[longest])))
      return delete_on_boundary(f, h[longest]);
    // A needle is not flipped: a flip only moves it round its short edge, which only a collapse
    // removes (two needles on one such edge flipped each other back and forth until the budget).
    return !needle && flip(mesh_.edge_handle(h[longest]));
  }

  /// Collapses h's edge, keeping the boundary end, else the one of lower index, where it is: the
  /// ends are within 1e-6 of the face's size of each other, so a midpoint would gain nothing but
  /// a point that is not in the input, and a boundary end keeps the boundary curve.
  bool collapse(HalfedgeHandle h) {
    const VertexHandle a = mesh_.from_vertex_handle(h), b = mesh_.to_vertex_handle(h);
    const bool ba = mesh_.is_boundary(a), bb = mesh_.is_boundary(b);
    if (ba != bb ? ba : a.idx() < b.idx()) h = mesh_.opposite_halfedge_handle(h);
    if (mesh_.is_boundary(mesh_.edge_handle(h)) && !boundary_loop_longer_than_3(mesh_, h)) return false;
    for (const HalfedgeHandle g : {h, mesh_.opposite_halfedge_handle(h)}) {
      if (!mesh_.is_collapse_ok(g) || turns_a_face(g)) continue;
      const VertexHandle kept = mesh_.to_vertex_handle(g);
      mesh_.collapse(g);
      ++result_.collapses;
      for (const FaceHandle f : mesh_.vf_range(kept)) enqueue(f);
      return true;
    }
    return false;
  }

  /// Would collapsing g (its from-vertex onto its to-vertex) turn a face around the from-vertex
  /// over? The ends lie within 1e-6 of the needle's longest edge of each other, but a face smaller
  /// than that beside them can still flip (a needle 1000 long beside faces 1e-4 across).
  bool turns_a_face(HalfedgeHandle g) const {
    const VertexHandle from = mesh_.from_vertex_handle(g), to = mesh_.to_vertex_handle(g);
    const FaceHandle gone0 = mesh_.face_handle(g), gone1 = mesh_.opposite_face_handle(g);
    for (const FaceHandle f : mesh_.vf_range(from)) {
      if (f == gone0 || f == gone1) continue;
      Vec3 before[3], after[3];
      int k = 0;
      for (const VertexHandle v : mesh_.fv_range(f)) {
        before[k] = mesh_.point(v);
        after[k++] = v == from ? mesh_.point(to) : mesh_.point(v);
      }
      const Vec3 n0 = OpenMesh::cross(before[1] - before[0], before[2] - before[0]);
      const Vec3 n1 = OpenMesh::cross(after[1] - after[0], after[2] - after[0]);
      if ((n0 | n1) < 0) return true;
    }
    return false;
  }

  /// A cap's third point lies on e: the two new faces are the neighbour across e split there.
  bool flip(EdgeHandle e) {
    if (!mesh_.is_flip_ok(e)) return false;
    mesh_.flip(e);
    ++result_.flips;
    for (int s = 0; s < 2; ++s) enqueue(mesh_.face_handle(mesh_.halfedge_handle(e, s)));
    return true;
  }

  /// Deletes zero-area face f whose longest edge (halfedge `along`) is on the boundary: the
  /// boundary then runs through the third point, Euler characteristic and loops unchanged.
  /// Refused where a vertex would be pinched (the third point already on the boundary elsewhere)
  /// or the component's last face would go.
  bool delete_on_boundary(FaceHandle f, HalfedgeHandle along) {
    const HalfedgeHandle h1 = mesh_.next_halfedge_handle(along),
                         h2 = mesh_.next_halfedge_handle(h1);
    const bool b1 = mesh_.is_boundary(mesh_.opposite_halfedge_handle(h1));
    const bool b2 = mesh_.is_boundary(mesh_.opposite_halfedge_handle(h2));
    if (b1 && b2) return false;
    if (!b1 && !b2 && mesh_.is_boundary(mesh_.to_vertex_handle(h1))) return false;
    mesh_.delete_face(f, true);  // a corner between two boundary edges had only f: it goes too
    ++result_.boundary_deletions;
    return true;
  }

  void enqueue(FaceHandle f) {
    if (!f.is_valid() || mesh_.status(f).deleted() || queued_[f.idx()] || !has_zero_area(f)) return;
    queued_[f.idx()] = 1;
    queue_.push_back(f);
  }

  TriMesh& mesh_;
  std::deque<FaceHandle> queue_;
  std::vector<char> queued_;  ///< by face index: in queue_
  ZeroAreaRepair result_;
};

}  // namespace

ZeroAreaRepair repair_zero_area_faces(TriMesh& mesh, const std::vector<FaceHandle>& faces) {
  return Repairer(mesh).run(faces);
}

}  // namespace remesh::io
