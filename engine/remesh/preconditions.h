#pragma once
/// \file preconditions.h
/// What equalize() checks before it starts, and the parameters as a run takes them: the mesh's
/// size, its vertex stars, e_min against the mesh, and the estimated output against the limit
/// (ALGORITHM.md's "refuse a job over a configurable limit, with the estimate"). The service and
/// the CLI call the same checks before they queue or start a run.

#include <cstddef>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "core/mesh.h"
#include "remesh/params.h"

namespace remesh {

/// Estimated face count of the output: area / (sqrt(3)/4 * m^2), m = (e_min + e_max) / 2, e_max at
/// most the bounding-box diagonal (as equalize() takes it).
std::size_t estimate_output_faces(const TriMesh& mesh, const Params& params);
/// The largest estimate_output_faces() gives: past it (or not finite), it gives this.
inline constexpr std::size_t kMaxFaceEstimate = 1'000'000'000'000'000'000;

/// The parameters a run uses: e_max at most the mesh's bounding-box diagonal. No edge on the
/// surface is longer, so the same edges are inside, and the steps that aim at (e_min + e_max) / 2
/// aim at a length the surface has (an e_max of 1e300 made eq. 3.1 overflow to NaN positions).
Params as_run(const TriMesh& mesh, const Params& params);

/// Length of the diagonal of the box around the mesh's vertices (0 for an empty mesh).
double bounding_box_diagonal(const TriMesh& mesh);

/// The sizes of mesh the remesher works at: its bounding-box diagonal within these bounds. Past
/// them areas and products of lengths underflow or overflow (a tetrahedron 1e100 across was
/// "too large: 1e18 faces"; 1e-200 across had a diagonal of 0; a tetrahedron 1e-100 across ended
/// 81 % inside where at size 1 it ends 100 %; spot gives the same figures from 1e-28 to 1e28 across).
inline constexpr double kMinMeshSize = 1e-30, kMaxMeshSize = 1e30;

/// Throws MeshError, saying how large the mesh is, when its bounding-box diagonal lies outside
/// [kMinMeshSize, kMaxMeshSize] (or is not finite).
void check_mesh_size(const TriMesh& mesh);

/// Throws MeshError when an interior vertex has fewer than three faces around it. Such a vertex
/// has two, over the same three corners: a component that is one flat "pillow" of two triangles
/// back to back (a tetrahedron whose two corners coincide reads so once its zero-area faces are
/// repaired), which encloses nothing and which no flip, split or collapse can work on (OpenMesh
/// asserted in a flip; other such inputs came out non-manifold).
void check_vertex_stars(const TriMesh& mesh);

/// What check(params) cannot judge without the mesh: e_min must be shorter than the mesh's
/// bounding-box diagonal, since no edge between two points of its surface is longer (no edge could
/// end inside the interval). Every invalid field, named as check() names them; empty when valid.
std::vector<FieldError> check_against(const TriMesh& mesh, const Params& params);

/// Throws LimitError, with the estimate, when estimate_output_faces() exceeds
/// params.max_output_faces (0 = no limit); the message ends with `why` in brackets.
void check_output_estimate(const TriMesh& mesh, const Params& params, std::string_view why);

/// Every check equalize() makes before it starts: check(params), a mesh with faces,
/// check_mesh_size, check_vertex_stars, check_against, and the estimated output against
/// params.max_output_faces. Throws ParamsError, MeshError or LimitError.
void check_preconditions(const TriMesh& mesh, const Params& params);

}  // namespace remesh
