#include "remesh/regularize.h"

#include <utility>
#include <vector>

#include "remesh/geometry.h"
#include "remesh/valence_flips.h"

namespace remesh {

using OpenMesh::EdgeHandle;
using OpenMesh::VertexHandle;

namespace {

class Regularizer {
 public:
  Regularizer(TriMesh& mesh, double f, unsigned threads, const CreaseGuard* creases, int depth)
      : mesh_(mesh), info_(mesh, threads), f_(f), marks_(mesh.n_vertices()), creases_(creases),
        depth_(depth < 1 ? 1 : depth) {}

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
      } else if ((depth_ == 1 || cones_kept(mesh_, info_, q)) && chain(e, q, depth_)) {
        ++counts.chains, ++done;
        counts.chain_flips += flipped_in_chain_;
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

  /// A flip that stands: every vertex within depth_ rings of its quad is touched. (A chain from an
  /// edge reads the valences and the stars within depth_ rings of the edge's quad: each neutral
  /// flip of it is at a corner of the last, and so is the flip that ends it.)
  void touch(const Quad& q) {
    if (in_ring_.size() < mesh_.n_vertices()) in_ring_.resize(mesh_.n_vertices(), 0);
    ring_.assign({q.v0, q.v1, q.v2, q.v3});
    for (auto v : ring_) in_ring_[v.idx()] = 1;
    for (std::size_t begin = 0, r = 0; r < static_cast<std::size_t>(depth_); ++r) {
      const std::size_t end = ring_.size();
      for (std::size_t i = begin; i < end; ++i)
        for (auto w : mesh_.vv_range(ring_[i]))
          if (!in_ring_[w.idx()]) in_ring_[w.idx()] = 1, ring_.push_back(w);
      begin = end;
    }
    for (auto v : ring_) marks_.touch(v), in_ring_[v.idx()] = 0;
  }

  /// Flips e (neutral), then the first edge at one of the quad's corners whose flip now lowers the
  /// deviation; with `depth` > 1 and none, the first neutral flip there (cones_kept) from which
  /// such a chain goes on, at most `depth` neutral flips in all. Undoes its flips when none ends so.
  bool chain(EdgeHandle e, const Quad& q, int depth) {
    flip(e, q);
    links_.push_back({e, q});
    // The candidates first: a flip and its undoing may change a corner's outgoing halfedge, under a
    // circulator.
    const std::size_t from = candidates_.size();
    for (VertexHandle corner : {q.v0, q.v1, q.v2, q.v3})
      for (auto h : mesh_.voh_range(corner)) {
        const EdgeHandle g = mesh_.edge_handle(h);
        if (!mesh_.is_boundary(g) && !in_chain(g)) candidates_.push_back(g);
      }
    const std::size_t to = candidates_.size();
    bool done = false;
    for (std::size_t i = from; i < to && !done; ++i) {
      const EdgeHandle g = candidates_[i];
      const Quad r = quad_of(mesh_, g);
      if (info_.gain(r) > 0 && allowed(g)) {
        flip(g, r);
        flipped_in_chain_ = links_.size() + 1;
        for (const auto& link : links_) touch(link.second);
        touch(r);
        done = true;
      }
    }
    for (std::size_t i = from; depth > 1 && i < to && !done; ++i) {
      const EdgeHandle g = candidates_[i];
      const Quad r = quad_of(mesh_, g);
      if (info_.gain(r) == 0 && allowed(g) && cones_kept(mesh_, info_, r)) done = chain(g, r, depth - 1);
    }
    candidates_.resize(from);
    links_.pop_back();
    if (!done) flip(e, quad_of(mesh_, e));  // back: the edge is v2-v3 now; flipping it again restores v0-v1
    return done;
  }

  bool in_chain(EdgeHandle g) const {
    for (const auto& link : links_)
      if (link.first == g) return true;
    return false;
  }

  TriMesh& mesh_;
  VertexInfo info_;
  double f_;
  SweepMarks marks_;
  const CreaseGuard* creases_;
  int depth_;
  std::vector<std::pair<EdgeHandle, Quad>> links_;  ///< the chain's flips so far
  std::vector<EdgeHandle> candidates_;              ///< the chain's edges to try, level after level
  std::size_t flipped_in_chain_ = 0;                ///< flips of the last chain that stood
  std::vector<VertexHandle> ring_;                  ///< touch()'s walk (reused buffer)
  std::vector<char> in_ring_;                       ///< touch()'s membership flags, zero between calls
};

}  // namespace

bool cones_kept(const TriMesh& mesh, const VertexInfo& info, const Quad& q) {
  auto keeps = [&](VertexHandle v, int delta) {
    const int valence = info.valence[v.idx()];
    if (info.boundary[v.idx()] || valence + delta != 6) return true;
    const double deficit = geom::angle_deficit(mesh, v);
    return !(valence == 5 && deficit > kConeDeficit) && !(valence == 7 && deficit < -kConeDeficit);
  };
  return keeps(q.v0, -1) && keeps(q.v1, -1) && keeps(q.v2, +1) && keeps(q.v3, +1);
}

RegularizeCounts regularize(TriMesh& mesh, double f, int max_sweeps, unsigned threads, const CreaseGuard* creases,
                            int depth) {
  RegularizeCounts counts;
  Regularizer r(mesh, f, threads, creases, depth);
  for (int s = 0; s < max_sweeps; ++s)
    if (r.sweep(counts) == 0) break;
  return counts;
}

}  // namespace remesh
