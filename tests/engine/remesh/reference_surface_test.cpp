// The reference surface of the projection (Alg. 6) where the input is uneven or defective.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "remesh/reference_surface.h"
#include "test_helpers.h"

using namespace remesh;

using test::brute_distance;

TEST_CASE("projection finds a large triangle none of whose corners is among the nearest vertices",
          "[reference]") {
  // In the plane z = 0: one big triangle (0,0) (10,0) (0,10); beyond its hypotenuse, a fan from
  // (0,10) to the rim x = 10 of a dense patch [10,13] x [0,10] (spacing 0.5). Above (4.9, 4.9) the
  // big triangle lies under p, but the 30 nearest vertices are all on the dense patch, 5 units away,
  // and the fan triangles they touch run far from p (nefertiti's base).
  TriMesh m;
  constexpr int kRows = 21, kCols = 7;  // dense patch: y = 0.5 j, x = 10 + 0.5 i
  std::vector<OpenMesh::VertexHandle> grid(kRows * kCols);
  for (int j = 0; j < kRows; ++j)
    for (int i = 0; i < kCols; ++i) grid[j * kCols + i] = m.add_vertex(Vec3(10 + 0.5 * i, 0.5 * j, 0));
  for (int j = 0; j + 1 < kRows; ++j)
    for (int i = 0; i + 1 < kCols; ++i) {
      auto a = grid[j * kCols + i], b = grid[j * kCols + i + 1], c = grid[(j + 1) * kCols + i + 1],
           d = grid[(j + 1) * kCols + i];
      m.add_face(a, b, c);
      m.add_face(a, c, d);
    }
  const auto origin = m.add_vertex(Vec3(0, 0, 0)), top = m.add_vertex(Vec3(0, 10, 0));
  m.add_face(origin, grid[0], top);
  for (int j = 0; j + 1 < kRows; ++j) m.add_face(top, grid[j * kCols], grid[(j + 1) * kCols]);
  REQUIRE(m.n_faces() == 2 * 20 * 6 + 1 + 20);

  const ReferenceSurface reference(m);
  for (double x : {3.0, 4.0, 4.9}) {
    for (double h : {-0.5, 0.0, 0.5}) {
      const Vec3 p(x, x, h);
      const Vec3 c = reference.closest_point(p, Vec3(0, 0, 1));
      CHECK(std::abs((c - p).norm() - std::abs(h)) < 1e-9);
      CHECK((c - p).norm() <= brute_distance(m, p) + 1e-12);
    }
  }
}

TEST_CASE("projection ignores a triangle folded back onto a larger neighbour", "[reference]") {
  // A T-junction closed by a sliver whose middle corner M lies on the wrong side of the long edge
  // AB (nefertiti has 96 such folds): the sliver ABM faces -z while all around face +z.
  TriMesh m;
  const auto a = m.add_vertex(Vec3(0, 0, 0)), b = m.add_vertex(Vec3(4, 0, 0)), c = m.add_vertex(Vec3(2, -3, 0)),
             d = m.add_vertex(Vec3(2, 3, 0)), mid = m.add_vertex(Vec3(2, -0.3, 0.05));
  m.add_face(a, c, b);
  const auto sliver = m.add_face(a, b, mid);
  m.add_face(mid, b, d);
  m.add_face(a, mid, d);
  REQUIRE(m.n_faces() == 4);
  m.request_face_normals();
  m.update_face_normals();
  REQUIRE(m.normal(sliver)[2] < -0.95);

  const ReferenceSurface reference(m);
  // Below the sliver, with a vertex normal that agrees with the sliver's (a vertex that followed the
  // fold): the sliver is nearly as close as the base, but the point goes to the base.
  for (double y : {-0.25, -0.15, -0.05}) {
    const Vec3 p(2, y, -0.1);
    const Vec3 c = reference.closest_point(p, Vec3(0, 0, -1));
    CHECK(std::abs(c[2]) < 1e-12);
    CHECK(std::abs((c - p).norm() - 0.1) < 1e-12);
  }
  // Elsewhere the fold changes nothing: points above the +z triangles land straight below.
  for (const Vec3& p : {Vec3(2, -2, 0.3), Vec3(2, 2, 0.3), Vec3(1, 0.5, -0.2)}) {
    const Vec3 c = reference.closest_point(p, Vec3(0, 0, 1));
    CHECK(std::abs((c - p).norm() - brute_distance(m, p)) < 1e-12);
  }
}

