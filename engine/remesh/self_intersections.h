#pragma once
/// \file self_intersections.h
/// Not in the thesis: which faces of the mesh cross each other. The fold guard (fold_guard.h) and
/// the checks of every edit look only at a vertex's own faces and their neighbours; where the
/// reference itself is crumpled (nefertiti's base: thin triangles folded over their neighbours) or
/// two sheets of the surface lie closer than an edge, the projection can put faces a few rings
/// apart through each other. untangle.h moves them apart.

#include <array>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "core/mesh.h"
#include "remesh/geometry.h"  // Box

namespace remesh {

/// Do triangles (a, b, c) and (d, e, f) share a point other than the corners they have in common?
/// Corners are shared when they are equal points. Two triangles with two corners in common (an edge)
/// count as not crossing (one would have to fold onto the other, which the edits never do).
/// Triangles in one plane cross when their insides overlap (a fold within a flat face); touching
/// (a corner on the other, an edge along it) never counts. An orientation test whose sign rounding
/// could have decided counts as 0 (the point on the plane; Shewchuk's error bound), so triangles
/// that are coplanar but for rounding (a flat face's points, projected onto it) are tested in their
/// plane. The test looks for an edge of one through the inside of the other, so two triangles that
/// meet only edge to edge, both ends of their common segment on both boundaries (a sheet and its
/// exact mirror image), count as touching.
bool triangles_cross(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e, const Vec3& f);

/// triangles_cross for faces f and g of `mesh`; faces with an edge in common never cross.
bool faces_cross(const TriMesh& mesh, OpenMesh::FaceHandle f, OpenMesh::FaceHandle g);

/// A bounding sphere of a face: its centroid and the largest distance from it to a corner.
struct Sphere {
  Vec3 centre;
  double radius = 0;
};
Sphere face_sphere(const TriMesh& mesh, OpenMesh::FaceHandle f);

/// Do the spheres overlap (touching counts, with a margin of 1e-9 of the radii for rounding)?
inline bool spheres_overlap(const Sphere& a, const Sphere& b) {
  const double reach = (a.radius + b.radius) * (1 + 1e-9);
  return (a.centre - b.centre).sqrnorm() <= reach * reach;
}

/// Per face index: its face_sphere() and corners (a deleted face: radius 0 at the origin, corners 0;
/// not counted in `largest`).
struct FaceSpheres {
  std::vector<Vec3> centres;
  std::vector<double> radii;
  std::vector<std::array<int, 3>> corners;  ///< vertex indices
  double largest = 0;  ///< the largest radius
};
FaceSpheres face_spheres(const TriMesh& mesh);

/// Does the sphere (centre, radius) meet `box` grown by `grow` on every side?
bool sphere_meets(const Box& box, const Vec3& centre, double radius, double grow = 0);

/// Every pair (f, g), f < g, of faces of `mesh` that cross (faces_cross), sorted; with `region`,
/// only the pairs with a face whose bounding sphere meets it. Deleted faces are passed over (the
/// untangling's collapses leave them until its end). Parallel; the same answer whatever the
/// thread count.
std::vector<std::pair<unsigned, unsigned>> find_self_intersections(const TriMesh& mesh, unsigned threads,
                                                                   const Box* region = nullptr);

/// Pairs of faces whose bounding spheres overlap, per face on average, above which a surface lies
/// over itself throughout: a remeshed surface has 6-8 (its faces' neighbours; cheese simplified,
/// with slivers in walls thinner than the interval, 22), one sphere remeshed 256 times at one
/// place 1 670.
constexpr std::size_t kLayeredOverlapsPerFace = 64;

/// Does the mesh lie over itself throughout (a part duplicated in place, shells stacked on each
/// other): more than kLayeredOverlapsPerFace pairs of faces with overlapping bounding spheres per
/// face? Such a surface has crossing pairs in the order of its faces times its layers (64 copies of
/// a sphere at one place, 32 300 faces: 753 832 pairs), which moving faces apart cannot separate,
/// and whose search (find_self_intersections) took longer than the remeshing. Stops counting at
/// the limit: at most about kLayeredOverlapsPerFace sphere tests a face, no triangle tests. The
/// answer does not depend on the thread count.
bool lies_over_itself(const TriMesh& mesh, unsigned threads);

/// find_self_intersections(mesh, threads), or nullopt for a mesh that lies over itself throughout
/// (lies_over_itself), found in the same search: its answer costs one search, and a layered mesh
/// no more than lies_over_itself.
std::optional<std::vector<std::pair<unsigned, unsigned>>> find_self_intersections_unless_layered(const TriMesh& mesh,
                                                                                                unsigned threads);

/// Pairs of overlapping face spheres an input's search may meet, at least, whatever its face count.
constexpr std::size_t kInputOverlapsAtLeast = 20'000'000;

/// The same for an input mesh, to tell the user (remesh info, the job's input summary): an input
/// may have long slivers whose spheres overlap many faces (cheese.off: 125 pairs a face, where
/// kLayeredOverlapsPerFace would call it layered), so its search stops only past
/// max(kLayeredOverlapsPerFace a face, kInputOverlapsAtLeast) pairs: cheese's 2.2 million are
/// counted; an icosahedron 2 048 times at one place (24 000 a face) is not. Nullopt: not counted,
/// the input lies over itself throughout or is made of long slivers.
std::optional<std::vector<std::pair<unsigned, unsigned>>> find_input_self_intersections(const TriMesh& mesh,
                                                                                       unsigned threads);

}  // namespace remesh
