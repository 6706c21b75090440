// How far a result lies from its input (surface_distance.h): the exact point-to-mesh distance of
// the bounding-volume hierarchy against a scan of every triangle, and both one-sided distances on
// surfaces whose distance is known.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "remesh/geometry.h"
#include "remesh/preconditions.h"
#include "remesh/surface_distance.h"
#include "remesh/triangle_bvh.h"
#include "support/mesh_generators.h"
#include "test_helpers.h"

using namespace remesh;

namespace {

TriMesh scaled(TriMesh mesh, double factor) {
  for (auto v : mesh.vertices()) mesh.point(v) *= factor;
  return mesh;
}

}  // namespace

TEST_CASE("TriangleBvh's distance equals a scan of every triangle", "[remesh][distance]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-3.0, 3.0);
  for (const TriMesh& mesh : {test::make_icosphere(3, 1.5), test::make_torus(24, 12, 2.0, 0.5), test::make_box(4),
                              test::make_open_grid(9, 7, 0.3)}) {
    const TriangleBvh bvh(mesh);
    for (int i = 0; i < 300; ++i) {
      const Vec3 p(coord(rng), coord(rng), coord(rng));
      CHECK(bvh.distance(p) == Approx(test::brute_distance(mesh, p)).margin(1e-12));
    }
  }
  CHECK(std::isinf(TriangleBvh(TriMesh()).distance(Vec3(0, 0, 0))));
}

TEST_CASE("surface_distance: both sides, on surfaces whose distance is known", "[remesh][distance]") {
  const TriMesh sphere = test::make_icosphere(3, 1.0);
  SECTION("a surface is at distance 0 from itself") {
    const SurfaceDistance d = surface_distance(sphere, sphere, 2);
    // Exactly 0: a midpoint or centroid lies on its face within rounding, which is taken as 0.
    CHECK(d.result_to_input == 0);
    CHECK(d.input_to_result == 0);
  }
  SECTION("a copy 2 % larger: every vertex 0.02 out, the faces nearer") {
    const SurfaceDistance d = surface_distance(scaled(sphere, 1.02), sphere, 2);
    // The larger copy's vertices lie 0.02 outside the smaller's vertices, farther from its faces'
    // insides than that by at most the faces' sag; its midpoints nearer.
    CHECK(d.result_to_input >= 0.02 - 1e-12);
    CHECK(d.result_to_input <= 0.02 + 0.02);
    CHECK(d.input_to_result > 0.005);
    CHECK(d.input_to_result <= 0.02 + 1e-12);
    CHECK(d.hausdorff() == std::max(d.result_to_input, d.input_to_result));
    // Its scale: the input's bounding-box diagonal (a unit sphere's: 2 sqrt(3) at most).
    CHECK(d.diagonal == bounding_box_diagonal(sphere));
    CHECK(d.relative() == d.hausdorff() / d.diagonal);
  }
  SECTION("one-sided: a tip the result cuts off counts from the input only") {
    // The input: a unit square pyramid of height 2; the result: its base square alone, which lies
    // within the input (distance 0 one way), while the apex is 2 from it.
    TriMesh pyramid;
    const auto a = pyramid.add_vertex(Vec3(0, 0, 0)), b = pyramid.add_vertex(Vec3(1, 0, 0)),
               c = pyramid.add_vertex(Vec3(1, 1, 0)), e = pyramid.add_vertex(Vec3(0, 1, 0)),
               apex = pyramid.add_vertex(Vec3(0.5, 0.5, 2));
    pyramid.add_face(a, c, b);
    pyramid.add_face(a, e, c);
    for (auto [p, q] : {std::pair{a, b}, {b, c}, {c, e}, {e, a}}) pyramid.add_face(p, q, apex);
    TriMesh base;
    const auto a2 = base.add_vertex(Vec3(0, 0, 0)), b2 = base.add_vertex(Vec3(1, 0, 0)),
               c2 = base.add_vertex(Vec3(1, 1, 0)), e2 = base.add_vertex(Vec3(0, 1, 0));
    base.add_face(a2, c2, b2);
    base.add_face(a2, e2, c2);
    const SurfaceDistance d = surface_distance(base, pyramid, 2);
    CHECK(d.result_to_input == 0);
    CHECK(d.input_to_result == Approx(2.0));
  }
  SECTION("the same answer with 1 and 2 threads, over many blocks of samples") {
    // 12 800 + 38 400 + 25 600 samples one way, 2 592 the other: dozens of blocks of 1 024.
    const TriMesh fine = test::make_torus(160, 80, 2.0, 0.6), coarse = test::make_torus(36, 12, 2.0, 0.6);
    REQUIRE(distance_samples(fine).size() > 40 * 1024);
    for (const auto& [result, input] : {std::pair{&coarse, &fine}, {&fine, &coarse}}) {
      const SurfaceDistance one = surface_distance(*result, *input, 1), two = surface_distance(*result, *input, 2);
      CHECK(one.result_to_input == two.result_to_input);
      CHECK(one.input_to_result == two.input_to_result);
      CHECK(one.hausdorff() > 0);
    }
  }
  SECTION("deleted elements are passed over: the same as after garbage collection") {
    TriMesh torus = test::make_torus(24, 12, 2.0, 0.6);
    torus.request_face_status();
    torus.request_edge_status();
    torus.request_vertex_status();
    int k = 0;
    for (auto f : torus.faces())
      if (k++ % 3 == 0) torus.delete_face(f, true);
    TriMesh collected = torus;
    collected.garbage_collection();
    REQUIRE(collected.n_faces() < torus.n_faces());  // deleted, not yet collected
    CHECK(distance_samples(torus).size() == distance_samples(collected).size());
    const SurfaceDistance deleted = surface_distance(torus, sphere, 2), gone = surface_distance(collected, sphere, 2);
    CHECK(deleted.result_to_input == gone.result_to_input);
    CHECK(deleted.input_to_result == gone.input_to_result);
  }
}

TEST_CASE("distance_samples: every vertex, edge midpoint and face centroid", "[remesh][distance]") {
  const TriMesh torus = test::make_torus(10, 6, 2.0, 0.5);
  const std::vector<Vec3> points = distance_samples(torus);
  CHECK(points.size() == torus.n_vertices() + torus.n_edges() + torus.n_faces());
  // Each lies on the surface: at distance 0 from it.
  const TriangleBvh bvh(torus);
  double farthest = 0;
  for (const Vec3& p : points) farthest = std::max(farthest, bvh.distance(p));
  CHECK(farthest < 1e-12);
  CHECK(largest_distance({}, bvh, 2) == 0);
}
