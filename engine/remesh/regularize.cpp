#include "remesh/regularize.h"

#include <vector>

#include "remesh/valence_flips.h"

namespace remesh {

using OpenMesh::EdgeHandle;
using OpenMesh::VertexHandle;

namespace {

class Regularizer {
 public:
  Regularizer(TriMesh& mesh, double f, unsigned threads, const CreaseGuard* creases)
      : mesh_(mesh), info_(mesh, threads), f_(f), marks_(mesh.n_vertices()), creases_(creases) {}

  std::size_t sweep(RegularizeCounts& counts) {
    std::size_t done = 0;
    marks_.for_each_edge(mesh_, [&](EdgeHandle e) {
      if (mesh_.is_boundary(e)) return;
      const Quad q = quad_of(mesh_, e);
      if (!marks_.any(q)) return;
      const int gain = info_.gain(q);
      if (gain < 0 || !allowed(e)) return;
      if (gain > 0) {
        flip(e, q);
        touch(q);
        ++counts.single, ++done;
      } else if (flip_pair(e, q)) {
        ++counts.pairs, ++done;
      }
    });
    marks_.next_sweep();
    return done;
  }

 private:
  /// Algorithm 4's safety checks and angle rule.
  bool allowed(EdgeHandle e) const { return flip_is_safe(mesh_, e, f_, &info_, false, creases_); }

  void flip(EdgeHandle e, const Quad& q) {
    mesh_.flip(e);
    info_.flipped(q);
  }

  /// A flip that stands: its quad's vertices and their neighbours are touched. (A pair of flips
  /// looks one ring further than a single flip: everything it reads lies in the quad's 1-ring.)
  void touch(const Quad& q) {
    for (auto v : {q.v0, q.v1, q.v2, q.v3}) {
      marks_.touch(v);
      for (auto w : mesh_.vv_range(v)) marks_.touch(w);
    }
  }

  /// Flips e (neutral), then the first edge at one of the quad's corners whose flip now lowers the
  /// deviation; undoes the first flip when there is none.
  bool flip_pair(EdgeHandle e, const Quad& q) {
    flip(e, q);
    for (VertexHandle corner : {q.v0, q.v1, q.v2, q.v3}) {
      for (auto h : mesh_.voh_range(corner)) {
        const EdgeHandle g = mesh_.edge_handle(h);
        if (g == e || mesh_.is_boundary(g)) continue;
        const Quad r = quad_of(mesh_, g);
        if (info_.gain(r) > 0 && allowed(g)) {
          flip(g, r);
          touch(q);
          touch(r);
          return true;
        }
      }
    }
    flip(e, quad_of(mesh_, e));  // back: the edge is v2-v3 now; flipping it again restores v0-v1
    return false;
  }

  TriMesh& mesh_;
  VertexInfo info_;
  double f_;
  SweepMarks marks_;
  const CreaseGuard* creases_;
};

}  // namespace

RegularizeCounts regularize(TriMesh& mesh, double f, int max_sweeps, unsigned threads, const CreaseGuard* creases) {
  RegularizeCounts counts;
  Regularizer r(mesh, f, threads, creases);
  for (int s = 0; s < max_sweeps; ++s)
    if (r.sweep(counts) == 0) break;
  return counts;
}

}  // namespace remesh
