// Why edges are left outside the interval: the thickness of the reference at them (thin_parts.h).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "remesh/equalize.h"
#include "remesh/geometry.h"
#include "remesh/reference_surface.h"
#include "remesh/crease_lines.h"
#include "remesh/thin_parts.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

/// opposite_side_distance by testing every triangle.
double brute_opposite(const TriMesh& m, const Vec3& p, const Vec3& normal, double limit) {
  double best = std::numeric_limits<double>::infinity();
  for (auto f : m.faces()) {
    const Vec3 n = geom::face_normal(m, f);
    if (!(n.norm() > 0) || ((n / n.norm()) | normal) >= -0.3) continue;
    Vec3 c[3];
    int k = 0;
    for (auto v : m.fv_range(f)) c[k++] = m.point(v);
    const double d = (geom::closest_point_on_triangle(p, c[0], c[1], c[2]) - p).norm();
    if (d < limit) best = std::min(best, d);
  }
  return best;
}

}  // namespace

TEST_CASE("opposite_side_distance is the nearest triangle facing the other way within the limit, opposite_side_within whether there is one", "[thin]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> limit_of(0.05, 4.0), jitter(-0.2, 0.2), coordinate(-1.0, 1.0);
  // An uneven reference: a sphere with a spike, whose five triangles are far longer than the rest
  // (the search looks at those one by one).
  TriMesh spiked = test::make_icosphere(3, 2.0);
  spiked.point(spiked.vertex_handle(0)) *= 15.0;
  for (const TriMesh& m : {test::make_torus(40, 10, 3.0, 0.4), test::make_torus(48, 24, 5.0, 2.0),
                           test::make_double_torus(1.0, 2), test::make_icosphere(3, 2.0), spiked}) {
    const ReferenceSurface reference(m);
    const std::vector<Vec3> normals = geom::vertex_normals(m, 1);
    std::vector<double> area_below{0.0};  // cumulated face areas, to pick points evenly on the surface
    for (auto f : m.faces()) area_below.push_back(area_below.back() + 0.5 * geom::face_normal(m, f).norm());
    std::size_t finite = 0;
    for (int i = 0; i < 600; ++i) {
      const auto v = m.vertex_handle(static_cast<unsigned>(rng() % m.n_vertices()));
      Vec3 p = m.point(v) + Vec3(jitter(rng), jitter(rng), jitter(rng));
      Vec3 n = normals[v.idx()].normalized();
      // Every other query from a point on the surface picked evenly by area (often inside a long
      // triangle, far from its corners), with a direction of its own, so that triangles of any
      // size and orientation count.
      if (i % 2 == 1) {
        const double at = std::uniform_real_distribution<double>(0.0, area_below.back())(rng);
        const auto f = m.face_handle(static_cast<unsigned>(
            std::upper_bound(area_below.begin(), area_below.end(), at) - area_below.begin() - 1));
        const double a = 0.5 * (1 + coordinate(rng)), b = 0.5 * (1 + coordinate(rng)) * (1 - a);
        Vec3 c[3];
        int k = 0;
        for (auto u : m.fv_range(f)) c[k++] = m.point(u);
        p = c[0] * a + c[1] * b + c[2] * (1 - a - b) + Vec3(jitter(rng), jitter(rng), jitter(rng));
        if (const Vec3 r(coordinate(rng), coordinate(rng), coordinate(rng)); r.norm() > 0.1) n = r.normalized();
      }
      const double limit = limit_of(rng);
      const double got = reference.opposite_side_distance(p, n, limit);
      const double want = brute_opposite(m, p, n, limit);
      // The search that stops at the first such triangle answers the same question.
      CHECK(reference.opposite_side_within(p, n, limit) == (want < limit));
      if (std::isinf(want)) {
        CHECK(std::isinf(got));
      } else {
        ++finite;
        CHECK(got == Approx(want).margin(1e-12));
      }
    }
    // Both answers occur on the tori: the tube's other side within some limits, not others.
    if (m.n_vertices() == 400) CHECK(finite > 0);
  }
}

