#include "remesh/interval_cleanup.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <vector>

#include "remesh/geometry.h"
#include "remesh/projection.h"
#include "remesh/reposition.h"
#include "remesh/stellar_operations.h"
#include "remesh/valence_flips.h"

namespace remesh {

using OpenMesh::EdgeHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;

namespace {

/// The feature snap's guard for the Hausdorff distance. Judged: the snap's target and the reference
/// points within e_min of the patch's faces (the ones a relaxation of the patch could pull away
/// from). A move is kept only if it brings the target nearer to the faces and no other judged
/// point ends farther from them than it was or than the target was. A point whose nearest face
/// lies outside the patch keeps that face (it does not move), so no point's distance to the mesh
/// grows beyond the larger of its own and the target's distance before the move. (A bound shared by
/// all points, the farthest of their distances before, let a point whose nearest face is elsewhere
/// lift the bound to nearly e_min: on kitten a partial snap then pushed a reference vertex from
/// 0.68 to 0.86 units off the mesh.)
class GapJudge {
 public:
  /// `reach`: a distance from the target beyond which no point is within e_min of the faces.
  GapJudge(const TriMesh& mesh, std::vector<OpenMesh::FaceHandle> faces, const Vec3& target,
           const PointIndex& points, double e_min, double reach)
      : faces_(std::move(faces)), target_(target) {
    target_before_ = nearest_distance(mesh, target);
    // A point within e_min of a face lies in the faces' bounding box grown by e_min, and in the
    // sphere around that box: only the points in both are measured (cheese, whose reference is
    // dense along its holes' rims, has ~1 000 points within `reach` of a target), and each only
    // against the faces whose own box is within e_min, or the best distance so far.
    std::vector<Box> boxes(faces_.size());
    Box all;
    for (std::size_t k = 0; k < faces_.size(); ++k)
      for (auto v : mesh.fv_range(faces_[k])) boxes[k].add(mesh.point(v)), all.add(mesh.point(v));
    const double grow = e_min * (1 + 1e-9);  // a little wider, for the arithmetic's last bit
    const Box grown{all.lo - Vec3(grow), all.hi + Vec3(grow)};
    const Vec3 centre = 0.5 * (grown.lo + grown.hi);
    const double radius = std::min(reach, 0.5 * (grown.hi - grown.lo).norm());
    // The index's test, in its own arithmetic, could differ in the last bit: ask a little wider.
    std::vector<std::uint32_t> near;
    if (!faces_.empty()) points.within(centre, radius * (1 + 1e-9), near);
    for (std::uint32_t i : near) {
      const Vec3& q = points.points()[i];
      if (!grown.contains(q) || q == target || !((q - target).sqrnorm() < reach * reach)) continue;
      // The nearest face, among those whose box is within e_min (ties to the first, as nearest()).
      std::pair<double, OpenMesh::FaceHandle> best{e_min, OpenMesh::FaceHandle()};
      for (std::size_t k = 0; k < faces_.size(); ++k)
        if (boxes[k].squared_distance(q) <= best.first * best.first * (1 + 1e-9))
          if (const double x = distance(mesh, q, faces_[k]); x < best.first) best = {x, faces_[k]};
      if (!best.second.is_valid()) continue;
      points_.push_back(q);
      nearest_.push_back(best.second);
      before_.push_back(best.first);
    }
  }

  /// Is the target nearer to the (moved) faces, and every other judged point within its bound?
  /// (Never with no faces: nothing can come nearer.)
  bool holds(const TriMesh& mesh) const {
    if (!(nearest_distance(mesh, target_) < target_before_)) return false;
    for (std::size_t k = 0; k < points_.size(); ++k) {
      const double limit = std::max(before_[k], target_before_);
      // The face that was nearest usually still is: its distance bounds the point's from above.
      if (distance(mesh, points_[k], nearest_[k]) <= limit) continue;
      if (nearest_distance(mesh, points_[k]) > limit) return false;
    }
    return true;
  }

 private:
  static double distance(const TriMesh& mesh, const Vec3& q, OpenMesh::FaceHandle f) {
    auto fv = mesh.cfv_iter(f);
    const Vec3 &a = mesh.point(*fv), &b = mesh.point(*++fv), &c = mesh.point(*++fv);
    return (geom::closest_point_on_triangle(q, a, b, c) - q).norm();
  }

  /// Distance from q to the nearest face (infinity with none), and that face.
  std::pair<double, OpenMesh::FaceHandle> nearest(const TriMesh& mesh, const Vec3& q) const {
    std::pair<double, OpenMesh::FaceHandle> best{std::numeric_limits<double>::infinity(), OpenMesh::FaceHandle()};
    for (auto f : faces_)
      if (const double x = distance(mesh, q, f); x < best.first) best = {x, f};
    return best;
  }
  double nearest_distance(const TriMesh& mesh, const Vec3& q) const { return nearest(mesh, q).first; }

  std::vector<OpenMesh::FaceHandle> faces_;
  Vec3 target_;
  double target_before_ = 0;  ///< the target's distance to the faces before the move
  std::vector<Vec3> points_;  ///< the other judged points
  std::vector<OpenMesh::FaceHandle> nearest_;
  std::vector<double> before_;  ///< each point's distance to the faces before the move
};

class Cleanup {
 public:
  Cleanup(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max, double f,
          std::vector<NeighbourCache>* caches = nullptr)
      : mesh_(mesh), reference_(reference), e_min_(e_min), e_max_(e_max), f_(f), caches_(caches) {}

