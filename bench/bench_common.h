#pragma once
/// \file bench_common.h
/// Helpers of the benchmark programs: a small mesh loader (OpenMesh I/O, until engine/io is linked),
/// scaling, topology counts and the symmetric Hausdorff distance by dense sampling.

#include <cstddef>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace remesh::bench {

/// Reads a mesh with the product's reader (remesh_io: validated, repaired) when it is built, else
/// OFF/OBJ/PLY/STL with OpenMesh. Throws naming the file on failure.
TriMesh load_mesh(const std::string& path);

/// Writes an OFF file with 17 significant digits. Throws std::runtime_error on failure.
void write_off(const TriMesh& mesh, const std::string& path);

/// Splits every triangle into four at its edges' midpoints (the corners' triangles and the middle
/// one, orientation kept): the same surface with 4x the faces and half the mean edge, for the
/// benchmark on meshes larger than the shared ones (--subdivide). Precondition: no deleted elements.
TriMesh subdivide_midpoints(const TriMesh& mesh);

/// Scales the mesh about the origin so that its mean edge length becomes `mean_edge`. Returns the factor.
double scale_to_mean_edge(TriMesh& mesh, double mean_edge);

struct Topology {
  long euler = 0;
  std::size_t boundary_loops = 0, components = 0;
};
Topology topology_of(const TriMesh& mesh);

/// Symmetric Hausdorff distance between a and b, estimated by sampling: every vertex plus about
/// `samples` points spread over the faces by area (barycentric grid per face), each measured
/// exactly against the other mesh's triangles (triangle_bvh.h); the larger of the two one-sided
/// maxima.
double hausdorff_distance(const TriMesh& a, const TriMesh& b, std::size_t samples, unsigned threads);

/// Local thickness of `surface` at each point p (with unit normal n, pointing out): the distance
/// from p to the nearest point of a face of `surface` whose normal opposes n (dot < -0.3), i.e. the
/// other side of the part p lies on; infinity when there is none. Brute force over the faces: for
/// a few thousand points.
std::vector<double> thickness_at(const TriMesh& surface, const std::vector<Vec3>& points,
                                 const std::vector<Vec3>& normals, unsigned threads);

/// Peak resident set size of this process so far (VmHWM), in MiB.
double peak_rss_mib();

}  // namespace remesh::bench
