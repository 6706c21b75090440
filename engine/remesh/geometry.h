#pragma once
/// \file geometry.h
/// Small geometric helpers shared by the steps: angles, closest point on a triangle, normals and the
/// fold / degeneracy tests every mesh edit must pass.

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include "core/mesh.h"

namespace remesh {

/// An axis-aligned box; empty (lo above hi) until a point is added.
struct Box {
  Vec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
  void add(const Vec3& p) { lo.minimize(p), hi.maximize(p); }
  bool contains(const Vec3& q) const {
    return q[0] >= lo[0] && q[0] <= hi[0] && q[1] >= lo[1] && q[1] <= hi[1] && q[2] >= lo[2] && q[2] <= hi[2];
  }
  /// Squared distance from q to the box (0 inside).
  double squared_distance(const Vec3& q) const {
    double d = 0;
    for (int a = 0; a < 3; ++a) {
      const double out = std::max({lo[a] - q[a], 0.0, q[a] - hi[a]});
      d += out * out;
    }
    return d;
  }
};

}  // namespace remesh

namespace remesh::geom {

/// The valence Algorithm 4 aims at: 6 inside, 4 on the boundary.
inline unsigned target_valence(const TriMesh& mesh, OpenMesh::VertexHandle v) { return mesh.is_boundary(v) ? 4u : 6u; }

/// Smallest interior angle of triangle (a, b, c), in radians; 0 for a degenerate triangle.
double min_angle(const Vec3& a, const Vec3& b, const Vec3& c);

/// Unnormalised normal (b - a) x (c - a); its length is twice the area.
inline Vec3 cross_normal(const Vec3& a, const Vec3& b, const Vec3& c) { return (b - a) % (c - a); }

/// Closest point to p on triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Closest point to p on segment [a, b].
Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b);

/// Smallest angle (radians) a triangle created by an edit may have. Below it a triangle counts as
/// degenerate; an edit may still create one no worse than the worst it replaces.
constexpr double kMinAngle = 1.0 * 3.14159265358979323846 / 180.0;

/// min_angle(a, b, c) < kMinAngle, the same answer without the arc tangent for a triangle whose
/// smallest angle is clearly larger (nearly every call of the fold tests).
bool below_min_angle(const Vec3& a, const Vec3& b, const Vec3& c);

/// The degeneracy rule of every edit: a triangle it makes may have its smallest angle below
/// kMinAngle only if no worse than the worst triangle it replaces, whose angle `worst()` returns.
/// worst() runs at most once, and only for a new triangle below kMinAngle: the arc tangents of the
/// old triangles are nearly never needed.
/// With a `slack`, "no worse" allows a relative loss of that much (split_point_ok's kSplitAngleSlack).
template <class Worst>
class AngleFloor {
 public:
  explicit AngleFloor(Worst worst, double slack = 0) : worst_(std::move(worst)), keep_(1 - slack) {}
  /// Would triangle (a, b, c) break the rule? Equal to
  /// min_angle(a, b, c) < min(kMinAngle, (1 - slack) worst()).
  bool breaks(const Vec3& a, const Vec3& b, const Vec3& c) {
    if (!below_min_angle(a, b, c)) return false;
    if (!known_) worst_angle_ = worst_() * keep_, known_ = true;
    return min_angle(a, b, c) < worst_angle_;
  }

 private:
  Worst worst_;
  double keep_;
  bool known_ = false;
  double worst_angle_ = 0;
};

/// Smallest cosine between the normal of a triangle before and after an edit (about 60 degrees).
/// Below it the edit folds or badly tilts the triangle and is refused.
constexpr double kMinNormalCos = 0.5;

/// Smallest cosine between the normals of two adjacent triangles an edit may leave (a dihedral
/// angle of 60 degrees between them); an edit may keep a pair that was already sharper, not
/// sharpen it further.
constexpr double kMinAdjacentCos = -0.5;
static_assert(kMinAdjacentCos <= 0, "adjacent_ok() accepts a pair with a non-negative cosine at once");

/// Is the pair of adjacent faces (unnormalised normals, before and after an edit) acceptable? With
/// `min_cos` (at most 0) in place of kMinAdjacentCos: the feature snap's looser limit
/// (interval_cleanup.cpp, kSnapAdjacentCos).
bool adjacent_ok(const Vec3& f_before, const Vec3& g_before, const Vec3& f_after, const Vec3& g_after,
                 double min_cos = kMinAdjacentCos);

/// True when `after` (unnormalised normal) agrees with `before`: both non-zero and the angle between
/// them is below acos(min_cos).
bool normals_agree(const Vec3& before, const Vec3& after, double min_cos = kMinNormalCos);

/// The three corner vertices of face f.
void face_vertices(const TriMesh& mesh, OpenMesh::FaceHandle f, OpenMesh::VertexHandle out[3]);

/// Unnormalised normal of face f from the current points.
Vec3 face_normal(const TriMesh& mesh, OpenMesh::FaceHandle f);

/// Area-weighted unit normal of vertex v (zero for an isolated vertex or a degenerate star).
Vec3 vertex_normal(const TriMesh& mesh, OpenMesh::VertexHandle v);

/// face_normal() of every face, one per face index (zero for deleted faces). Parallel.
std::vector<Vec3> face_normals(const TriMesh& mesh, unsigned threads);

/// vertex_normal() of every vertex, one per vertex index. Parallel.
std::vector<Vec3> vertex_normals(const TriMesh& mesh, unsigned threads);

/// 2 pi minus the sum of the angles at interior vertex v (radians; positive at a tip, negative at
/// a saddle); 0 for a boundary vertex or a star with a zero-length edge.
double angle_deficit(const TriMesh& mesh, OpenMesh::VertexHandle v);

/// Smallest angle (radians) of the faces around v (the worst angle of its star).
double star_min_angle(const TriMesh& mesh, OpenMesh::VertexHandle v);

/// Would moving v to `p` keep every face of its star unfolded and non-degenerate? A new face may
/// be below kMinAngle only if it is no worse than the worst face of the star before the move.
/// Adjacent pairs are judged by adjacent_ok() with `min_adjacent_cos`.
bool move_is_safe(const TriMesh& mesh, OpenMesh::VertexHandle v, const Vec3& p,
                  double min_adjacent_cos = kMinAdjacentCos);

}  // namespace remesh::geom