  bool inside(double length) const { return length >= e_min_ && length <= e_max_; }
  double outside_by(double length) const { return std::max({0.0, e_min_ - length, length - e_max_}); }
  double target() const { return 0.5 * (e_min_ + e_max_); }

  std::size_t count_outside() const {
    std::size_t n = 0;
    for (auto e : mesh_.edges())
      if (!inside(mesh_.calc_edge_length(e))) ++n;
    return n;
  }

  /// One round: every edge outside the interval, worst first.
  std::size_t round(CleanupCounts& counts, bool boundary_only) {
    std::vector<std::pair<double, unsigned>> list;
    for (auto e : mesh_.edges()) {
      if (boundary_only && !mesh_.is_boundary(mesh_.from_vertex_handle(mesh_.halfedge_handle(e, 0))) &&
          !mesh_.is_boundary(mesh_.to_vertex_handle(mesh_.halfedge_handle(e, 0))))
        continue;
      const double d = outside_by(mesh_.calc_edge_length(e));
      if (d > 0) list.emplace_back(-d, e.idx());
    }
    std::sort(list.begin(), list.end());
    std::size_t fixes = 0, seen = 0;
    for (const auto& item : list) {
      if (++seen % kStopCheckEvery == 0 && stop_.stop_requested()) break;
      const EdgeHandle e = mesh_.edge_handle(item.second);
      if (mesh_.status(e).deleted()) continue;
      const double length = mesh_.calc_edge_length(e);
      if (inside(length)) continue;
      const bool is_long = length > e_max_;
      if (remember_failures_ && unchanged_since_failure(e)) {
        ++counts.skipped;
        // Every fix would fail again, the patch relaxation too, at the cost of one from the
        // budget as before (so that the outcome is the same as without the memory).
        if (patch_budget_ > 0 && !patch_failed(e)) --patch_budget_, failed_patches_.push_back(e.idx());
        continue;
      }
      const std::size_t budget_before = patch_budget_;
      if (try_flip(e)) {
        ++counts.flips;
      } else if (!is_long && try_collapse(e)) {
        ++counts.collapses;
      } else if (is_long && try_split(e)) {
        ++counts.splits;
      } else if (try_relocate(e)) {
        ++counts.relocations;
      } else if (patch_budget_ > 0 && !patch_failed(e) && (--patch_budget_, try_relax_patch(e, counts))) {
        ++counts.patches;
      } else {
        // A failure counts only with the patch relaxation tried, or out of budget for good: a
        // patch passed over because it failed in an earlier state of the neighbourhood may
        // succeed in this one once failed_patches_ is cleared.
        if (patch_budget_ != budget_before || patch_budget_ == 0) record_failure(e);
        continue;
      }
      ++fixes;
    }
    // A collapse changes the neighbourhoods: patches that failed may succeed now.
    if (collapsed_since_round_) failed_patches_.clear();
    collapsed_since_round_ = false;
    return fixes;
  }

  void set_patch_budget(std::size_t budget) { patch_budget_ = budget; }
  void set_stop(std::stop_token stop) { stop_ = std::move(stop); }
  bool stop_requested() const { return stop_.stop_requested(); }
  void set_remember_failures(bool on) { remember_failures_ = on; }
  void set_protect_tips(bool on) { protect_tips_ = on; }
  void set_rest(PatchRest* rest) { rest_ = rest; }
  void set_creases(const CreaseGuard* creases) { creases_ = creases && !creases->empty() ? creases : nullptr; }

  NeighbourCache* cache_of(VertexHandle v) {
    return caches_ && static_cast<std::size_t>(v.idx()) < caches_->size() ? &(*caches_)[v.idx()] : nullptr;
  }

  /// Collects what the collapses deleted. Once, after the last round: between rounds the deleted
  /// elements are skipped, and collecting (which renumbers every element) after every round took a
  /// third of the cleanup's time on armadillo_86k.
  void finish() {
    if (collapsed_) collect_garbage(mesh_);
    collapsed_ = false;
  }

 private:
  /// Failure memory. Every fix stamps the vertices whose position or faces it changed with the
  /// next tick of clock_; an edge that no fix could mend is stamped with the tick of its failure.
  /// The fixes of an edge read only the vertices within kFailureRings rings of its ends (a patch's
  /// vertices lie within 2 rings, their settling reads a 3rd and their fold checks a 4th), so
  /// while none of those carries a later stamp every fix would fail again the same way, and the
  /// edge is passed over. Measured (Table 4.2 setup, 2 threads): the same output meshes on all 22
  /// runs; cheese's simplification 12.3 -> 10.3 s, cow's 1.15 -> 1.00 s, cheese's refinement
  /// 2.46 -> 2.36 s.
  static constexpr std::size_t kFailureRings = 4;
  /// The same for one relocation (fix 3), which reads v's ring (its settling and projection) and
  /// the faces across the ring's edges (move_is_safe): 2 rings. An edge whose fixes partly changed
  /// something nearby is tried again, and its ends' and opposite vertices' relocations with it;
  /// most of those fail again as before. Measured (cheese's simplification, where most edges
  /// cannot be mended): 79 % of 927 000 relocations were such repeats.
  static constexpr std::size_t kRelocateRings = 2;

  /// A tick per vertex or edge index, 0 = none; the vectors grow with the mesh (splits add elements).
  static std::uint32_t tick_of(const std::vector<std::uint32_t>& ticks, int idx) {
    return static_cast<std::size_t>(idx) < ticks.size() ? ticks[idx] : 0;
  }
  void set_tick(std::vector<std::uint32_t>& ticks, int idx, std::size_t elements) const {
    if (ticks.size() <= static_cast<std::size_t>(idx)) ticks.resize(elements, 0);
    ticks[idx] = clock_;
  }

