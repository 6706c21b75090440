// The shapes of a mesh's triangles (triangle_quality.h), against known triangles and a recount.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "remesh/triangle_quality.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

TriMesh one_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  TriMesh m;
  m.add_face(m.add_vertex(a), m.add_vertex(b), m.add_vertex(c));
  return m;
}

/// Every angle of every face by the law of cosines (acos), in degrees: another formula than the
/// one measured.
std::vector<double> all_angles(const TriMesh& m) {
  std::vector<double> angles;
  for (auto f : m.faces()) {
    std::vector<Vec3> p;
    for (auto v : m.fv_range(f)) p.push_back(m.point(v));
    for (int k = 0; k < 3; ++k) {
      const double a = (p[(k + 1) % 3] - p[(k + 2) % 3]).norm();  // opposite corner k
      const double b = (p[k] - p[(k + 1) % 3]).norm(), c = (p[k] - p[(k + 2) % 3]).norm();
      angles.push_back(std::acos(std::clamp((b * b + c * c - a * a) / (2 * b * c), -1.0, 1.0)) * 180 / M_PI);
    }
  }
  return angles;
}

}  // namespace

TEST_CASE("triangle_quality of known triangles", "[triangles]") {
  const TriangleQuality equilateral = triangle_quality(one_triangle({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(0.75), 0}));
  CHECK(equilateral.faces == 1);
  CHECK(equilateral.min_angle == Approx(60));
  CHECK(equilateral.max_angle == Approx(60));
  CHECK(equilateral.min_radius_ratio == Approx(1));
  CHECK(equilateral.below_30 == 0);
  CHECK(equilateral.above_90 == 0);
  // A right isosceles triangle: 45, 45, 90 (not obtuse); 2 r / R = 2 sqrt(2) - 2.
  const TriangleQuality right = triangle_quality(one_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  CHECK(right.min_angle == Approx(45));
  CHECK(right.max_angle == Approx(90));
  CHECK(right.mean_radius_ratio == Approx(2 * std::sqrt(2.0) - 2));
  CHECK(right.above_90 == 0);
  // A needle and an obtuse sliver, in space (not in a coordinate plane).
  const TriangleQuality needle = triangle_quality(one_triangle({0, 0, 0}, {1, 1, 1}, {1, 1, 1.1}));
  CHECK(needle.min_angle < 5);
  CHECK(needle.below_30 == 1);
  CHECK(needle.min_radius_ratio < 0.2);
  const TriangleQuality sliver = triangle_quality(one_triangle({0, 0, 0}, {2, 0, 0}, {1, 0.05, 0}));
  CHECK(sliver.max_angle == Approx(180 - 2 * std::atan(0.05) * 180 / M_PI));
  CHECK(sliver.above_90 == 1);
  // Degenerate: every corner at one point, or three on a line.
  CHECK(triangle_quality(one_triangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0})).min_radius_ratio == 0);
  CHECK(triangle_quality(TriMesh()).faces == 0);
}

TEST_CASE("triangle_quality of meshes matches a recount by the law of cosines", "[triangles]") {
  std::vector<TriMesh> meshes;
  meshes.push_back(test::make_icosphere(2));
  meshes.push_back(test::make_torus(24, 9, 3.0, 1.0));
  meshes.push_back(test::make_sliver_cylinder(16, 1.0, 3.0));
  meshes.push_back(test::make_fan(40, 1.0));
  for (const TriMesh& m : meshes) {
    const TriangleQuality q = triangle_quality(m);
    const std::vector<double> angles = all_angles(m);
    CHECK(q.faces == m.n_faces());
    CHECK(q.min_angle == Approx(*std::min_element(angles.begin(), angles.end())).margin(1e-6));
    CHECK(q.max_angle == Approx(*std::max_element(angles.begin(), angles.end())).margin(1e-6));
    std::size_t below = 0, above = 0;
    for (std::size_t f = 0; f < m.n_faces(); ++f) {
      below += std::min({angles[3 * f], angles[3 * f + 1], angles[3 * f + 2]}) < 30;
      above += std::max({angles[3 * f], angles[3 * f + 1], angles[3 * f + 2]}) > 90 + 1e-9;
    }
    CHECK(q.below_30 == Approx(double(below) / double(m.n_faces())));
    CHECK(q.above_90 == Approx(double(above) / double(m.n_faces())));
    CHECK(q.min_radius_ratio >= 0);
    CHECK(q.min_radius_ratio <= q.mean_radius_ratio);
    CHECK(q.mean_radius_ratio <= 1 + 1e-12);
  }
}
