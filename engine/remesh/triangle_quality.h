#pragma once
/// \file triangle_quality.h
/// Not in the thesis: the shape of the result's triangles, which finite-element and graphics users
/// judge a mesh by before its edge lengths. An interval of edge lengths bounds the shapes (with
/// edges in [e_min, e_max] no angle is below 2 asin(e_min / (2 e_max)), 38.9 degrees at [1.2, 1.8])
/// only where every edge is inside; the edges left outside and the thin parts make the worst ones.

#include <cstddef>

#include "core/mesh.h"

namespace remesh {

struct TriangleQuality {
  std::size_t faces = 0;
  double min_angle = 0;  ///< degrees: the smallest interior angle of any face (0 without faces)
  double max_angle = 0;  ///< degrees: the largest
  /// Faces with an angle under 30 degrees, and with one over 90 (obtuse), as fractions of the faces.
  double below_30 = 0, above_90 = 0;
  /// The radius ratio 2 r / R (inscribed over circumscribed radius): 1 for an equilateral triangle,
  /// 0 for a degenerate one. The smallest over the faces, and the mean.
  double min_radius_ratio = 0, mean_radius_ratio = 0;
};

/// The shapes of the live faces of `mesh`. Deterministic (one serial pass in face order).
TriangleQuality triangle_quality(const TriMesh& mesh);

}  // namespace remesh