  /// Stamps v with the current tick: its position or faces changed.
  void stamp(VertexHandle v) { stamped_.emplace_back(v.idx(), clock_); }
  /// Stamps v and its neighbours (a flip, collapse or split changes the faces of each).
  void stamp_star(VertexHandle v) {
    stamp(v);
    for (auto w : mesh_.vv_range(v)) stamp(w);
  }

  void record_failure(EdgeHandle e) { set_tick(failed_at_, e.idx(), mesh_.n_edges()); }

  /// Did e fail before, with nothing within kFailureRings rings of its ends changed since?
  bool unchanged_since_failure(EdgeHandle e) {
    const std::uint32_t failed = tick_of(failed_at_, e.idx());
    if (failed == 0) return false;
    spread_stamps();
    const HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    return tick_of(changed_near_, mesh_.from_vertex_handle(h).idx()) <= failed &&
           tick_of(changed_near_, mesh_.to_vertex_handle(h).idx()) <= failed;
  }

  /// Did relocate(v) fail before, with nothing within kRelocateRings rings of v changed since?
  bool relocation_unchanged(VertexHandle v) {
    const std::uint32_t failed = tick_of(relocate_failed_at_, v.idx());
    if (failed == 0) return false;
    spread_stamps();
    return tick_of(changed_close_, v.idx()) <= failed;
  }

  /// Hands each stamp on to the vertices within kFailureRings rings of the stamped vertex
  /// (changed_near_) and within kRelocateRings (changed_close_), in the mesh as it is after the
  /// fix (or a later one: a query hands on the stamps since the last): one walk over the rings per
  /// fix, instead of one per query, and queries outnumber fixes
  /// 50 to 1 in a tight interval (kitten at [1.425, 1.575]: 4.0 million queries, 76 000 fixes).
  /// The answers are those of a walk at query time: a vertex within the rings then but not at the
  /// fix can only have come nearer through a later fix, which stamped the vertices on the new path;
  /// one farther away then than at the fix makes an edge count as changed, and its fixes are tried
  /// again and fail as before. Measured: the same meshes, byte for byte, on the 14 small Table
  /// 4.1/4.2 runs, nefertiti, armadillo and 11 others (tight intervals, open meshes); kitten at
  /// [1.425, 1.575] 24.6 -> 18.9 s, armadillo at [1.35, 1.65] 65.9 -> 53.5 s, cheese at [1.3,
  /// 1.7] 6.2 -> 5.7 s; on the Table 4.2 runs, where fixes are fewer, within the noise (nefertiti's
  /// cleanup 0.63 -> 0.66 s).
  void spread_stamps() {
    const std::size_t n = mesh_.n_vertices();
    if (changed_near_.size() < n) changed_near_.resize(n, 0), changed_close_.resize(n, 0);
    // One walk per fix (the stamps of a fix share its tick, and ticks only grow).
    for (std::size_t begin = 0; begin < stamped_.size();) {
      const std::uint32_t tick = stamped_[begin].second;
      std::size_t end = begin;
      ring_walk_.clear();
      for (; end < stamped_.size() && stamped_[end].second == tick; ++end) {
        // A vertex a later collapse removed lies in no ring now; the kept one was stamped then.
        const VertexHandle v = mesh_.vertex_handle(stamped_[end].first);
        if (!mesh_.status(v).deleted()) ring_walk_.push_back(v);
      }
      grow_rings(ring_walk_, kFailureRings, &ring_ends_);
      for (std::size_t i = 0; i < ring_walk_.size(); ++i) {
        const int v = ring_walk_[i].idx();
        changed_near_[v] = tick;
        if (i < ring_ends_[kRelocateRings]) changed_close_[v] = tick;
        patch_mark_[v] = 0;
      }
      begin = end;
    }
    stamped_.clear();
  }

