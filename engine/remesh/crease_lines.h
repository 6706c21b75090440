#pragma once
/// \file crease_lines.h
/// Not in the thesis: the creases of the reference (lines of edges whose two faces meet at more
/// than kCreaseAngle), for the tangential filter (low_pass_filter.h; equalize.cpp uses it until the
/// interval cleanup starts). A mesh vertex that lies on a crease slides along it only (no farther
/// than the next point of the crease, so it stays on a bent one), and one where the creases meet,
/// end or bend sharply holds still, as a boundary vertex does: the filter's move in the vertex's
/// tangent plane (for a vertex on a crease, a plane across both faces' planes) followed by the
/// projection takes it off the crease onto one side, and the remeshed surface cuts the edge off.
/// On a cylinder of 128 segments given as one row of side slivers with fan caps (as CAD exports
/// write it), at [0.08, 0.12]: the rim lost 2/3 of its vertices in the second iteration; the run
/// stalled at 97.5 % inside with 415 of 2466 vertices up to 0.17 off the surface (5 % of the bbox
/// diagonal) and the rims' points up to 0.145 from it. With the creases: 100 % inside after 24
/// iterations, every vertex on the surface (also with 64 and 500 segments, and at [0.04, 0.06] and
/// [0.15, 0.225]; a washer's bent inner rim too), the rims' points within 0.05. The creases are
/// not kept exactly: Algorithm 3's splits and collapses of the mesh's edges along a crease put
/// their vertex on the chord, and the projection takes it to one side. With Params::keep_creases
/// every step follows CreaseGuard (below) and they are kept: a box's edges within 1e-9, the
/// cylinder's rims within the sag of an edge over the input's polyline (0.002 at [0.08, 0.12]).

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/mesh.h"
#include "remesh/geometry.h"
#include "remesh/point_index.h"

namespace remesh {

/// A crease: a connected group of at least kMinCreaseEdges reference edges whose faces' normals
/// differ by more than kCreaseAngle. A scan's noise makes such edges too, alone or a few together:
/// of the meshes of ../shared/meshes, armadillo, mountain, spot, bunny, eight, kitten, camelhead and
/// bunny_zipper have none, while fandisk has 693 crease edges, cheese 3038, cow 27, nefertiti 10.
/// Over 60 degrees the scans keep more (cow 112, nefertiti 64, camelhead 12, bunny_zipper 10), and
/// the rule cost cow's simplification: Hausdorff distance over five intervals 2.29 % of the bbox
/// diagonal without it, 3.19 % with 60 degrees, 2.50 % with 75 (refinement 1.22, 1.37, 1.31 %).
/// CAD creases meet at 90 degrees; over 45 degrees, or in groups of 5, the scans keep hundreds.
constexpr double kCreaseAngle = 75.0 * 3.14159265358979323846 / 180.0;
constexpr std::size_t kMinCreaseEdges = 10;

/// Turn (radians) between a crease's two segments at a vertex above which the vertex is a corner.
constexpr double kCreaseBend = 30.0 * 3.14159265358979323846 / 180.0;

class CreaseLines {
 public:
  /// The creases of `reference` (a valid mesh, typically the input).
  explicit CreaseLines(const TriMesh& reference);
  /// The given edges of `reference` as its creases (tests).
  CreaseLines(const TriMesh& reference, const std::vector<OpenMesh::EdgeHandle>& edges);

  bool empty() const { return segments_.empty(); }
  std::size_t size() const { return segments_.size(); }

  enum class Kind { None, Line, Corner };
  struct Where {
    Kind kind = Kind::None;
    /// Line: p lies on the crease between these two points (the ends of its segment, or, at a
    /// crease vertex, its two neighbours along the crease).
    Vec3 back{0, 0, 0}, ahead{0, 0, 0};
  };
  /// Where p lies: on no crease (farther than `tol` from each), on one, or at a corner (a point
  /// where creases meet or end, one bends by more than kCreaseBend, or two pass within tol).
  Where locate(const Vec3& p, double tol) const;

  /// The part of move `t` from p (located at `where`, a Line) that keeps p on the crease: along
  /// the side (towards `ahead` or `back`) t points to more, no farther than that point.
  static Vec3 slide(const Vec3& p, const Where& where, const Vec3& t);

  /// Does one crease run from a to b (both within `tol` of it), its length between them at most
  /// `max_arc`, passing no corner (it may end at one: a or b)? With `path`, the segments it runs
  /// along are appended to it, as pairs of points.
  bool joined(const Vec3& a, const Vec3& b, double tol, double max_arc,
              std::vector<std::array<Vec3, 2>>* path = nullptr) const;

