#include "remesh/preconditions.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "remesh/geometry.h"
#include "remesh/statistics.h"

namespace remesh {

double bounding_box_diagonal(const TriMesh& mesh) {
  Box box;
  for (auto v : mesh.vertices()) box.add(mesh.point(v));
  if (!(box.lo[0] <= box.hi[0])) return 0.0;  // no vertex
  // Scaled by the largest extent first, so that a mesh 1e-200 across is not 0 across (the squares
  // would underflow) nor one 1e200 across infinite.
  const Vec3 d = box.hi - box.lo;
  const double largest = std::max({std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
  return largest > 0 && std::isfinite(largest) ? largest * (d / largest).norm() : largest;
}

void check_mesh_size(const TriMesh& mesh) {
  const double diagonal = bounding_box_diagonal(mesh);
  if (diagonal >= kMinMeshSize && diagonal <= kMaxMeshSize) return;  // false for NaN too
  char text[200];
  std::snprintf(text, sizeof text,
                "the mesh is %.3g across (its bounding-box diagonal): sizes outside %.0e .. %.0e are not supported "
                "(areas would underflow or overflow); scale it, and the interval with it",
                diagonal, kMinMeshSize, kMaxMeshSize);
  throw MeshError(text);
}

void check_vertex_stars(const TriMesh& mesh) {
  for (auto v : mesh.vertices()) {
    if (mesh.status(v).deleted() || mesh.is_isolated(v) || mesh.is_boundary(v) || mesh.valence(v) >= 3) continue;
    const Vec3& p = mesh.point(v);
    char text[320];
    std::snprintf(text, sizeof text,
                  "the vertex at (%.9g, %.9g, %.9g) has only %u faces around it: two triangles back to back over "
                  "the same three corners (a flat part that encloses nothing), which cannot be remeshed; remove them",
                  p[0], p[1], p[2], mesh.valence(v));
    throw MeshError(text);
  }
}

std::vector<FieldError> check_against(const TriMesh& mesh, const Params& params) {
  std::vector<FieldError> errors;
  const double diagonal = bounding_box_diagonal(mesh);
  if (std::isfinite(params.e_min) && std::isfinite(diagonal) && params.e_min >= diagonal) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "must be shorter than the mesh's bounding-box diagonal, %.6g: no edge on its surface is longer",
                  diagonal);
    errors.push_back({"emin", text});
  }
  return errors;
}

Params as_run(const TriMesh& mesh, const Params& params) {
  Params run = params;
  run.e_max = std::min(params.e_max, bounding_box_diagonal(mesh));
  return run;
}

std::size_t estimate_output_faces(const TriMesh& mesh, const Params& params) {
  // With e_max as the run takes it (as_run): an e_max of 1e300 made the estimate 0, under any limit.
  const Params run = as_run(mesh, params);
  const double m = 0.5 * (run.e_min + run.e_max);
  if (!(m > 0) || !std::isfinite(m)) return 0;
  const double faces = surface_area(mesh) / (std::sqrt(3.0) / 4.0 * m * m);
  if (!std::isfinite(faces) || faces > static_cast<double>(kMaxFaceEstimate)) return kMaxFaceEstimate;
  return static_cast<std::size_t>(std::ceil(faces));
}


void check_output_estimate(const TriMesh& mesh, const Params& params, std::string_view why) {
  const std::size_t estimate = estimate_output_faces(mesh, params);
  // The estimate stops at kMaxFaceEstimate: said as "over" that (it printed 1000000000000000000 as
  // if counted).
  if (params.max_output_faces > 0 && estimate > params.max_output_faces)
    throw LimitError("estimated output of " + std::string(estimate >= kMaxFaceEstimate ? "over " : "") +
                     std::to_string(estimate) + " faces exceeds the limit of " +
                     std::to_string(params.max_output_faces) + " faces (" + std::string(why) + ")");
}

void check_preconditions(const TriMesh& mesh, const Params& params) {
  if (auto errors = check(params); !errors.empty()) throw ParamsError(std::move(errors));
  if (mesh.n_faces() == 0) throw MeshError("the mesh has no faces");
  check_mesh_size(mesh);
  check_vertex_stars(mesh);
  if (auto errors = check_against(mesh, params); !errors.empty()) throw ParamsError(std::move(errors));
  check_output_estimate(mesh, params, "e_max too small for this mesh");
}

}  // namespace remesh
