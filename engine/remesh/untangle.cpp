#include "remesh/untangle.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/union_find.h"
#include "remesh/geometry.h"
#include "remesh/point_index.h"
#include "remesh/projection.h"
#include "remesh/self_intersections.h"
#include "remesh/stellar_operations.h"
#include "remesh/valence_flips.h"

namespace remesh {

namespace {

using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;
using Pairs = std::vector<std::pair<unsigned, unsigned>>;

/// Rounds of vertex moves, each over the vertices of the crossing faces left.
constexpr int kMoveRounds = 8;
/// The fractions of the way to the ring's centroid a vertex move tries in turn.
constexpr double kSteps[] = {1.0, 0.5, 0.25};
/// Rounds of flips and collapses at most (each round runs while the last lowered the crossings).
/// Measured (crossing face pairs, armadillo coarsened): 6 after one round, 0 after two.
constexpr int kEditRounds = 4;
/// The untangling's budget: once its crossing tests have been given kWorkBase + kWorkPerFace
/// faces per face of the mesh (Untangler::faces_near), it makes no more edits. Measured (Table
/// 4.2 setup): the runs that untangle anything use at most 36 per face (cheese simplified: 74 876
/// for 2 084 faces; cow refined 48 620 for 12 238). A crumpled input (eight.off with its vertices
/// moved at random, remeshed at 0.05-0.08: 37 309 crossing pairs) used 29 000 per face and 221 s,
/// and it left 18 325 pairs either way.
constexpr std::size_t kWorkBase = std::size_t{1} << 20;
constexpr std::size_t kWorkPerFace = 64;
/// The largest disk a tangle is flattened in: its vertices within this many rings of the tangle's.
constexpr std::size_t kMaxPatchRings = 4;
/// Gauss-Seidel sweeps of the membrane at most, and the move (relative to the mean edge of the
/// disk) below which it counts as settled.
constexpr int kMembraneSweeps = 2000;
constexpr double kMembraneSettled = 1e-4;
/// How far (in e_min) a membrane vertex may lie from the reference.
constexpr double kMaxFlattening = 1.0;
/// The flattening indexes the faces anew only once the vertices have drifted from the index by
/// more than this share of the largest face's bounding radius: a disk's crossings are then looked
/// for in balls up to 1 + 3 kReindexDrift times wider, for the same answers. Measured (Table 4.2
/// setup): nefertiti refined builds its index of 207 000 faces 3 times instead of 5 (once per
/// flattened disk before), the untangling 0.58 -> 0.46 s; with flips no longer re-indexing
/// (reshaped_), twice and 0.38 s. The same meshes, bit for bit, on 12 runs (cow, cheese,
/// camelhead, nefertiti, armadillo, bunny_zipper; refined and simplified).
/// A flattened disk no longer adds to the drift: its faces (every face of a vertex it moved) join
/// the reshaped faces that every query returns, as a flip's and a collapse's do. Measured on
/// nefertiti subdivided once (830 000 faces refined): four disks made it index every face four
/// more times, 0.22 s each.
constexpr double kReindexDrift = 1.0;
/// ... or once this many faces are reshaped (every query returns them all).
constexpr std::size_t kMaxReshaped = 4096;

/// Vertices of the faces of `pairs`, each once, in increasing order.
std::vector<VertexHandle> vertices_of(const TriMesh& mesh, const Pairs& pairs) {
  std::vector<VertexHandle> out;
  for (const auto& [f, g] : pairs)
    for (unsigned face : {f, g})
      for (auto v : mesh.fv_range(mesh.face_handle(face))) out.push_back(v);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// Edges of the faces of `pairs`, each once, in increasing order.
std::vector<OpenMesh::EdgeHandle> edges_of(const TriMesh& mesh, const Pairs& pairs) {
  std::vector<OpenMesh::EdgeHandle> out;
  for (const auto& [f, g] : pairs)
    for (unsigned face : {f, g})
      for (auto e : mesh.fe_range(mesh.face_handle(face))) out.push_back(e);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// The faces of `pairs` grouped into tangles (connected through shared vertices), each tangle given
/// by its vertices, in increasing order.
std::vector<std::vector<VertexHandle>> tangles(const TriMesh& mesh, const Pairs& pairs) {
  const std::vector<VertexHandle> vertices = vertices_of(mesh, pairs);
  std::unordered_map<int, std::size_t> slot;
  for (std::size_t i = 0; i < vertices.size(); ++i) slot[vertices[i].idx()] = i;
  std::vector<std::size_t> parent(vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](std::size_t i) { return find_root(parent, i); };
  for (const auto& [f, g] : pairs)
    for (unsigned face : {f, g}) {
      std::size_t first = SIZE_MAX;
      for (auto v : mesh.fv_range(mesh.face_handle(face))) {
        const std::size_t i = root(slot[v.idx()]);
        if (first == SIZE_MAX) first = i;
        else parent[i] = first;
      }
    }
  std::unordered_map<std::size_t, std::size_t> group;
  std::vector<std::vector<VertexHandle>> out;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const auto [it, added] = group.emplace(root(i), out.size());
    if (added) out.emplace_back();
    out[it->second].push_back(vertices[i]);
  }
  return out;
}

/// A face with its face_sphere().
struct FaceSphere {
  FaceHandle face;
  Sphere sphere;
};

/// The mean of v's neighbours; v itself when it has none.
Vec3 ring_centroid(const TriMesh& mesh, VertexHandle v) {
  Vec3 sum(0, 0, 0);
  int n = 0;
  for (auto w : mesh.vv_range(v)) sum += mesh.point(w), ++n;
  return n > 0 ? sum / n : mesh.point(v);
}

/// A disk of the mesh around a tangle: the vertices it moves, its faces and its rim.
struct Disk {
  std::vector<VertexHandle> inner;  ///< moved; none on the mesh's boundary
  std::vector<FaceHandle> faces;    ///< every face of an inner vertex
  std::vector<VertexHandle> rim;    ///< the boundary loop of `faces`, in the faces' orientation
  Vec3 normal;                      ///< unit vector area of the rim
};

class Untangler {
 public:
  Untangler(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max, const CreaseGuard* creases)
      : mesh_(mesh), reference_(reference), e_min_(e_min), e_max_(e_max), creases_(creases),
        vertex_mark_(mesh.n_vertices(), 0), face_mark_(mesh.n_faces(), 0) {}

  /// One round of vertex moves over the vertices of `pairs`; returns the moves kept. A vertex whose
  /// moves failed, with no move near it since (unchanged_since_failure), is passed over: its moves
  /// would fail again the same way. Measured (Table 4.2 setup): cow refined, the untangling 0.053
  /// -> 0.042 s (rounds 2 and 3 retried every vertex of 76 crossing pairs to keep one move); the
  /// same meshes, bit for bit, on 11 refinements and simplifications.
  std::size_t move_round(const Pairs& pairs) {
    if (!face_index_) index_faces();
    std::size_t kept = 0;
    for (auto v : vertices_of(mesh_, pairs)) {
      if (exhausted()) break;
      if (!mesh_.is_boundary(v) && !unchanged_since_failure(v) && try_moves(v)) ++kept;
    }
    return kept;
  }

  /// The crossing pairs now, given `pairs`, those before the moves (and collapses) since the last
  /// call: the pairs near the moves are looked for again (find_self_intersections with a region),
  /// the others stand; a pair with a face a collapse deleted is gone.
  Pairs refresh(const Pairs& pairs, unsigned threads) {
    if (!moved_) return pairs;
    moved_ = false;
    Pairs now = find_self_intersections(mesh_, threads, &moves_);
    for (const auto& pair : pairs) {
      if (mesh_.status(mesh_.face_handle(pair.first)).deleted() || mesh_.status(mesh_.face_handle(pair.second)).deleted())
        continue;
      bool near = false;
      for (unsigned face : {pair.first, pair.second}) {
        const Sphere s = face_sphere(mesh_, mesh_.face_handle(face));
        near = near || sphere_meets(moves_, s.centre, s.radius);
      }
      if (!near) now.push_back(pair);
    }
    std::sort(now.begin(), now.end());
    return now;
  }

  /// Flattens each tangle of `pairs` in the smallest disk that works; returns the vertices moved.
  std::size_t flatten(const Pairs& pairs) {
    std::size_t moved = 0;
    index_if_drifted();
    failures_.clear();  // a flattened disk moves its rim's neighbourhood at once: every vertex tries again
    for (const std::vector<VertexHandle>& seeds : tangles(mesh_, pairs)) {
      for (std::size_t rings = 1; rings <= kMaxPatchRings && !exhausted(); ++rings) {
        const std::optional<Disk> disk = disk_around(seeds, rings);
        if (!disk) continue;
        if (flatten_disk(*disk)) {
          moved += disk->inner.size();
          index_if_drifted();
          break;
        }
      }
    }
    return moved;
  }

  /// One round of flips over the edges of the crossing faces of `pairs` (try_flip); returns the
  /// flips kept.
  std::size_t flip_round(const Pairs& pairs) {
    if (!face_index_) index_faces();
    std::size_t kept = 0;
    for (auto e : edges_of(mesh_, pairs)) {
      if (exhausted()) break;
      if (try_flip(e)) ++kept;
    }
    if (kept > 0) failures_.clear();  // the flipped quads changed their vertices' stars
    return kept;
  }

  /// Indexes the faces anew when there is no index yet, the vertices have drifted from it by more
  /// than kReindexDrift of the largest face's radius (faces_near's balls grow by 3 drift_) or more
  /// than kMaxReshaped faces are reshaped.
  void index_if_drifted() {
    if (!face_index_ || drift_ > kReindexDrift * spheres_.largest || reshaped_.size() > kMaxReshaped) index_faces();
  }

  /// The live faces that may meet the ball of `radius` around p, ascending: from the index of
  /// index_faces() (a face's centroid has moved by at most drift_ since, and its radius grown by
  /// at most 2 drift_, with the same corners), and every face a flip, a collapse or a flattened
  /// disk has reshaped since, wherever it lies now. Precondition: an index (index_if_drifted).
  void faces_near(const Vec3& p, double radius, std::vector<std::uint32_t>& out) const {
    face_index_->within(p, (radius + spheres_.largest + 3 * drift_) * (1 + 1e-9), out);
    if (!reshaped_.empty()) {
      const std::size_t found = out.size();
      out.insert(out.end(), reshaped_.begin(), reshaped_.end());
      std::inplace_merge(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(found), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    }
    if (collapsed_)
      out.erase(std::remove_if(out.begin(), out.end(),
                               [&](std::uint32_t f) { return mesh_.status(mesh_.face_handle(f)).deleted(); }),
                out.end());
    work_ += out.size();
  }

  /// Whether the untangling should make no more edits: `stop` is requested, or the faces its
  /// crossing tests were given (faces_near) number more than the budget (see kWorkPerFace). Each
  /// edit is whole, so the mesh is valid whenever the edits stop.
  bool exhausted() const { return work_ > budget_ || stop_.stop_requested(); }
  void set_limits(std::stop_token stop, std::size_t budget) {
    stop_ = std::move(stop);
    budget_ = budget;
  }
  std::size_t work() const { return work_; }

  /// Records a collapse just made, its from-vertex gone from `gone_at` into `stays` (which stays
  /// where it is): the faces of stays' star, which include every face whose corners it changed,
  /// are reshaped (faces_near adds them wherever they are), and both positions join the moves'
  /// box for refresh() (every such face has stays for a corner, so its sphere meets the box). The
  /// faces it deleted are passed over from now on; the mesh keeps them until the untangling's end,
  /// so that the index and the face numbers stand. No vertex moves: the drift does not grow.
  void collapsed(VertexHandle stays, const Vec3& gone_at) {
    collapsed_ = true;
    note_move(gone_at, mesh_.point(stays));
    reshape(mesh_.vf_range(stays));
    failures_.clear();  // the stars around changed
  }

 private:
  // ---- flips ----

  /// Crossing pairs between the triangles `tris` (adjacent: no pair between them) and the faces
  /// `near` but `skip` (the faces the triangles are, or replace).
  std::size_t crossings_of(const std::array<std::array<Vec3, 3>, 2>& tris, const FaceHandle (&skip)[2],
                           const std::vector<std::uint32_t>& near) const {
    std::size_t n = 0;
    for (std::uint32_t j : near) {
      const FaceHandle g = mesh_.face_handle(j);
      if (g == skip[0] || g == skip[1]) continue;
      VertexHandle c[3];
      geom::face_vertices(mesh_, g, c);
      const Vec3 &d = mesh_.point(c[0]), &e = mesh_.point(c[1]), &f = mesh_.point(c[2]);
      for (const auto& t : tris) n += triangles_cross(t[0], t[1], t[2], d, e, f);
    }
    return n;
  }

  /// Flips e when the valence flips' rule allows it but for the agreement of old and new normals
  /// (flip_is_safe with f = 0 and turned_ok: in a tangle the faces are turned every way already,
  /// and that test refused most of the flips that take two faces out of each other), the flip
  /// lowers the crossings of its two faces and takes no edge out of the interval. The quad's
  /// corners do not move, so its faces, before and after, lie in the ball around the corners'
  /// centroid that reaches the farthest corner: the faces that can cross them are those
  /// faces_near() finds there. A flip gives its two faces other corners, which the index does not
  /// see: they join reshaped_, which faces_near() always adds. (The flips used to grow drift_ by
  /// the ball's diameter, and a round that kept one indexed every face anew: 207 000 on nefertiti.)
  bool try_flip(OpenMesh::EdgeHandle e) {
    if (!flip_is_safe(mesh_, e, 0.0, nullptr, /*turned_ok=*/true)) return false;
    // An edge whose ends a crease joins stays (CreaseGuard::along by the positions alone: in a
    // tangle the two faces of a crease edge may be crumpled flat, and the guard's test of their
    // angle would let it be flipped, cutting the crease).
    if (creases_ && creases_->along(mesh_.point(mesh_.from_vertex_handle(mesh_.halfedge_handle(e, 0))),
                                    mesh_.point(mesh_.to_vertex_handle(mesh_.halfedge_handle(e, 0)))))
      return false;
    const Quad q = quad_of(mesh_, e);
    const Vec3 p[4] = {mesh_.point(q.v0), mesh_.point(q.v1), mesh_.point(q.v2), mesh_.point(q.v3)};
    if (outside((p[3] - p[2]).norm()) && !outside((p[1] - p[0]).norm())) return false;
    const Vec3 centre = 0.25 * (p[0] + p[1] + p[2] + p[3]);
    double radius = 0;
    for (const Vec3& x : p) radius = std::max(radius, (x - centre).norm());
    std::vector<std::uint32_t>& near = near_;
    faces_near(centre, radius, near);
    const HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    const FaceHandle faces[2] = {mesh_.face_handle(h), mesh_.opposite_face_handle(h)};
    // Old faces (v0, v1, v2), (v1, v0, v3); new faces (v3, v1, v2), (v2, v0, v3) (quad_of).
    const std::size_t before = crossings_of({{{p[0], p[1], p[2]}, {p[1], p[0], p[3]}}}, faces, near);
    if (before == 0 || crossings_of({{{p[3], p[1], p[2]}, {p[2], p[0], p[3]}}}, faces, near) >= before) return false;
    mesh_.flip(e);
    for (const Vec3& x : p) note_move(x, x);
    reshape(faces);
    return true;
  }

  // ---- vertex moves ----

  /// Crossing pairs between v's faces and the faces `near` (or other faces of the star).
  std::size_t crossings(VertexHandle v, const std::vector<std::uint32_t>& near) const {
    std::vector<FaceSphere>& star = star_;
    star.clear();
    for (auto f : mesh_.vf_range(v)) star.push_back({f, face_sphere(mesh_, f)});
    std::size_t n = 0;
    for (std::uint32_t j : near) {
      const FaceHandle g = mesh_.face_handle(j);
      // A pair of star faces is counted from the one with the lower index.
      const bool in_star = std::any_of(star.begin(), star.end(), [&](const FaceSphere& s) { return s.face == g; });
      const Sphere other = face_sphere(mesh_, g);
      for (const FaceSphere& s : star) {
        if (s.face == g || (in_star && g.idx() < s.face.idx())) continue;
        if (spheres_overlap(s.sphere, other) && faces_cross(mesh_, s.face, g)) ++n;
      }
    }
    return n;
  }

  bool outside(double length) const { return length < e_min_ || length > e_max_; }

  std::size_t outside_edges(VertexHandle v) const {
    std::size_t n = 0;
    for (auto w : mesh_.vv_range(v)) n += outside((mesh_.point(w) - mesh_.point(v)).norm());
    return n;
  }

  /// Of the candidate moves that fold nothing (geom::move_is_safe), leave no more of v's edges
  /// outside the interval and lower the crossings of v's faces, keeps the one with the fewest
  /// crossings, then the fewest edges outside, then the first. The star of v, before or after a
  /// move to p, lies in the ball around v's position whose radius is the larger of its longest edge
  /// and |p - v| (a ball is convex), so the faces that can cross it are those faces_near() finds.
  bool try_moves(VertexHandle v) {
    const Vec3 start = mesh_.point(v);
    double reach = 0;
    for (auto w : mesh_.vv_range(v)) reach = std::max(reach, (mesh_.point(w) - start).norm());
    std::vector<std::uint32_t>& near = near_;
    faces_near(start, reach, near);
    const std::size_t before = crossings(v, near);
    if (before == 0) {
      failures_[v.idx()] = Failure{start, reach, log_.size()};
      return false;
    }
    const Vec3 centroid = ring_centroid(mesh_, v);
    const Vec3 normal = geom::vertex_normal(mesh_, v);
    // On the reference first (the surface stays the input's), else where the ring puts it; a
    // vertex on a crease along it only (CreaseGuard::constrain: a corner stays).
    const CreaseLines::Where where = creases_ ? creases_->locate(start) : CreaseLines::Where{};
    std::vector<Vec3> candidates;
    double radius = reach;
    for (double s : kSteps) {
      const Vec3 target = start + s * (centroid - start);
      if (where.kind != CreaseLines::Kind::None) {
        candidates.push_back(CreaseGuard::constrain(start, where, target));
      } else {
        candidates.push_back(project_vertex(mesh_, v, target, normal, reference_));
        candidates.push_back(target);
      }
    }
    for (const Vec3& p : candidates) radius = std::max(radius, (p - start).norm());
    if (radius > reach) faces_near(start, radius, near);
    // Should every move fail: what it read lies within `radius` of start, plus one edge (the faces
    // across the ring's edges that move_is_safe reads).
    failures_[v.idx()] = Failure{start, radius, log_.size()};
    const std::size_t outside_before = outside_edges(v);
    Vec3 best = start;
    std::pair<std::size_t, std::size_t> best_score{before, outside_before};
    for (const Vec3& p : candidates) {
      if (p == start || !geom::move_is_safe(mesh_, v, p)) continue;
      mesh_.point(v) = p;
      const std::size_t out = outside_edges(v);
      const std::pair<std::size_t, std::size_t> score{out <= outside_before ? crossings(v, near) : before, out};
      mesh_.point(v) = start;
      if (score.first < before && score < best_score) best = p, best_score = score;
    }
    if (best == start) return false;
    failures_.erase(v.idx());
    mesh_.point(v) = best;
    note_move(start, best);
    double longest = 0;  // the longest edge of v's star, before or after the move
    for (auto w : mesh_.vv_range(v))
      longest = std::max({longest, (mesh_.point(w) - start).norm(), (mesh_.point(w) - best).norm()});
    log_.push_back(Move{start, best, longest});
    // How far v now is from where index_faces() saw it.
    const Vec3 indexed = origins_.emplace(v.idx(), start).first->second;
    drift_ = std::max(drift_, (best - indexed).norm());
    return true;
  }

  // ---- flattening ----

  /// The disk of the faces of the vertices within rings - 1 rings of `seeds`, when it is one: no
  /// moved vertex on the mesh's boundary, one rim loop, Euler characteristic 1, a rim with a
  /// non-zero vector area.
  std::optional<Disk> disk_around(const std::vector<VertexHandle>& seeds, std::size_t rings) {
    const int stamp = ++stamp_;
    Disk disk;
    disk.inner = seeds;
    for (auto v : seeds) vertex_mark_[v.idx()] = stamp;
    for (std::size_t begin = 0, r = 1; r < rings; ++r) {
      const std::size_t end = disk.inner.size();
      for (std::size_t i = begin; i < end; ++i)
        for (auto w : mesh_.vv_range(disk.inner[i]))
          if (vertex_mark_[w.idx()] != stamp) vertex_mark_[w.idx()] = stamp, disk.inner.push_back(w);
      begin = end;
    }
    for (auto v : disk.inner) {
      if (mesh_.is_boundary(v) || (creases_ && creases_->on(mesh_.point(v)))) return std::nullopt;
      for (auto f : mesh_.vf_range(v))
        if (face_mark_[f.idx()] != stamp) face_mark_[f.idx()] = stamp, disk.faces.push_back(f);
    }
    // The rim: halfedges of disk faces whose opposite face is outside the disk, chained.
    std::unordered_map<int, HalfedgeHandle> leaving;
    std::size_t vertices = disk.inner.size();
    for (auto f : disk.faces)
      for (auto h : mesh_.fh_range(f)) {
        const FaceHandle g = mesh_.opposite_face_handle(h);
        if (g.is_valid() && face_mark_[g.idx()] == stamp) continue;
        if (!leaving.emplace(mesh_.from_vertex_handle(h).idx(), h).second) return std::nullopt;  // pinched
      }
    if (leaving.empty()) return std::nullopt;
    HalfedgeHandle h = leaving.begin()->second;
    for (std::size_t k = 0; k < leaving.size(); ++k) {
      disk.rim.push_back(mesh_.from_vertex_handle(h));
      const auto next = leaving.find(mesh_.to_vertex_handle(h).idx());
      if (next == leaving.end()) return std::nullopt;
      h = next->second;
    }
    if (h != leaving.begin()->second) return std::nullopt;  // more than one loop
    // Vertices of disk faces neither moved nor on the rim are held too; count them for Euler.
    const int rim_stamp = ++stamp_;
    for (auto v : disk.rim) vertex_mark_[v.idx()] = rim_stamp;
    for (auto f : disk.faces)
      for (auto v : mesh_.fv_range(f))
        if (vertex_mark_[v.idx()] != stamp && vertex_mark_[v.idx()] != rim_stamp) return std::nullopt;
    vertices += disk.rim.size();
    const std::size_t edges = (3 * disk.faces.size() + disk.rim.size()) / 2;
    if (vertices + disk.faces.size() != edges + 1) return std::nullopt;
    Vec3 area(0, 0, 0);
    for (std::size_t i = 0; i < disk.rim.size(); ++i)
      area += mesh_.point(disk.rim[i]) % mesh_.point(disk.rim[(i + 1) % disk.rim.size()]);
    if (area.norm() == 0) return std::nullopt;
    disk.normal = area.normalized();
    disk_stamp_ = stamp;
    return disk;
  }

  /// Replaces the disk's inner vertices by a membrane (projected onto the reference when that
  /// works) if the result has every disk face facing the rim's normal, none degenerate, no sharp
  /// fold against the faces around the rim and no crossing. Returns whether it did.
  bool flatten_disk(const Disk& disk) {
    std::vector<Vec3> start(disk.inner.size());
    for (std::size_t i = 0; i < disk.inner.size(); ++i) start[i] = mesh_.point(disk.inner[i]);
    auto restore = [&] {
      for (std::size_t i = 0; i < disk.inner.size(); ++i) mesh_.point(disk.inner[i]) = start[i];
      return false;
    };
    // The membrane: each inner vertex at the mean of its neighbours (Gauss-Seidel sweeps until the
    // largest move is below kMembraneSettled of the rim's mean edge).
    double rim_edge = 0;
    for (std::size_t i = 0; i < disk.rim.size(); ++i)
      rim_edge += (mesh_.point(disk.rim[i]) - mesh_.point(disk.rim[(i + 1) % disk.rim.size()])).norm();
    const double settled = kMembraneSettled * rim_edge / disk.rim.size();
    for (int sweep = 0; sweep < kMembraneSweeps; ++sweep) {
      double largest = 0;
      for (auto v : disk.inner) {
        const Vec3 mean = ring_centroid(mesh_, v);
        largest = std::max(largest, (mean - mesh_.point(v)).sqrnorm());
        mesh_.point(v) = mean;
      }
      if (largest <= settled * settled) break;
    }
    // The membrane must stay near the reference: a pleat is flattened, a shape is not.
    std::vector<Vec3> membrane(disk.inner.size()), projected(disk.inner.size());
    for (std::size_t i = 0; i < disk.inner.size(); ++i) {
      membrane[i] = mesh_.point(disk.inner[i]);
      projected[i] = reference_.closest_point(membrane[i], disk.normal);
      if ((projected[i] - membrane[i]).norm() > kMaxFlattening * e_min_) return restore();
    }
    // On the reference, when that keeps it sound; else the membrane itself.
    // Every face of a moved vertex is one of the disk's: they are reshaped (faces_near), and the
    // drift stays as it was.
    auto keep = [&] {
      for (std::size_t i = 0; i < disk.inner.size(); ++i) note_move(start[i], mesh_.point(disk.inner[i]));
      reshape(disk.faces);
      return true;
    };
    for (std::size_t i = 0; i < disk.inner.size(); ++i) mesh_.point(disk.inner[i]) = projected[i];
    if (sound(disk) && covers(disk, start)) return keep();
    for (std::size_t i = 0; i < disk.inner.size(); ++i) mesh_.point(disk.inner[i]) = membrane[i];
    if (sound(disk) && covers(disk, start)) return keep();
    return restore();
  }

  /// Does the disk, as the mesh holds it now, still pass within kMaxFlattening e_min of each of
  /// `points` (its inner vertices' positions before)? Those lay on the surface (every vertex of a
  /// run is projected onto the reference), so a disk that leaves one farther has cut a part of the
  /// surface away rather than flattened a pleat: the membrane of a disk whose rim girds a thin
  /// protrusion (a leg, a finger) spans the protrusion at the rim, and projected it lies on the
  /// protrusion's sides, within e_min of the reference, with the protrusion's end gone.
  bool covers(const Disk& disk, const std::vector<Vec3>& points) const {
    const double limit2 = kMaxFlattening * e_min_ * kMaxFlattening * e_min_;
    for (const Vec3& p : points) {
      bool near = false;
      for (auto f : disk.faces) {
        OpenMesh::VertexHandle c[3];
        geom::face_vertices(mesh_, f, c);
        const Vec3 q = geom::closest_point_on_triangle(p, mesh_.point(c[0]), mesh_.point(c[1]), mesh_.point(c[2]));
        if ((q - p).sqrnorm() <= limit2) {
          near = true;
          break;
        }
      }
      if (!near) return false;
    }
    return true;
  }

  /// Is the disk, as the mesh holds it now, free of folds (a face turned away from the rim's
  /// normal, two adjacent faces sharper than kMinAdjacentCos), degenerate faces and crossings?
  bool sound(const Disk& disk) {
    for (auto f : disk.faces) {
      OpenMesh::VertexHandle c[3];
      geom::face_vertices(mesh_, f, c);
      const Vec3 &a = mesh_.point(c[0]), &b = mesh_.point(c[1]), &d = mesh_.point(c[2]);
      if ((geom::cross_normal(a, b, d) | disk.normal) <= 0 || geom::below_min_angle(a, b, d)) return false;
      // No sharp fold against a neighbour, in the disk (each pair once) or across the rim.
      for (auto h : mesh_.fh_range(f)) {
        const FaceHandle g = mesh_.opposite_face_handle(h);
        if (!g.is_valid() || (face_mark_[g.idx()] == disk_stamp_ && g.idx() < f.idx())) continue;
        if (!geom::normals_agree(geom::face_normal(mesh_, f), geom::face_normal(mesh_, g), geom::kMinAdjacentCos))
          return false;
      }
    }
    // Crossings: disk faces among themselves, and against the faces near them.
    for (std::size_t i = 0; i < disk.faces.size(); ++i)
      for (std::size_t j = i + 1; j < disk.faces.size(); ++j)
        if (faces_cross(mesh_, disk.faces[i], disk.faces[j])) return false;
    // The faces outside the disk have moved by at most drift_ since index_faces() (faces_near).
    std::vector<std::uint32_t> near;
    for (auto f : disk.faces) {
      const Sphere s = face_sphere(mesh_, f);
      faces_near(s.centre, s.radius, near);
      for (std::uint32_t j : near) {
        const FaceHandle g = mesh_.face_handle(j);
        if (face_mark_[j] == disk_stamp_) continue;
        if (faces_cross(mesh_, f, g)) return false;
      }
    }
    return true;
  }

  /// Did try_moves(v) fail before, with no move since that could change what it reads? A move of
  /// u from a to b changes u's star, which lies within u's longest edge L of a (before) and of b
  /// (after); try_moves(v) reads the faces within its radius of v (crossings), v's ring (the
  /// centroid, the normal, the edges) and the faces across the ring's edges (move_is_safe), all
  /// within the radius plus one edge of v. So unless a or b lies within radius + L of v (with a
  /// hair of margin), v's moves fail again, the same way.
  bool unchanged_since_failure(VertexHandle v) const {
    const auto it = failures_.find(v.idx());
    if (it == failures_.end()) return false;
    const Failure& failure = it->second;
    if (mesh_.point(v) != failure.start) return false;
    for (std::size_t k = failure.log_size; k < log_.size(); ++k) {
      const Move& m = log_[k];
      const double limit = (failure.radius + m.longest) * (1 + 1e-9) + 1e-12;
      if ((m.from - failure.start).sqrnorm() <= limit * limit || (m.to - failure.start).sqrnorm() <= limit * limit)
        return false;
    }
    return true;
  }

  /// Grows the box of the moves since the last refresh() by a move from a to b.
  void note_move(const Vec3& a, const Vec3& b) {
    if (!moved_) moves_ = Box{}, moved_ = true;
    moves_.add(a);
    moves_.add(b);
  }

  /// Adds `faces` (FaceHandles) to reshaped_, which stays ascending and without repeats: the new
  /// ones sorted and merged in, not the whole list sorted again (a flip adds two to up to
  /// kMaxReshaped).
  template <class Faces>
  void reshape(const Faces& faces) {
    const std::size_t old = reshaped_.size();
    for (const FaceHandle f : faces) reshaped_.push_back(static_cast<std::uint32_t>(f.idx()));
    const auto middle = reshaped_.begin() + static_cast<std::ptrdiff_t>(old);
    std::sort(middle, reshaped_.end());
    std::inplace_merge(reshaped_.begin(), middle, reshaped_.end());
    reshaped_.erase(std::unique(reshaped_.begin(), reshaped_.end()), reshaped_.end());
  }

  /// Indexes the faces' bounding spheres as the mesh holds them now.
  void index_faces() {
    spheres_ = face_spheres(mesh_);
    face_index_.emplace(spheres_.centres);
    origins_.clear();
    drift_ = 0;
    reshaped_.clear();
  }

  TriMesh& mesh_;
  const ReferenceSurface& reference_;
  FaceSpheres spheres_;
  std::optional<PointIndex> face_index_;
  mutable std::vector<FaceSphere> star_;  ///< crossings()' scratch
  mutable std::size_t work_ = 0;          ///< faces given to crossing tests (faces_near)
  std::size_t budget_ = SIZE_MAX;         ///< exhausted() past this much work
  std::stop_token stop_;
  std::vector<std::uint32_t> near_;       ///< try_moves()' scratch
  /// The position at index_faces() of each vertex moved since (a vertex a flattened disk moved
  /// first: where the disk left it; its faces are reshaped), and the farthest any has moved.
  std::unordered_map<int, Vec3> origins_;
  double drift_ = 0;
  /// The faces flips, collapses and flattened disks have reshaped since index_faces(), ascending
  /// (faces_near adds them all).
  std::vector<std::uint32_t> reshaped_;
  bool collapsed_ = false;  ///< a collapse made: the mesh has deleted faces
  double e_min_, e_max_;
  const CreaseGuard* creases_;  ///< may be null (untangle's `creases`)
  std::vector<int> vertex_mark_, face_mark_;
  Box moves_;
  bool moved_ = false;
  /// Failure memory (unchanged_since_failure): the vertex moves kept, in order, and per vertex whose
  /// moves last failed, where it was, the radius try_moves read around it and the log's size then.
  struct Move {
    Vec3 from, to;
    double longest;  ///< the longest edge of the moved vertex's star, before or after
  };
  struct Failure {
    Vec3 start;
    double radius;
    std::size_t log_size;
  };
  std::vector<Move> log_;
  std::unordered_map<int, Failure> failures_;
  int stamp_ = 0;
  int disk_stamp_ = 0;  ///< the mark of the faces of the last disk_around()
};

/// A collapse of the untangling: halfedge h's from-vertex goes, its to-vertex stays where it is (on
/// the reference, like every vertex of a run). Judged on the triangles of the two ends' stars, as
/// they are and as they would be (corners as points: triangles_cross needs no mesh), against the
/// faces the untangler's index finds near (Untangler::faces_near, which knows the collapses made
/// so far: Untangler::collapsed). Measured on nefertiti subdivided once (830 000 faces refined):
/// a judge with its own index of every face, and a garbage collection and a search of the whole
/// mesh for crossings after each round of collapses, took 2.3 of the untangling's 4.6 s.
class CollapseJudge {
 public:
  explicit CollapseJudge(const TriMesh& mesh, const Untangler& untangler) : mesh_(mesh), untangler_(untangler) {}

  /// Crossing pairs of the two ends' faces before and after the collapse of h (faces gone since
  /// the index was built are passed over).
  std::pair<std::size_t, std::size_t> crossings(HalfedgeHandle h) {
    const VertexHandle gone = mesh_.from_vertex_handle(h), stays = mesh_.to_vertex_handle(h);
    const Vec3 at = mesh_.point(stays);
    const FaceHandle lost[2] = {mesh_.face_handle(h), mesh_.opposite_face_handle(h)};
    star_.clear();
    for (auto v : {gone, stays})
      for (auto f : mesh_.vf_range(v)) star_.push_back(f);
    std::sort(star_.begin(), star_.end());
    star_.erase(std::unique(star_.begin(), star_.end()), star_.end());
    now_.clear();
    then_.clear();
    double radius = 0;
    for (auto f : star_) {
      VertexHandle c[3];
      geom::face_vertices(mesh_, f, c);
      Triangle t{mesh_.point(c[0]), mesh_.point(c[1]), mesh_.point(c[2])};
      now_.push_back(t);
      for (const Vec3& x : t) radius = std::max(radius, (x - at).norm());
      if (f == lost[0] || f == lost[1]) continue;
      for (int k = 0; k < 3; ++k)
        if (c[k] == gone) t[k] = at;
      then_.push_back(t);
    }
    // Every face of both stars, before and after, lies within `radius` of `at`.
    untangler_.faces_near(at, radius, near_);
    const std::size_t before = count(now_);
    return {before, before == 0 ? 0 : count(then_)};
  }

 private:
  using Triangle = std::array<Vec3, 3>;

  /// Crossing pairs of `tris` among themselves and against the live faces near that are not in the
  /// stars.
  std::size_t count(const std::vector<Triangle>& tris) const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < tris.size(); ++i)
      for (std::size_t k = i + 1; k < tris.size(); ++k)
        n += triangles_cross(tris[i][0], tris[i][1], tris[i][2], tris[k][0], tris[k][1], tris[k][2]);
    for (std::uint32_t j : near_) {
      const FaceHandle g = mesh_.face_handle(j);
      if (mesh_.status(g).deleted() || std::binary_search(star_.begin(), star_.end(), g)) continue;
      VertexHandle c[3];
      geom::face_vertices(mesh_, g, c);
      const Vec3 &d = mesh_.point(c[0]), &e = mesh_.point(c[1]), &f = mesh_.point(c[2]);
      for (const Triangle& t : tris) n += triangles_cross(t[0], t[1], t[2], d, e, f);
    }
    return n;
  }

  const TriMesh& mesh_;
  const Untangler& untangler_;
  std::vector<std::uint32_t> near_;
  std::vector<FaceHandle> star_;  ///< sorted
  std::vector<Triangle> now_, then_;
};

/// May the collapse of h (its from-vertex into its to-vertex, where that stands) keep the creases?
/// A vertex off them may go, one on a crease line only into a vertex along it, a corner never.
bool crease_keeps(const CreaseGuard& creases, const TriMesh& mesh, HalfedgeHandle h) {
  const CreaseLines::Kind gone = creases.locate(mesh.point(mesh.from_vertex_handle(h))).kind;
  if (gone == CreaseLines::Kind::None) return true;
  return gone == CreaseLines::Kind::Line && creases.along(mesh, mesh.edge_handle(h));
}

/// Collapses edges of the crossing faces of `pairs`, one end onto the other where it stands, when
/// that lowers the crossings of the two ends' faces and passes the rules of Algorithm 3's
/// collapses (link condition, no interior edge between two boundary vertices, no boundary vertex
/// removed, components of 4 vertices or more, no fold against a neighbour, no new angle below the
/// stars' smallest or kMinAngle, no edge longer than e_max) but for the agreement of old and new
/// normals (collapse_geometry_ok's turned_ok: a tangle's faces are turned already). A collapse may
/// leave short edges: the crossings sit where the surface is thinner than the interval allows (the
/// edges there are short already). Measured (crossing face pairs, coarsened meshes): keeping the
/// edges outside from growing left camelhead at 8 instead of 0; keeping tips (is_tip: in a tangle
/// the spikes of crumpled faces) left armadillo at 15 instead of 6. With `creases`, a vertex on a
/// crease goes only into another along it, and a corner not at all. Leaves deleted elements, each
/// collapse told to `untangler` (Untangler::collapsed).
/// Returns the collapses.
std::size_t collapse_round(TriMesh& mesh, Untangler& untangler, double e_max, const Pairs& pairs,
                           const CreaseGuard* creases) {
  untangler.index_if_drifted();
  CollapseJudge judge(mesh, untangler);
  std::size_t kept = 0;
  for (auto e : edges_of(mesh, pairs)) {
    if (untangler.exhausted()) break;
    if (mesh.status(e).deleted()) continue;
    const HalfedgeHandle h0 = mesh.halfedge_handle(e, 0);
    const VertexHandle a = mesh.from_vertex_handle(h0), b = mesh.to_vertex_handle(h0);
    // No interior edge between two boundary vertices (it would pinch), no component below 4.
    if ((mesh.is_boundary(a) && mesh.is_boundary(b) && !mesh.is_boundary(e)) || !component_larger_than(mesh, a, 4))
      continue;
    for (const HalfedgeHandle h : {h0, mesh.opposite_halfedge_handle(h0)}) {
      const VertexHandle gone = mesh.from_vertex_handle(h), stays = mesh.to_vertex_handle(h);
      if (mesh.is_boundary(gone) || !mesh.is_collapse_ok(h)) continue;
      if (creases && !crease_keeps(*creases, mesh, h)) continue;
      const Vec3 at = mesh.point(stays);
      if (!collapse_geometry_ok(mesh, h, at, e_max, /*turned_ok=*/true)) continue;
      const auto [before, after] = judge.crossings(h);
      if (before == 0) break;  // neither direction can lower them
      if (after >= before) continue;
      const Vec3 gone_at = mesh.point(gone);
      mesh.collapse(h);
      untangler.collapsed(stays, gone_at);
      ++kept;
      break;
    }
  }
  return kept;
}

}  // namespace

std::size_t untangle_budget(std::size_t faces) { return kWorkBase + kWorkPerFace * faces; }

UntangleCounts untangle(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                        unsigned threads, const CreaseGuard* creases, std::optional<Pairs> crossing,
                        std::stop_token stop) {
  UntangleCounts counts;
  Pairs pairs = crossing ? std::move(*crossing) : find_self_intersections(mesh, threads);
  counts.pairs_before = pairs.size();
  if (pairs.empty()) return counts;
  Untangler untangler(mesh, reference, e_min, e_max, creases);
  untangler.set_limits(stop, untangle_budget(mesh.n_faces()));
  auto move_rounds = [&] {
    for (int r = 0; r < kMoveRounds && !pairs.empty(); ++r) {
      const std::size_t kept = untangler.move_round(pairs);
      counts.moved += kept;
      if (kept == 0) break;
      pairs = untangler.refresh(pairs, threads);
    }
  };
  move_rounds();
  // Flips, then collapses, each followed by vertex moves, again while they lower the crossings
  // (kEditRounds at most): one edit can free the next.
  for (int round = 0; round < kEditRounds && !pairs.empty(); ++round) {
    const std::size_t at_start = pairs.size();
    const std::size_t flipped = untangler.flip_round(pairs);
    counts.moved += flipped;
    counts.flipped += flipped;
    if (flipped > 0) {
      pairs = untangler.refresh(pairs, threads);
      move_rounds();
    }
    if (pairs.empty()) break;
    const std::size_t collapsed = collapse_round(mesh, untangler, e_max, pairs, creases);
    if (collapsed > 0) {
      counts.moved += collapsed;
      counts.collapsed += collapsed;
      pairs = untangler.refresh(pairs, threads);
      move_rounds();
    }
    if (pairs.size() >= at_start) break;
  }
  if (!pairs.empty()) {
    const std::size_t flattened = untangler.flatten(pairs);
    counts.moved += flattened;
    counts.flattened += flattened;
    if (flattened > 0) {
      pairs = untangler.refresh(pairs, threads);
      move_rounds();
    }
  }
  // The faces the collapses deleted go now; the pairs left follow their faces' new numbers.
  if (counts.collapsed > 0) {
    std::vector<FaceHandle> faces;
    faces.reserve(2 * pairs.size());
    for (const auto& [f, g] : pairs) faces.emplace_back(static_cast<int>(f)), faces.emplace_back(static_cast<int>(g));
    collect_garbage(mesh, faces);
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const auto f = static_cast<unsigned>(faces[2 * i].idx()), g = static_cast<unsigned>(faces[2 * i + 1].idx());
      pairs[i] = {std::min(f, g), std::max(f, g)};
    }
    std::sort(pairs.begin(), pairs.end());
  }
  counts.left = std::move(pairs);
  counts.work = untangler.work();
  counts.cut_short = untangler.exhausted();
  return counts;
}

UntangleCounts untangle_creases_first(TriMesh& mesh, const ReferenceSurface& reference, double e_min,
                                      double e_max, unsigned threads, const CreaseGuard* creases,
                                      std::optional<Pairs> crossing, std::stop_token stop) {
  UntangleCounts first = untangle(mesh, reference, e_min, e_max, threads, creases, std::move(crossing), stop);
  if (!creases || first.left.empty()) return first;
  UntangleCounts rest = untangle(mesh, reference, e_min, e_max, threads, nullptr, std::nullopt, stop);
  rest.pairs_before = first.pairs_before;
  rest.moved += first.moved;
  rest.flipped += first.flipped;
  rest.collapsed += first.collapsed;
  rest.flattened += first.flattened;
  rest.work += first.work;
  rest.cut_short = rest.cut_short || first.cut_short;
  return rest;
}

}  // namespace remesh