 private:
  struct Segment {
    std::uint32_t a, b;  ///< indices into points_
  };
  /// The segments passing within tol of p, each once (a per-thread buffer, valid until the next call).
  const std::vector<std::uint32_t>& segments_near(const Vec3& p, double tol) const;
  std::vector<Vec3> points_;            ///< the reference's vertices
  std::vector<Segment> segments_;
  std::vector<std::uint8_t> corner_;    ///< by point: a corner of the crease network
  /// By point on a crease and not a corner: its two neighbours along the crease.
  std::vector<std::array<std::uint32_t, 2>> along_;
  PointIndex samples_;                  ///< points along the segments (crease_lines.cpp)
  std::vector<std::uint32_t> sample_segment_;  ///< by sample: its segment
  double reach_ = 0;                    ///< half the samples' largest spacing
  /// The samples' bounding box: a point farther from it than reach_ + 2 tol is near no crease,
  /// known without the kd-tree (a scan's few creases: nefertiti's 10 edges cost its run with
  /// keep_creases 8.9 s instead of 6.2 before this test, every flip asking for both ends).
  Box box_;
};

/// Not in the thesis: the rule every step of a run follows so that the reference's creases stay in
/// the remeshed surface exactly, as its boundary curves do. Which vertices and edges are on a
/// crease is read from their positions (no mark to carry through the edits, renumberings and
/// snapshots): a vertex whose point lies on a crease within `tol` is on it (a Line vertex, or a
/// Corner), and an edge runs along a crease when one crease joins its ends, no longer than
/// kArcShare times the edge between them and through no corner (CreaseLines::joined: the chord of
/// a crease, not an edge across to a crease beside it, as the rims of a wall between two holes).
/// - a vertex on a crease moves along it only; a corner does not move (filter, cleanup);
/// - an edge along a crease is not flipped; its split point and its collapse point are put on the
///   crease;
/// - an edge with one end on a crease (not along it) collapses onto that end; one with both ends on
///   creases (not along one) is not collapsed, nor one along a crease between two corners.
/// Measured: Params::keep_creases (params.h) and bench/HISTORY.md.
class CreaseGuard {
 public:
  /// The crease between an edge's ends may be this much longer than the edge (a chord over an arc
  /// of 90 degrees is 0.90 as long as the arc; 1.5 lets arcs up to 150 degrees pass, so the mesh
  /// edge's own faces must show the crease too: kAlongCos).
  static constexpr double kArcShare = 1.5;
  /// A mesh edge runs along a crease only where its two faces meet at more than about 26 degrees
  /// (cosine between their normals below this). A chord across a cylinder's flat cap joins two
  /// points of its rim, and a crease of 90 degrees or less joins them: counted along it, the chord
  /// could not be flipped, and a split put its point on the rim, turning faces over (a cylinder of
  /// 64 segments whose caps are fans from a rim vertex, [0.08, 0.12]: 60.7 % inside, 5 728 folded
  /// pairs of faces; with this test 99.985 %, none).
  static constexpr double kAlongCos = 0.9;

  CreaseGuard(const CreaseLines& lines, double tol) : lines_(&lines), tol_(tol) {}

  bool empty() const { return lines_->empty(); }
  CreaseLines::Where locate(const Vec3& p) const { return lines_->locate(p, tol_); }
  bool on(const Vec3& p) const { return !empty() && locate(p).kind != CreaseLines::Kind::None; }
  /// Do the points a and b lie on one crease, joined as the class comment says?
  bool along(const Vec3& a, const Vec3& b) const;
  /// Does the mesh edge e run along a crease: its ends joined by one (along(a, b)) and its two
  /// faces meeting at an angle (kAlongCos)? A boundary edge never does.
  bool along(const TriMesh& mesh, OpenMesh::EdgeHandle e) const;
  /// The point closest to p of the crease that joins a and b (the ends of an edge along it; p a
  /// point of the edge); p itself when none joins them.
  Vec3 onto(const Vec3& p, const Vec3& a, const Vec3& b) const;
  /// Where a vertex at p (on a crease: `where`) ends up when a step would move it to x: x off the
  /// creases, p at a corner, along the crease towards x on a Line (slide).
  static Vec3 constrain(const Vec3& p, const CreaseLines::Where& where, const Vec3& x);

 private:
  const CreaseLines* lines_;
  double tol_;
};

}  // namespace remesh
