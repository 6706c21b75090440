#pragma once
/// \file mesh_generators.h
/// Small meshes built in code for the tests, and independent checks of mesh validity and topology
/// (written here, not taken from the engine, so tests do not grade the engine with its own code).

#include <cstddef>
#include <string>

#include "core/mesh.h"

namespace remesh::test {

/// Icosahedron subdivided `subdiv` times (20 * 4^subdiv faces), vertices on the sphere of `radius`.
TriMesh make_icosphere(int subdiv, double radius = 1.0);
/// Torus with nu x nv quads split into triangles; R = ring radius, r = tube radius.
TriMesh make_torus(int nu, int nv, double R, double r);
/// Flat open patch in z = 0, (nx x ny) quads of side `spacing`, alternating diagonals; one boundary loop.
TriMesh make_open_grid(int nx, int ny, double spacing);
/// Flat patch of the equilateral triangular lattice (side `spacing`), `rows` x `cols` vertices;
/// every interior vertex has valence 6.
TriMesh make_hex_lattice_patch(int rows, int cols, double spacing);
/// Closed surface of a voxel plate with `holes` square holes through it: genus == holes.
/// `cell` is the voxel size; each voxel face is split into 2 * sub * sub triangles.
TriMesh make_plate_with_holes(int holes, double cell = 1.0, int sub = 2);
/// Genus-2 closed surface (make_plate_with_holes(2, ...)).
TriMesh make_double_torus(double cell = 1.0, int sub = 2);
/// A box of n x n x n unit cells from the origin, its faces cut into cells of two triangles (its 12
/// edges are creases of 90 degrees, its 8 corners where three meet).
TriMesh make_box(int n);
/// Flat disk of `radius` in z = 0 triangulated as a fan: `sectors` triangles around a centre vertex
/// (a cap as CAD exports write it; above 360 sectors every triangle has an angle below 1 degree).
TriMesh make_fan(int sectors, double radius);
/// Closed cylinder (axis z, from 0 to `height`) as CAD exports write it: `segments` flat side facets,
/// each two slivers from rim to rim, and caps that are fans around a centre vertex.
TriMesh make_sliver_cylinder(int segments, double radius, double height);
/// The same side (without its axis vertices), its caps fans from the rim vertex at angle 0 (as
/// CAD exports write them): the caps' chords join two points of a rim.
TriMesh make_rim_fanned_cylinder(int segments, double radius, double height);
/// `copies` copies of `mesh` as components of one mesh, copy k moved by k * offset (offset zero:
/// all at one place, as a file instancing a part several times at one spot gives).
TriMesh stacked_copies(const TriMesh& mesh, int copies, const Vec3& offset = Vec3(0, 0, 0));

/// Empty if `mesh` is valid: no deleted elements left, every vertex manifold, every face a
/// non-degenerate triangle (area > area_eps * mean area), no folded pair of adjacent triangles
/// (normals with dot < -fold_cos). Otherwise a message naming the first problem.
std::string check_mesh_valid(const TriMesh& mesh, double area_eps = 1e-10, double fold_cos = 0.95);

std::size_t count_components(const TriMesh& mesh);
std::size_t count_boundary_loops(const TriMesh& mesh);
long euler_characteristic(const TriMesh& mesh);  ///< V - E + F (non-deleted, non-isolated vertices)

}  // namespace remesh::test