  bool try_flip(EdgeHandle e) {
    if (mesh_.is_boundary(e)) return false;
    const HalfedgeHandle h0 = mesh_.halfedge_handle(e, 0), h1 = mesh_.halfedge_handle(e, 1);
    const VertexHandle v2 = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h0));
    const VertexHandle v3 = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h1));
    if (!inside((mesh_.point(v2) - mesh_.point(v3)).norm())) return false;
    if (!flip_is_safe(mesh_, e, f_, nullptr, false, creases_)) return false;
    mesh_.flip(e);
    ++clock_;
    const HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    for (auto v : {v2, v3, mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h)),
                   mesh_.to_vertex_handle(mesh_.next_halfedge_handle(mesh_.opposite_halfedge_handle(h)))})
      stamp(v);
    return true;
  }

  bool try_collapse(EdgeHandle e) {
    if (!ring_can_fit(e)) return false;
    if (collapse_at(e, e_max_, false)) return true;
    // The eq. 3.1 point leaves an edge outside (typically a valence-4 vertex among short edges:
    // merging it with a neighbour makes the far corner of its star too far). Plan again with the
    // main phase's looser length bound and place the merged vertex freely in its tangent plane.
    return collapse_at(e, 2.0 * e_max_, true);
  }

  /// Could one point lie within e_max of every vertex around e? collapse_at keeps a collapse only
  /// if each edge of the merged vertex is inside the interval, so then every two of those vertices
  /// lie within 2 e_max of each other. Tested on the ring alone, before the collapse is planned (eq.
  /// 3.1) and projected. The same meshes (the 14 small Table 4.1/4.2 runs, byte for byte); in a
  /// tight interval, where almost every collapse fails so, the cleanup takes a third less time
  /// (kitten at [1.425, 1.575]: 30.6 -> 21.3 s; cheese refined 1.58 -> 1.38 s in all).
  bool ring_can_fit(EdgeHandle e) {
    const HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    const VertexHandle v0 = mesh_.from_vertex_handle(h), v1 = mesh_.to_vertex_handle(h);
    std::vector<Vec3>& ring = ring_;
    ring.clear();
    for (VertexHandle end : {v0, v1})
      for (auto w : mesh_.vv_range(end))
        if (w != v0 && w != v1) ring.push_back(mesh_.point(w));  // a shared neighbour twice: harmless
    const double reach = 2 * e_max_ * (1 + 1e-9);  // a hair wide, for the rounding of the lengths
    // First the ring's bounding box: two points in a box are at most its diagonal apart. Most rings
    // pass here without the pairs, which a vertex of high valence makes quadratic (a 2000-sided
    // polygon, triangulated as a fan from one corner: 4 million pairs an edge, 4.5 s of its 4.7).
    Box box;
    for (const Vec3& p : ring) box.add(p);
    if (ring.empty() || (box.hi - box.lo).sqrnorm() <= reach * reach) return true;
    for (std::size_t i = 0; i < ring.size(); ++i)
      for (std::size_t j = i + 1; j < ring.size(); ++j)
        if ((ring[i] - ring[j]).sqrnorm() > reach * reach) return false;
    return true;
  }

  bool collapse_at(EdgeHandle e, double plan_limit, bool free_placement) {
    CollapsePlan plan;
    if (!plan_collapse(mesh_, e, target(), plan_limit, plan, /*keep_tips=*/protect_tips_, creases_)) return false;
    const VertexHandle kept = mesh_.to_vertex_handle(plan.halfedge);
    const VertexHandle removed = mesh_.from_vertex_handle(plan.halfedge);
    const bool on_boundary = mesh_.is_boundary(kept) || mesh_.is_boundary(removed);
    // A collapse at a crease: plan_collapse put the point on it or kept the crease end.
    const bool on_crease = creases_ && (creases_->on(mesh_.point(kept)) || creases_->on(mesh_.point(removed)));
    // A vertex plan_collapse keeps in place (a boundary end, a protected tip) stays there; a
    // boundary edge collapses along the boundary only.
    if (free_placement && (on_boundary || plan.kept_in_place || on_crease)) return false;
    const Vec3 normal = geom::vertex_normal(mesh_, kept) + geom::vertex_normal(mesh_, removed);
    Vec3 p = plan.position;
    if (free_placement) p = settle(p, collapse_neighbours(mesh_, plan.halfedge), normal);
    if (!on_crease && (!mesh_.is_boundary(kept) || mesh_.is_boundary(mesh_.edge_handle(plan.halfedge))))
      p = project_vertex(mesh_, kept, p, normal, reference_, cache_of(kept));
    if (!collapse_geometry_ok(mesh_, plan.halfedge, p, e_max_)) return false;
    for (VertexHandle end : {kept, removed})
      for (auto w : mesh_.vv_range(end))
        if (w != kept && w != removed && !inside((mesh_.point(w) - p).norm())) return false;
    plan.position = p;
    apply_collapse(mesh_, plan);
    collapsed_ = collapsed_since_round_ = true;
    ++clock_;
    stamp_star(kept);
    return true;
  }

  /// Gradient steps from `x`, within the plane orthogonal to `normal` (or along `tangent` when it is
  /// non-zero), on the sum of squared distances of |x - q| to the interval (shrunk by a margin) over
  /// the points q. Not projected.
  Vec3 settle(Vec3 x, const std::vector<Vec3>& points, Vec3 normal, const Vec3& tangent = Vec3(0, 0, 0)) const {
    const double len = normal.norm();
    if (len > 0) normal /= len;
    const double margin = 0.05 * (e_max_ - e_min_);
    const double lo = e_min_ + margin, hi = e_max_ - margin;
    for (int it = 0; it < 30; ++it) {
      Vec3 grad(0, 0, 0);
      int active = 0;
      for (const Vec3& q : points) {
        const Vec3 d = x - q;
        const double l = d.norm();
        if (!(l > 0)) continue;
        const double excess = l < lo ? l - lo : (l > hi ? l - hi : 0.0);
        if (excess == 0) continue;
        grad += d * (excess / l);
        ++active;
      }
      if (active == 0) break;
      if (tangent.sqrnorm() > 0) {
        grad = tangent * (grad | tangent);  // slide along the boundary curve
      } else {
        grad -= normal * (grad | normal);  // stay in the tangent plane
      }
      x -= grad * (1.0 / active);
    }
    return x;
  }

  bool try_split(EdgeHandle e) {
    const HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    const VertexHandle v0 = mesh_.from_vertex_handle(h), v1 = mesh_.to_vertex_handle(h);
    const Vec3 a = mesh_.point(v0), b = mesh_.point(v1);
    const std::vector<Vec3> around = split_neighbours(mesh_, e);
    const Vec3 normal = geom::vertex_normal(mesh_, v0) + geom::vertex_normal(mesh_, v1);
    const Vec3 p0 = a + (b - a) * equalizing_parameter(a, b, around, target());
    // Through v0's kd-tree answer: exact wherever it came from (reference_surface.h), and the split
    // point lies next to v0.
    NeighbourCache* cache = cache_of(v0);
    // An edge along a crease: the new vertex goes onto the crease (the chord of a bent one sags).
    const bool crease = creases_ && creases_->along(mesh_, e);
    auto project = [&](const Vec3& x) {
      if (crease) return creases_->onto(x, a, b);
      if (!mesh_.is_boundary(e))
        return cache ? reference_.closest_point(x, normal, *cache) : reference_.closest_point(x, normal);
      return reference_.has_boundary() ? reference_.closest_boundary_point(x) : x;
    };
    Vec3 p = project(p0);
    // The eq. 3.1 point leaves an edge outside: place the new vertex freely in the tangent plane
    // (along the edge on the boundary).
    if (!split_point_fits(e, p, around)) {
      const Vec3 along = mesh_.is_boundary(e) || crease ? (b - a).normalized() : Vec3(0, 0, 0);
      p = project(settle(p0, around, normal, along));
      if (!split_point_fits(e, p, around)) return false;
    }
    ++clock_;
    stamp_star(mesh_.split(e, p));
    return true;
  }

  /// Would splitting e at p give edges inside the interval and unfolded, non-degenerate triangles?
  bool split_point_fits(EdgeHandle e, const Vec3& p, const std::vector<Vec3>& around) const {
    for (const Vec3& q : around)
      if (!inside((q - p).norm())) return false;
    for (int s = 0; s < 2; ++s) {
      const HalfedgeHandle g = mesh_.halfedge_handle(e, s);
      if (mesh_.is_boundary(g)) continue;
      const Vec3& x = mesh_.point(mesh_.from_vertex_handle(g));
      const Vec3& y = mesh_.point(mesh_.to_vertex_handle(g));
      const Vec3& z = mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(g)));
      const Vec3 before = geom::cross_normal(x, y, z);
      geom::AngleFloor floor([&] { return geom::min_angle(x, y, z); });
      for (const auto& [u, w] : {std::pair<Vec3, Vec3>{x, p}, std::pair<Vec3, Vec3>{p, y}}) {
        if (!geom::normals_agree(before, geom::cross_normal(u, w, z))) return false;
        if (floor.breaks(u, w, z)) return false;
      }
    }
    return true;
  }

  /// Edges of v's star outside the interval with v at p, and the sum of their squared excess.
  std::pair<std::size_t, double> outside_around(VertexHandle v, const Vec3& p) const {
    std::size_t n = 0;
    double excess = 0;
    for (auto w : mesh_.vv_range(v)) {
      const double d = outside_by((mesh_.point(w) - p).norm());
      if (d > 0) ++n, excess += d * d;
    }
    return {n, excess};
  }

  /// Direction a boundary vertex may slide along (its boundary curve), or zero at a corner
  /// (boundary turning by more than 30 degrees), where it must stay.
  Vec3 boundary_tangent(VertexHandle v) const {
    const HalfedgeHandle out = mesh_.halfedge_handle(v);  // the outgoing boundary halfedge
    const Vec3 next = mesh_.point(mesh_.to_vertex_handle(out));
    const Vec3 prev = mesh_.point(mesh_.from_vertex_handle(mesh_.prev_halfedge_handle(out)));
    const Vec3 p = mesh_.point(v);
    Vec3 a = p - prev, b = next - p;
    if (!(a.norm() > 0) || !(b.norm() > 0)) return Vec3(0, 0, 0);
    if ((a.normalized() | b.normalized()) < std::cos(M_PI / 6)) return Vec3(0, 0, 0);
    return (next - prev).normalized();
  }

  /// Where v lies on the creases (Kind::None without them).
  CreaseLines::Where crease_at(VertexHandle v) const {
    return creases_ ? creases_->locate(mesh_.point(v)) : CreaseLines::Where{};
  }

  /// The direction a vertex on a crease line slides along (its crease's, through the points around).
  static Vec3 crease_tangent(const CreaseLines::Where& where) {
    const Vec3 d = where.ahead - where.back;
    return d.sqrnorm() > 0 ? d.normalized() : Vec3(0, 0, 0);
  }

  /// Where a move of v to x (settled; the projection's input) ends: on the reference (projected),
  /// or, for a vertex on a crease, along it (`where`; the crease lies on the reference).
  Vec3 placed(VertexHandle v, const Vec3& x, const Vec3& n, const CreaseLines::Where& where, NeighbourCache* cache) {
    if (where.kind != CreaseLines::Kind::None) return CreaseGuard::constrain(mesh_.point(v), where, x);
    return project_vertex(mesh_, v, x, n, reference_, cache);
  }

  bool relocate(VertexHandle v) {
    if (protect_tips_ && is_tip(mesh_, v)) return false;
    const bool boundary = mesh_.is_boundary(v);
    const CreaseLines::Where where = boundary ? CreaseLines::Where{} : crease_at(v);
    if (where.kind == CreaseLines::Kind::Corner) return false;
    const Vec3 tangent = boundary ? boundary_tangent(v)
                         : where.kind == CreaseLines::Kind::Line ? crease_tangent(where) : Vec3(0, 0, 0);
    if ((boundary || where.kind != CreaseLines::Kind::None) && tangent.sqrnorm() == 0) return false;
    const Vec3 start = mesh_.point(v);
    // Not one whose relocation failed with nothing near it changed since (failure memory): a
    // lookup, asked before the star is measured (a vertex of high valence is asked once for each
    // edge of its star).
    if (remember_failures_ && relocation_unchanged(v)) return false;
    // Progress: fewer star edges outside, or as many but closer to the interval (a strictly
    // decreasing measure, so rounds cannot cycle). A vertex with its whole star inside cannot
    // progress, so it is not settled and projected in vain (cheese: 23 000 of 130 000 attempts).
    const auto [n_before, e_before] = outside_around(v, start);
    if (n_before == 0) return false;
    const Vec3 n = geom::vertex_normal(mesh_, v);
    std::vector<Vec3>& ring = ring_;
    ring.clear();
    for (auto w : mesh_.vv_range(v)) ring.push_back(mesh_.point(w));
    const Vec3 x = settle(start, ring, n, tangent);
    const Vec3 p = placed(v, x, n, where, cache_of(v));
    const auto [n_after, e_after] = outside_around(v, p);
    if (n_after > n_before || (n_after == n_before && !(e_after < 0.9 * e_before)) ||
        !geom::move_is_safe(mesh_, v, p)) {
      if (remember_failures_) set_tick(relocate_failed_at_, v.idx(), mesh_.n_vertices());
      return false;
    }
    mesh_.point(v) = p;
    ++clock_;
    stamp(v);
    return true;
  }

  /// Relocates an end of e, else a vertex opposite e (moving it changes the triangles around e, and
  /// often lets the next pass fix e by an end).
  bool try_relocate(EdgeHandle e) {
    const HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    if (relocate(mesh_.from_vertex_handle(h)) || relocate(mesh_.to_vertex_handle(h))) return true;
    for (int s = 0; s < 2; ++s) {
      const HalfedgeHandle g = mesh_.halfedge_handle(e, s);
      if (!mesh_.is_boundary(g) && relocate(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(g)))) return true;
    }
    return false;
  }

  /// Spreads the strain of a stubborn edge over its neighbourhood: the interior vertices within
  /// kPatchRings rings of e take a few Gauss-Seidel rounds of the relocation (settle, project, keep
  /// the move only if it folds nothing). The patch keeps its new positions only if fewer of its
  /// edges lie outside the interval, or as many but with 10 % less squared excess; else every
  /// vertex goes back. (An edge of 1.98 between six regular vertices cannot be split, its halves
  /// would be short, nor fixed by moving one end, whose other edges are at their limits.)
  bool try_relax_patch(EdgeHandle e, CleanupCounts& counts) {
    const HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    const VertexHandle a = mesh_.from_vertex_handle(h), b = mesh_.to_vertex_handle(h);
    if (rest_ && rest_->resting(a, b)) {
      ++counts.rested;
      failed_patches_.push_back(e.idx());
      return false;
    }
    if (relax_patch({a, b}, VertexHandle(), Vec3(0, 0, 0), false)) return true;
    failed_patches_.push_back(e.idx());
    if (rest_) rest_->failed(a, b);
    return false;
  }

  /// Has the patch of e already failed in this cleanup? (Retrying it in the next round costs a few
  /// hundred projections and almost never succeeds; the next iteration's cleanup tries again.)
  bool patch_failed(EdgeHandle e) const {
    return std::find(failed_patches_.begin(), failed_patches_.end(), e.idx()) != failed_patches_.end();
  }

  /// Adds to `patch` every vertex within `rings` rings of it (kPatchRings for a patch), marking
  /// all in patch_mark_ (the caller clears the marks). With `ring_ends`, (*ring_ends)[r] is the
  /// size of `patch` once the vertices within r rings are in it ([0]: the seeds).
  void grow_rings(std::vector<VertexHandle>& patch, std::size_t rings = kPatchRings,
                  std::vector<std::size_t>* ring_ends = nullptr) {
    std::vector<char>& in = patch_mark_;
    if (in.size() < mesh_.n_vertices()) in.assign(mesh_.n_vertices(), 0);
    for (auto v : patch) in[v.idx()] = 1;
    if (ring_ends) ring_ends->assign(1, patch.size());
    for (std::size_t begin = 0, r = 0; r < rings; ++r) {
      const std::size_t end = patch.size();
      for (std::size_t i = begin; i < end; ++i)
        for (auto w : mesh_.vv_range(patch[i]))
          if (!in[w.idx()]) in[w.idx()] = 1, patch.push_back(w);
      begin = end;
      if (ring_ends) ring_ends->push_back(patch.size());
    }
  }

  /// The faces a relaxation of the patch around v can move: those incident to its vertices.
  std::vector<OpenMesh::FaceHandle> patch_faces(VertexHandle v) {
    std::vector<VertexHandle> patch{v};
    grow_rings(patch);
    std::vector<OpenMesh::FaceHandle> faces;
    for (auto u : patch) {
      patch_mark_[u.idx()] = 0;
      for (auto f : mesh_.vf_range(u)) faces.push_back(f);
    }
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    return faces;
  }

  /// Moves `pinned` (if valid) to `pin_at`, then relaxes the other interior vertices within
  /// kPatchRings rings of `patch` (which includes `pinned`). Keeps the result if the patch's edges
  /// outside the interval are fewer, or as many with 10 % less squared excess, or (with
  /// `allow_equal`) not more; else every vertex goes back.
  bool relax_patch(std::vector<VertexHandle> patch, VertexHandle pinned, const Vec3& pin_at, bool allow_equal,
                   const GapJudge* judge = nullptr) {
    std::vector<char>& in = patch_mark_;
    grow_rings(patch);
    // Edges of the patch: those with an end inside it.
    auto measure = [&]() {
      std::size_t n = 0;
      double excess = 0;
      for (auto v : patch)
        for (auto w : mesh_.vv_range(v)) {
          if (in[w.idx()] && w.idx() < v.idx()) continue;  // count inner edges once
          const double d = outside_by((mesh_.point(w) - mesh_.point(v)).norm());
          if (d > 0) ++n, excess += d * d;
        }
      return std::pair<std::size_t, double>{n, excess};
    };
    const auto [n_before, e_before] = measure();
    std::vector<Vec3> saved;
    saved.reserve(patch.size());
    for (auto v : patch) saved.push_back(mesh_.point(v));
    // A snap (judged move) may sharpen adjacent faces further than the other edits (kSnapAdjacentCos).
    const double adjacent_cos = judge ? kSnapAdjacentCos : geom::kMinAdjacentCos;
    bool ok = !pinned.is_valid() || geom::move_is_safe(mesh_, pinned, pin_at, adjacent_cos);
    if (ok && pinned.is_valid()) mesh_.point(pinned) = pin_at;
    std::vector<Vec3>& ring = ring_;
    // Each vertex moves a little per sweep: its kd-tree answer is mostly reusable (reference_surface.h).
    if (!caches_) patch_caches_.assign(patch.size(), NeighbourCache{});
    // A sweep in which no vertex moved ends the relaxation (the next would not move any either).
    for (int sweep = 0, moved = 1; ok && moved && sweep < kPatchSweeps; ++sweep) {
      moved = 0;
      for (std::size_t i = 0; i < patch.size(); ++i) {
        const VertexHandle v = patch[i];
        // A snap (judged) may move a tip: it moves vertices onto the input's own points.
        if (v == pinned || mesh_.is_boundary(v) || (protect_tips_ && !judge && is_tip(mesh_, v))) continue;
        const CreaseLines::Where where = crease_at(v);
        if (where.kind == CreaseLines::Kind::Corner) continue;
        ring.clear();
        for (auto w : mesh_.vv_range(v)) ring.push_back(mesh_.point(w));
        const Vec3 n = geom::vertex_normal(mesh_, v);
        const Vec3 x = settle(mesh_.point(v), ring, n,
                              where.kind == CreaseLines::Kind::Line ? crease_tangent(where) : Vec3(0, 0, 0));
        if (x == mesh_.point(v)) continue;  // its edges are well inside: settle leaves it, so does the projection
        NeighbourCache* cache = caches_ ? cache_of(v) : &patch_caches_[i];
        const Vec3 p = placed(v, x, n, where, cache);
        if (geom::move_is_safe(mesh_, v, p, adjacent_cos)) mesh_.point(v) = p, moved = 1;
      }
    }
    if (ok) {
      const auto [n_after, e_after] = measure();
      ok = n_after < n_before || (n_after == n_before && (allow_equal || e_after < 0.9 * e_before));
      ok = ok && (!judge || judge->holds(mesh_));
    }
    if (!ok) {
      for (std::size_t i = 0; i < patch.size(); ++i) mesh_.point(patch[i]) = saved[i];
    } else {
      ++clock_;
      for (auto v : patch) stamp(v);
    }
    for (auto v : patch) in[v.idx()] = 0;
    return ok;
  }

 public:
  /// See snap_to_features() in interval_cleanup.h.
  bool snap(const SnapMove& move, const PointIndex& features, std::size_t& budget) {
    const VertexHandle v = move.v;
    if (mesh_.is_boundary(v) || budget == 0) return false;
    if (crease_at(v).kind != CreaseLines::Kind::None) return false;  // it stays on its crease
    // The patch's faces lie within kPatchRings + 1 edges of v.
    const double reach = (move.target - mesh_.point(v)).norm() + (kPatchRings + 1) * e_max_ + e_min_;
    const GapJudge judge(mesh_, patch_faces(v), move.target, features, e_min_, reach);
    --budget;
    if (relax_patch({v}, v, move.target, true, &judge)) return true;
    if (!move.partial) return false;
    const Vec3 from = mesh_.point(v), n = geom::vertex_normal(mesh_, v);
    for (double s : kPartialSnaps) {
      if (budget == 0) break;
      --budget;
      // Projected like every other vertex move (the normal keeps it on its own sheet).
      const Vec3 partial = project_vertex(mesh_, v, from + s * (move.target - from), n, reference_, cache_of(v));
      if (relax_patch({v}, v, partial, true, &judge)) return true;
    }
    return false;
  }

 private:
  static constexpr std::size_t kPatchRings = 2;
  /// CleanupOptions::stop is asked once per this many edges of a round.
  static constexpr std::size_t kStopCheckEvery = 64;
  std::stop_token stop_;
  static constexpr int kPatchSweeps = 6;
  /// When the vertex cannot reach the feature point, the fractions of the way to it tried in turn.
  /// Measured (Table 4.2 setup, Hausdorff % of the bbox diagonal): 15 and 8 % after 25 % bring
  /// nefertiti 0.198 -> 0.185 (CGAL 0.193); with them the guard had to become per point (kitten).
  static constexpr double kPartialSnaps[] = {0.85, 0.7, 0.55, 0.4, 0.25, 0.15, 0.08};
  /// The sharpest pair of adjacent faces a snap may make (cosine between their normals, about 154
  /// degrees apart: faces meeting at 26 degrees); the other edits stop at geom::kMinAdjacentCos
  /// (60 degrees). Three faces around the tip of a horn meet at about 60 degrees or less, so under
  /// that rule a valence-3 vertex near the apex could not move up at all, not even 8 % of the way
  /// (cow: its horns' vertices, 2.8 units from the apex; camelhead). The move goes toward a point
  /// of the reference, whose own faces are that sharp there, and keeps its other guards (no fold:
  /// no face tilts by 60 degrees or more; interval; GapJudge). Measured (Table 4.2 setup,
  /// Hausdorff % of the bbox diagonal): cow 2.06 -> 1.80, camelhead 1.57 -> 1.25, cheese 4.44 ->
  /// 4.19; the same meshes as before on eight, bunny, spot and fandisk; -0.8 and -0.97 give about
  /// the same.
  static constexpr double kSnapAdjacentCos = -0.9;

  TriMesh& mesh_;
  const ReferenceSurface& reference_;
  double e_min_, e_max_, f_;
  bool collapsed_ = false;              ///< deleted elements to collect (finish)
  bool protect_tips_ = false;            ///< CleanupOptions::protect_tips
  const CreaseGuard* creases_ = nullptr;  ///< CleanupOptions::creases (null when there are none)
  bool collapsed_since_round_ = false;  ///< a collapse in the current round
  std::vector<Vec3> ring_;        ///< a vertex's 1-ring points, for relocate and relax_patch (reused buffer)
  std::vector<char> patch_mark_;  ///< grow_rings' membership flags, all zero between calls
  std::vector<NeighbourCache> patch_caches_;  ///< relax_patch's kd-tree answers, one per patch vertex
  /// The iterations' kd-tree answers, one per vertex index (projection.h), when the caller keeps
  /// them: a relocated vertex has moved little since its projection, so its answer is mostly
  /// reusable. A vertex without a slot (a split's, beyond the vector) goes without; a slot left from
  /// another vertex (after a renumbering) still gives an exact answer (reference_surface.h).
  std::vector<NeighbourCache>* caches_;
  std::vector<int> failed_patches_;           ///< edges whose patch relaxation failed (patch_failed)
  PatchRest* rest_ = nullptr;                 ///< CleanupOptions::rest
  bool remember_failures_ = true;             ///< CleanupOptions::remember_failures
  std::uint32_t clock_ = 0;                   ///< ticks once per fix (failure memory)
  /// Stamps not yet handed on (spread_stamps): vertex index and tick.
  std::vector<std::pair<int, std::uint32_t>> stamped_;
  /// Per vertex: the tick of the last fix that changed a vertex within kFailureRings rings of it,
  /// and within kRelocateRings rings.
  std::vector<std::uint32_t> changed_near_, changed_close_;
  std::vector<VertexHandle> ring_walk_;   ///< spread_stamps' walk (reused buffer)
  std::vector<std::size_t> ring_ends_;    ///< and its rings' ends (grow_rings)
  std::vector<std::uint32_t> failed_at_;      ///< per edge: the tick at its last failure, 0 = none
  std::vector<std::uint32_t> relocate_failed_at_;  ///< per vertex: the tick its last relocation failed, 0 = none
  /// Patch relaxations left in this cleanup (interval_cleanup's `patch_budget`).
  std::size_t patch_budget_ = std::max<std::size_t>(64, mesh_.n_edges() / 1000);
};

}  // namespace