TEST_CASE("thin_parts counts the edges outside where the reference is thinner than 2 e_min / sqrt(3)", "[thin]") {
  // The thin torus has every edge shorter than 1.2, the thick one most. The thin one's tube is 0.6
  // across (< 1.39); the thick one's is 6 across and its hole 10.
  const TriMesh thin = test::make_torus(40, 10, 3.0, 0.3), thick = test::make_torus(64, 32, 8.0, 3.0);
  const ThinParts a = thin_parts(thin, ReferenceSurface(thin), 1.2, 1.8, 2);
  CHECK(a.outside == thin.n_edges());
  CHECK(a.in_thin_parts == a.outside);
  CHECK(a.limit == Approx(2.4 / std::sqrt(3.0)));
  const ThinParts b = thin_parts(thick, ReferenceSurface(thick), 1.2, 1.8, 2);
  const IterationStats s = measure(thick, 1.2, 1.8, 1);
  CHECK(b.outside == s.small + s.big);
  CHECK(b.outside > thick.n_edges() / 2);
  CHECK(b.in_thin_parts == 0);
  // With an interval the thick torus's edges fit, nothing is outside.
  const ThinParts c = thin_parts(thick, ReferenceSurface(thick), 0.3, 1.5, 1);
  CHECK(c.outside == 0);
  CHECK(c.in_thin_parts == 0);
  CHECK(c.at_irregular == 0);
  // The tori's grids have valence 6 everywhere: no edge outside is at an irregular vertex.
  CHECK(a.at_irregular == 0);
  CHECK(b.at_irregular == 0);
}

TEST_CASE("thin_parts counts the edges outside at vertices of valence other than 6", "[thin]") {
  // An icosphere keeps the icosahedron's 12 vertices of valence 5, none of them neighbours after
  // subdivision: 60 edges touch one. With every edge outside all 60 count; with none, none.
  const TriMesh sphere = test::make_icosphere(3, 4.0);
  const ThinParts all = thin_parts(sphere, ReferenceSurface(sphere), 10.0, 20.0, 2);
  CHECK(all.outside == sphere.n_edges());
  CHECK(all.at_irregular == 60);
  const ThinParts none = thin_parts(sphere, ReferenceSurface(sphere), 0.01, 20.0, 2);
  CHECK(none.outside == 0);
  CHECK(none.at_irregular == 0);
}

TEST_CASE("thin_parts counts the edges outside at kept creases", "[thin]") {
  // A box of 10 x 10 x 10 cells: its cells' diagonals (sqrt 2) are outside [0.9, 1.1], its grid
  // edges (1) inside. With the crease guard, the diagonals with an end on one of the box's 12 edges
  // (two coordinates at 0 or 10) count; without it, none.
  const TriMesh box = test::make_box(10);
  const CreaseLines lines(box);
  REQUIRE(!lines.empty());
  const CreaseGuard guard(lines, 1e-9);
  const ReferenceSurface reference(box);
  const ThinParts kept = thin_parts(box, reference, 0.9, 1.1, 2, &guard);
  auto on_box_edge = [](const Vec3& p) {
    int at_side = 0;
    for (int k = 0; k < 3; ++k) at_side += p[k] == 0.0 || p[k] == 10.0;
    return at_side >= 2;
  };
  std::size_t outside = 0, at_edge = 0;
  for (auto e : box.edges()) {
    const double l = box.calc_edge_length(e);
    if (l >= 0.9 && l <= 1.1) continue;
    ++outside;
    const auto h = box.halfedge_handle(e, 0);
    at_edge += on_box_edge(box.point(box.from_vertex_handle(h))) || on_box_edge(box.point(box.to_vertex_handle(h)));
  }
  CHECK(kept.outside == outside);
  CHECK(at_edge > 0);
  CHECK(at_edge < outside);
  CHECK(kept.at_creases == at_edge);
  CHECK(thin_parts(box, reference, 0.9, 1.1, 2).at_creases == 0);
}

