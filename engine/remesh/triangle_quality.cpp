#include "remesh/triangle_quality.h"

#include <algorithm>
#include <cmath>

namespace remesh {

namespace {

/// The angle at the corner between edge vectors u and v, in degrees (atan2 of the cross and dot
/// products: accurate near 0 and 180 degrees, where acos of the cosine is not).
double angle_between(const Vec3& u, const Vec3& v) {
  return std::atan2(OpenMesh::cross(u, v).norm(), u | v) * (180.0 / M_PI);
}

}  // namespace

TriangleQuality triangle_quality(const TriMesh& mesh) {
  TriangleQuality q;
  double smallest = 180, largest = 0, ratio_sum = 0, min_ratio = 1;
  std::size_t below = 0, above = 0;
  for (auto f : mesh.faces()) {
    const auto h = mesh.halfedge_handle(f);
    const Vec3 a = mesh.point(mesh.from_vertex_handle(h)), b = mesh.point(mesh.to_vertex_handle(h)),
               c = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
    const double at_a = angle_between(b - a, c - a), at_b = angle_between(c - b, a - b);
    const double angles[3] = {at_a, at_b, 180 - at_a - at_b};
    const double lo = std::min({angles[0], angles[1], angles[2]}), hi = std::max({angles[0], angles[1], angles[2]});
    smallest = std::min(smallest, lo);
    largest = std::max(largest, hi);
    below += lo < 30;
    above += hi > 90;
    // 2 r / R from the sides: r = area / s and R = abc / (4 area) give (b+c-a)(c+a-b)(a+b-c) / (abc).
    const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
    const double product = la * lb * lc;
    const double ratio = product > 0 ? std::max(0.0, (lb + lc - la) * (lc + la - lb) * (la + lb - lc) / product) : 0.0;
    ratio_sum += ratio;
    min_ratio = std::min(min_ratio, ratio);
    ++q.faces;
  }
  if (q.faces == 0) return q;
  const double n = static_cast<double>(q.faces);
  q.min_angle = smallest;
  q.max_angle = largest;
  q.below_30 = static_cast<double>(below) / n;
  q.above_90 = static_cast<double>(above) / n;
  q.min_radius_ratio = min_ratio;
  q.mean_radius_ratio = ratio_sum / n;
  return q;
}

}  // namespace remesh