std::size_t snap_to_features(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                             const std::vector<SnapMove>& moves, const PointIndex& features,
                             std::size_t& budget, const CreaseGuard* creases) {
  Cleanup cleanup(mesh, reference, e_min, e_max, 0.5);
  cleanup.set_creases(creases);
  std::size_t moved = 0;
  for (const SnapMove& move : moves)
    if (cleanup.snap(move, features, budget)) ++moved;
  return moved;
}

PatchRest::~PatchRest() {
  try {
    OpenMesh::VPropHandleT<Failures> at;
    if (mesh_.get_property_handle(at, kName)) mesh_.remove_property(at);
  } catch (...) {  // the name's string could not be allocated: the property stays, harmless
  }
}

void PatchRest::begin() {
  const bool found = mesh_.get_property_handle(at_, kName);
  if (found && cleanup_ == 0) mesh_.remove_property(at_);  // another run's, whose numbers are not ours
  if (!found || cleanup_ == 0) mesh_.add_property(at_, kName);
  ++cleanup_;
}

std::uint32_t PatchRest::rest_after(std::uint32_t row) {
  return row < kRow ? 0 : std::uint32_t{1} << std::min(row - kRow, kMaxRestShift);
}

bool PatchRest::resting(VertexHandle a, VertexHandle b) const {
  // Each end failed in one of the last rest_after(its row) cleanups, not in this one.
  auto rests = [this](const Failures& f) {
    return f.at > 0 && f.at < cleanup_ && cleanup_ - f.at <= rest_after(f.row);
  };
  return rests(mesh_.property(at_, a)) && rests(mesh_.property(at_, b));
}