TEST_CASE("thin_parts counts the regular vertices where the reference is thinner than 2 e_max and elsewhere",
          "[thin]") {
  // Each interior vertex is classed by opposite_side_distance along its normal, checked here by
  // testing every triangle (brute_opposite). The torus's tube is 3 across and its hole 5: thinner
  // than 2 e_max = 3.6, not than 2.4. The flattened sphere (a lens 1.5 thick at its middle, 0 at
  // its rim) has both at 2 e_max = 1.
  struct Case {
    TriMesh mesh;
    double e_max;
  };
  std::vector<Case> cases;
  cases.push_back({test::make_torus(48, 16, 4.0, 1.5), 1.8});
  cases.push_back({test::make_torus(48, 16, 4.0, 1.5), 1.2});
  TriMesh lens = test::make_icosphere(3, 5.0);
  for (auto v : lens.vertices()) lens.point(v)[2] *= 0.15;
  cases.push_back({lens, 0.5});
  cases.push_back({test::make_icosphere(3, 10.0), 1.8});
  for (const Case& c : cases) {
    const TriMesh& m = c.mesh;
    const ThinParts t = thin_parts(m, ReferenceSurface(m), 0.5 * c.e_max, c.e_max, 2);
    CHECK(t.vertex_limit == 2 * c.e_max);
    CHECK_FALSE(t.sampled);
    std::size_t thinner = 0, regular_thinner = 0, thicker = 0, regular_thicker = 0;
    for (auto v : m.vertices()) {
      const bool thin = brute_opposite(m, m.point(v), geom::vertex_normal(m, v).normalized(), t.vertex_limit) <
                        t.vertex_limit;
      const bool regular = m.valence(v) == 6;
      (thin ? thinner : thicker) += 1;
      (thin ? regular_thinner : regular_thicker) += regular;
    }
    CHECK(t.vertices_thinner == thinner);
    CHECK(t.regular_thinner == regular_thinner);
    CHECK(t.vertices_thicker == thicker);
    CHECK(t.regular_thicker == regular_thicker);
  }
  // The classes as described: the torus wholly thin at e_max 1.8, wholly thick at 1.2, every
  // vertex regular; the sphere (20 across) wholly thick with its 12 vertices of valence 5; the
  // lens both.
  const ThinParts torus_thin = thin_parts(cases[0].mesh, ReferenceSurface(cases[0].mesh), 0.9, 1.8, 1);
  CHECK(torus_thin.vertices_thinner == cases[0].mesh.n_vertices());
  CHECK(torus_thin.regular_thinner == cases[0].mesh.n_vertices());
  const ThinParts torus_thick = thin_parts(cases[1].mesh, ReferenceSurface(cases[1].mesh), 0.6, 1.2, 1);
  CHECK(torus_thick.vertices_thicker == cases[1].mesh.n_vertices());
  const ThinParts sphere = thin_parts(cases[3].mesh, ReferenceSurface(cases[3].mesh), 0.9, 1.8, 1);
  CHECK(sphere.vertices_thinner == 0);
  CHECK(sphere.regular_thicker == cases[3].mesh.n_vertices() - 12);
  const ThinParts lens_parts = thin_parts(cases[2].mesh, ReferenceSurface(cases[2].mesh), 0.25, 0.5, 1);
  CHECK(lens_parts.vertices_thinner > 0);
  CHECK(lens_parts.vertices_thicker > 0);
}

TEST_CASE("thin_parts measures every k-th vertex of a large mesh", "[thin]") {
  // 24 000 vertices: about every 2nd is measured (kThicknessSample = 20 000, picked by a hash of
  // the index), all in the tube (0.6 across) and all regular; the same ones every time.
  const TriMesh m = test::make_torus(400, 60, 20.0, 0.3);
  REQUIRE(m.n_vertices() == 24000);
  const ThinParts t = thin_parts(m, ReferenceSurface(m), 1.2, 1.8, 2);
  CHECK(t.sampled);
  CHECK(t.vertices_thinner > 11000);
  CHECK(t.vertices_thinner < 13000);
  CHECK(t.regular_thinner == t.vertices_thinner);
  CHECK(t.vertices_thicker == 0);
  CHECK(thin_parts(m, ReferenceSurface(m), 1.2, 1.8, 1).vertices_thinner == t.vertices_thinner);
}

TEST_CASE("equalize reports the returned mesh's edges outside and those in thin parts", "[thin]") {
  // A torus whose tube (0.5 across) no ring of edges of at least 1.2 can follow, and a sphere.
  for (const bool thin : {true, false}) {
    TriMesh m = thin ? test::make_torus(48, 8, 4.0, 0.25) : test::make_icosphere(3, 4.0);
    Params p;
    p.e_min = 1.2;
    p.e_max = 1.8;
    p.iterations = 20;
    const Result r = equalize(m, p);
    const IterationStats s = measure(m, p.e_min, p.e_max, 1);
    CHECK(r.thin.outside == s.small + s.big);
    if (thin) {
      CHECK(r.thin.outside > 0);
      CHECK(r.thin.in_thin_parts == r.thin.outside);
    } else {
      CHECK(r.thin.in_thin_parts == 0);
    }
  }
}
