#pragma once
/// \file valence_flips.h
/// Algorithm 4 as ../shared/ALGORITHM.md corrects it (the pseudocode's test is inverted; the prose
/// is right). For an interior edge V1V3 with opposite vertices V2, V4:
///   dev  = sum over the four of |valence - target| (target 6 inside, 4 on the boundary)
///   amin = smallest angle of the two triangles
/// The edge is flipped only if dev_after < dev_before, amin_after >= f * amin_before, the flip is
/// topologically legal (is_flip_ok, no vertex left with valence < 3) and folds no triangle (both new
/// normals agree with both old ones, within 60 degrees: geom::normals_agree) nor creates a
/// degenerate one. Not in the thesis: nor may it leave the two new triangles, or either of them and
/// one of the four triangles around the quad, meeting at a dihedral angle sharper than 60 degrees
/// when they did not before (geom::adjacent_ok): a flip across a crease would cut it. We test before
/// flipping, which is the same as flipping and undoing.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstddef>
#include <cstdlib>
#include <vector>

#include "core/mesh.h"
#include "remesh/crease_lines.h"

namespace remesh {

/// The quad around interior edge e: v0 -> v1 is the edge, v2 opposite in the face of h0, v3 in the
/// face of h1.
struct Quad {
  OpenMesh::VertexHandle v0, v1, v2, v3;
};
Quad quad_of(const TriMesh& mesh, OpenMesh::EdgeHandle e);

/// Valence and boundary flag of every vertex, kept current through the flips of a sweep (a sweep
/// asks for them millions of times; circulating each time dominated the step).
struct VertexInfo {
  std::vector<int> valence;
  std::vector<char> boundary;

  /// Circulates every vertex once, on up to `threads` threads.
  explicit VertexInfo(const TriMesh& mesh, unsigned threads = 1);
  int deviation(OpenMesh::VertexHandle v, int delta) const {
    return std::abs(valence[v.idx()] + delta - (boundary[v.idx()] ? 4 : 6));
  }
  /// dev_before - dev_after of flipping the quad's edge (> 0: the flip improves).
  int gain(const Quad& q) const {
    const int before = deviation(q.v0, 0) + deviation(q.v1, 0) + deviation(q.v2, 0) + deviation(q.v3, 0);
    const int after = deviation(q.v0, -1) + deviation(q.v1, -1) + deviation(q.v2, +1) + deviation(q.v3, +1);
    return before - after;
  }
  bool improves(const Quad& q) const { return gain(q) > 0; }
  void flipped(const Quad& q) {
    --valence[q.v0.idx()], --valence[q.v1.idx()], ++valence[q.v2.idx()], ++valence[q.v3.idx()];
  }
};

/// Which edges a sweep after the first must look at again. Flips move no vertex, and a flip changes
/// the valence of its quad's four vertices, which are the corners of every triangle it changes; so
/// an edge whose quad has no vertex touched since the edge was last looked at would get the same
/// answer again, and is skipped. Sweeps that skip give the same flips as full sweeps.
/// for_each_edge() walks a sweep: every edge in the first; after it, only the edges around the
/// vertices touched (an edge with a touched end, or opposite a touched vertex), in index order,
/// those around vertices touched during the sweep included, as long as the sweep has not passed
/// them. A full scan would look at every edge and find few with a touched quad (nefertiti: 1 in 6
/// after the first sweep); the walk looks at the same edges in the same order.
class SweepMarks {
 public:
  explicit SweepMarks(std::size_t n_vertices) : previous_(n_vertices, 1), current_(n_vertices, 0) {}
  /// Touched in the previous sweep or in this one so far (every vertex, in the first sweep).
  bool any(const Quad& q) const {
    for (auto v : {q.v0, q.v1, q.v2, q.v3})
      if (previous_[v.idx()] | current_[v.idx()]) return true;
    return false;
  }
  void touch(OpenMesh::VertexHandle v) {
    if (current_[v.idx()]) return;
    current_[v.idx()] = 1;
    touched_.push_back(v);
  }
  void next_sweep();

  /// Calls visit(e) for the edges a sweep must look at (see the class comment), in index order.
  /// visit may flip edges and touch vertices; it still checks any() itself (the walk may offer an
  /// edge whose quad has no touched vertex).
  template <class Visit>
  void for_each_edge(const TriMesh& mesh, Visit&& visit) {
    if (first_) {
      for (auto e : mesh.edges()) visit(e);
      return;
    }
    pending_.assign((mesh.n_edges() + 63) / 64, 0);
    for (auto v : was_touched_) offer_edges_around(mesh, v, -1);
    std::size_t drained = touched_.size();
    for (std::size_t w = 0; w < pending_.size(); ++w)
      while (pending_[w] != 0) {  // bits set by the visits below are seen here
        const int e = static_cast<int>(64 * w) + std::countr_zero(pending_[w]);
        pending_[w] &= pending_[w] - 1;
        visit(mesh.edge_handle(e));
        for (; drained < touched_.size(); ++drained) offer_edges_around(mesh, touched_[drained], e);
      }
  }

 private:
  /// Marks in pending_ the edges whose quad contains v and whose index is above `after`.
  void offer_edges_around(const TriMesh& mesh, OpenMesh::VertexHandle v, int after);

  std::vector<char> previous_, current_;
  std::vector<OpenMesh::VertexHandle> touched_, was_touched_;  ///< touched in this sweep, in the previous
  std::vector<std::uint64_t> pending_;  ///< one bit per edge still to visit in this sweep
  bool first_ = true;
};

/// Does edge e pass the valence-and-angle rule and the safety checks with factor f?
bool flip_improves(const TriMesh& mesh, OpenMesh::EdgeHandle e, double f);

/// One sweep over all edges in index order, flipping each edge that passes flip_improves().
/// Returns the number of flips.
std::size_t valence_flip_sweep(TriMesh& mesh, double f);

/// Sweeps while they still flip something, at most `max_sweeps` times (the thesis does one; more
/// sweeps raise regularity at little cost). Returns the total number of flips. `threads` count the
/// valences; the sweeps are serial.
std::size_t valence_flips(TriMesh& mesh, double f, int max_sweeps = 3, unsigned threads = 1,
                          const CreaseGuard* creases = nullptr);

/// Safety part of a flip alone (legal, no fold, no degenerate triangle, minimum angle no lower than
/// f * before). Used by the interval cleanup too. With `info` (current for `mesh`), the ends'
/// valences come from it instead of circulating them: the same answer. With `turned_ok`, the new
/// faces need not agree with the old ones (untangle.h: a tangle's faces are turned already); the
/// tests of adjacent faces still refuse a face turned over against its neighbours.
/// With `creases`, an edge along a crease is not flipped (CreaseGuard, crease_lines.h).
bool flip_is_safe(const TriMesh& mesh, OpenMesh::EdgeHandle e, double f, const VertexInfo* info = nullptr,
                  bool turned_ok = false, const CreaseGuard* creases = nullptr);

}  // namespace remesh