void PatchRest::failed(VertexHandle a, VertexHandle b) {
  for (auto v : {a, b}) {
    Failures& f = mesh_.property(at_, v);
    if (f.at == cleanup_) continue;
    // The row goes on when this failure comes right after the rest the last one gave (at most two
    // apart before a rest of more than one cleanup).
    const std::uint32_t within = std::max<std::uint32_t>(2, rest_after(f.row) + 1);
    f.row = f.at > 0 && cleanup_ - f.at <= within ? f.row + 1 : 1;
    f.at = cleanup_;
  }
}

CleanupCounts interval_cleanup(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                               double flip_factor, const CleanupOptions& options) {
  Cleanup cleanup(mesh, reference, e_min, e_max, flip_factor, options.caches);
  if (options.patch_budget > 0) cleanup.set_patch_budget(options.patch_budget);
  cleanup.set_remember_failures(options.remember_failures);
  cleanup.set_protect_tips(options.protect_tips);
  cleanup.set_creases(options.creases);
  cleanup.set_stop(options.stop);
  if (options.rest) options.rest->begin();
  cleanup.set_rest(options.rest);
  CleanupCounts counts;
  counts.outside_before = cleanup.count_outside();
  if (counts.outside_before > 0)
    for (int r = 0; r < options.rounds && !cleanup.stop_requested(); ++r)
      if (cleanup.round(counts, options.boundary_only) == 0) break;
  cleanup.finish();
  counts.outside_after = cleanup.count_outside();
  return counts;
}

}  // namespace remesh