TEST_CASE("projection's pruning is exact on slivers: with every vertex a candidate it finds the closest point",
          "[reference]") {
  // A closed prism of 12 sides, radius 1 and height 6, capped by fans: its side triangles are
  // slivers 6 long and 0.5 wide, whose bounding spheres (radius 3) prune nothing, so the pruning by
  // the sphere around each vertex's triangles and by plane distance decides (cheese.off's holes).
  // With 26 vertices, fewer than the 30 nearest of Alg. 6, every triangle is a candidate and the
  // answer must be the exact one, from inside, outside, beside the caps and far away.
  TriMesh m;
  constexpr int kSides = 12;
  std::vector<OpenMesh::VertexHandle> bottom, top;
  for (int i = 0; i < kSides; ++i) {
    const double a = 2 * M_PI * i / kSides;
    bottom.push_back(m.add_vertex(Vec3(std::cos(a), std::sin(a), 0)));
    top.push_back(m.add_vertex(Vec3(std::cos(a), std::sin(a), 6)));
  }
  const auto low = m.add_vertex(Vec3(0, 0, 0)), high = m.add_vertex(Vec3(0, 0, 6));
  for (int i = 0; i < kSides; ++i) {
    const int j = (i + 1) % kSides;
    m.add_face(bottom[i], bottom[j], top[j]);
    m.add_face(bottom[i], top[j], top[i]);
    m.add_face(low, bottom[j], bottom[i]);
    m.add_face(high, top[i], top[j]);
  }
  REQUIRE(m.n_vertices() == 26);
  const ReferenceSurface reference(m);
  int checked = 0;
  for (double r : {0.0, 0.3, 0.9, 1.05, 1.5, 4.0})
    for (double z : {-2.0, -0.1, 0.2, 3.0, 5.9, 6.5, 9.0})
      for (int k = 0; k < 7; ++k) {
        const double a = 0.37 + 0.9 * k;  // angles between the vertices
        const Vec3 p(r * std::cos(a), r * std::sin(a), z);
        const Vec3 c = reference.closest_point(p);
        CHECK(std::abs((c - p).norm() - brute_distance(m, p)) < 1e-12);
        ++checked;
      }
  CHECK(checked == 6 * 7 * 7);
}

TEST_CASE("projection's test of a whole vertex keeps a large triangle whose corners are far from the query",
          "[reference]") {
  // A triangle 30 units wide in the plane z = 0 and, as a second part, a small tetrahedron 0.5 above
  // it. Near the triangle's corner (0, 0) the tetrahedron's vertices come first among the nearest
  // and set the first bound (under 0.5), while the triangle's corners lie 4-27 units from p, and
  // the centre of the sphere around each corner's triangles (their bounding box's, (15, 15, 0))
  // 14-17: the triangle is found only if that sphere holds all of it. With 7 vertices, fewer than
  // the 30 nearest of Alg. 6, every triangle is a candidate: the answer is the exact one.
  TriMesh m;
  const auto a = m.add_vertex(Vec3(0, 0, 0)), b = m.add_vertex(Vec3(30, 0, 0)), c = m.add_vertex(Vec3(0, 30, 0));
  m.add_face(a, b, c);
  const Vec3 apex(4, 4, 0.5);
  const auto t0 = m.add_vertex(apex), t1 = m.add_vertex(apex + Vec3(0.3, 0, 0.2)),
             t2 = m.add_vertex(apex + Vec3(0, 0.3, 0.2)), t3 = m.add_vertex(apex + Vec3(0, 0, 0.4));
  m.add_face(t0, t2, t1);
  m.add_face(t0, t1, t3);
  m.add_face(t0, t3, t2);
  m.add_face(t1, t2, t3);
  const ReferenceSurface reference(m);
  int checked = 0;
  for (double x : {3.0, 3.6, 4.0, 4.4, 5.0})
    for (double y : {3.0, 3.6, 4.0, 4.4, 5.0})
      for (double h : {0.02, 0.1, 0.2}) {
        const Vec3 p(x, y, h);
        for (const Vec3& hint : {Vec3(0, 0, 0), Vec3(0, 0, 1)}) {
          const Vec3 q = reference.closest_point(p, hint);
          CHECK(std::abs((q - p).norm() - h) < 1e-12);
          CHECK(std::abs(q[2]) < 1e-12);
          ++checked;
        }
      }
  CHECK(checked == 5 * 5 * 3 * 2);
}
