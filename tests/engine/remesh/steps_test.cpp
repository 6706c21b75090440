// Each step of Algorithm 1 alone.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stop_token>
#include <vector>

#include "remesh/crease_lines.h"
#include "remesh/fold_guard.h"
#include "remesh/geometry.h"
#include "remesh/interval_cleanup.h"
#include "remesh/low_pass_filter.h"
#include "remesh/mesh_snapshot.h"
#include "remesh/projection.h"
#include "remesh/reference_surface.h"
#include "remesh/reposition.h"
#include "remesh/stellar_operations.h"
#include "remesh/valence_flips.h"
#include "support/mesh_generators.h"
#include "test_helpers.h"

using namespace remesh;
using OpenMesh::EdgeHandle;

namespace {

TriMesh tetrahedron() {
  TriMesh m;
  auto a = m.add_vertex(Vec3(0, 0, 0)), b = m.add_vertex(Vec3(1, 0, 0)), c = m.add_vertex(Vec3(0, 1, 0)),
       d = m.add_vertex(Vec3(0, 0, 1));
  m.add_face(a, c, b);
  m.add_face(a, b, d);
  m.add_face(b, c, d);
  m.add_face(a, d, c);
  return m;
}

/// Independent area-weighted vertex normal.
Vec3 normal_of(const TriMesh& m, OpenMesh::VertexHandle v) {
  Vec3 n(0, 0, 0);
  for (auto f : m.vf_range(v)) {
    Vec3 p[3];
    int k = 0;
    for (auto w : m.fv_range(f)) p[k++] = m.point(w);
    n += (p[1] - p[0]) % (p[2] - p[0]);
  }
  return n.normalize();
}

/// Smallest angle of the two faces of edge e, by the law of cosines (independent of geometry.cpp).
double two_face_min_angle(const TriMesh& m, EdgeHandle e) {
  double best = M_PI;
  for (int s = 0; s < 2; ++s) {
    auto f = m.face_handle(m.halfedge_handle(e, s));
    Vec3 p[3];
    int k = 0;
    for (auto w : m.fv_range(f)) p[k++] = m.point(w);
    for (int i = 0; i < 3; ++i) {
      const Vec3 u = p[(i + 1) % 3] - p[i], w = p[(i + 2) % 3] - p[i];
      best = std::min(best, std::acos(std::clamp((u | w) / (u.norm() * w.norm()), -1.0, 1.0)));
    }
  }
  return best;
}

}  // namespace

TEST_CASE("splits and collapses keep the mesh valid and its topology", "[steps]") {
  TriMesh mesh = test::make_icosphere(3, 10.0);
  const long euler = test::euler_characteristic(mesh);
  std::size_t splits = 0, collapses = 0;
  for (unsigned i = 0; i < mesh.n_edges(); i += 7) {
    if (split_edge(mesh, mesh.edge_handle(i), 1.0).is_valid()) ++splits;
  }
  for (unsigned i = 0; i < mesh.n_edges(); i += 5) {
    const EdgeHandle e = mesh.edge_handle(i);
    if (mesh.status(e).deleted()) continue;
    CollapsePlan plan;
    if (plan_collapse(mesh, e, 1.0, 1e9, plan)) {
      apply_collapse(mesh, plan);
      ++collapses;
    }
  }
  mesh.garbage_collection();
  CHECK(splits > 50);
  CHECK(collapses > 50);
  CHECK(test::check_mesh_valid(mesh) == "");
  CHECK(test::euler_characteristic(mesh) == euler);
  CHECK(test::count_components(mesh) == 1);
}

TEST_CASE("collect_garbage compacts a mesh exactly as OpenMesh's garbage_collection", "[steps]") {
  // core/mesh.h: the same compaction compiled without the library's assertions.
  for (TriMesh mesh :
       {test::make_icosphere(3, 10.0), test::make_torus(24, 12, 10.0, 4.0), test::make_open_grid(9, 7, 1.0)}) {
    for (unsigned i = 0; i < mesh.n_edges(); i += 6) split_edge(mesh, mesh.edge_handle(i), 1.0);
    std::size_t collapses = 0;
    for (unsigned i = 0; i < mesh.n_edges(); i += 4) {
      const EdgeHandle e = mesh.edge_handle(i);
      CollapsePlan plan;
      if (mesh.status(e).deleted() || !plan_collapse(mesh, e, 1.0, 1e9, plan)) continue;
      apply_collapse(mesh, plan);
      ++collapses;
    }
    REQUIRE(collapses > 5);
    TriMesh theirs = mesh;
    theirs.garbage_collection();
    collect_garbage(mesh);
    REQUIRE(mesh.n_vertices() == theirs.n_vertices());
    REQUIRE(mesh.n_edges() == theirs.n_edges());
    REQUIRE(mesh.n_faces() == theirs.n_faces());
    for (unsigned v = 0; v < mesh.n_vertices(); ++v) {
      CHECK(mesh.point(mesh.vertex_handle(v)) == theirs.point(theirs.vertex_handle(v)));
      CHECK(vertex_valence(mesh, mesh.vertex_handle(v)) == theirs.valence(theirs.vertex_handle(v)));
    }
    for (unsigned h = 0; h < mesh.n_halfedges(); ++h) {
      const auto a = mesh.halfedge_handle(h), b = theirs.halfedge_handle(h);
      CHECK(mesh.to_vertex_handle(a) == theirs.to_vertex_handle(b));
      CHECK(mesh.next_halfedge_handle(a) == theirs.next_halfedge_handle(b));
      CHECK(mesh.face_handle(a) == theirs.face_handle(b));
    }
    CHECK(test::check_mesh_valid(mesh) == "");
  }
}

TEST_CASE("boundary collapses stay on the boundary and never pinch", "[steps]") {
  TriMesh mesh = test::make_open_grid(8, 8, 1.0);
  std::size_t boundary_collapses = 0;
  for (auto e : mesh.edges()) {
    if (mesh.status(e).deleted()) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    const auto v0 = mesh.from_vertex_handle(h), v1 = mesh.to_vertex_handle(h);
    CollapsePlan plan;
    if (!mesh.is_boundary(e) && mesh.is_boundary(v0) && mesh.is_boundary(v1)) {
      CHECK_FALSE(plan_collapse(mesh, e, 1.0, 1e9, plan));
    } else if (mesh.is_boundary(e) && plan_collapse(mesh, e, 1.0, 1e9, plan)) {
      // The kept vertex lies on the collapsed boundary edge.
      const Vec3 a = mesh.point(v0), b = mesh.point(v1);
      CHECK(((plan.position - a) % (b - a)).norm() < 1e-9);
      apply_collapse(mesh, plan);
      ++boundary_collapses;
    }
  }
  mesh.garbage_collection();
  CHECK(boundary_collapses > 5);
  CHECK(test::check_mesh_valid(mesh) == "");
  CHECK(test::count_boundary_loops(mesh) == 1);
  CHECK(test::euler_characteristic(mesh) == 1);
  for (auto v : mesh.vertices())
    if (mesh.is_boundary(v)) CHECK(std::abs(mesh.point(v)[2]) < 1e-12);
}

TEST_CASE("a split of a sliver's long side is kept when it loses no more than a hair of its angle", "[steps]") {
  // A disk of 600 sectors (angles of 0.6 degrees at the centre): splitting a spoke at its middle
  // keeps 0.6 degrees at the centre and leaves 0.6 * (1 - 1e-4) at the rim. Refused while a split
  // could make nothing smaller than the sliver it replaces: such a fan stalled unchanged.
  const double theta = 2 * M_PI / 600;
  TriMesh fan = test::make_fan(600, 1.0);
  std::vector<EdgeHandle> spokes;
  for (auto e : fan.edges())
    if (!fan.is_boundary(e) && spokes.size() < 40) spokes.push_back(e);
  std::size_t splits = 0;
  for (std::size_t k = 0; k < spokes.size(); k += 2)
    if (split_edge(fan, spokes[k], 0.5).is_valid()) ++splits;
  CHECK(splits == spokes.size() / 2);
  for (auto e : fan.edges())
    if (!fan.is_boundary(e)) CHECK(two_face_min_angle(fan, e) >= theta * (1 - 1e-3));
  CHECK(test::check_mesh_valid(fan) == "");
  CHECK(test::euler_characteristic(fan) == 1);
}

TEST_CASE("a collapse beside a tip keeps the tip where it is", "[steps]") {
  // An icosphere with one vertex pulled out to 1.6 times the radius: a spike whose apex has an angle
  // deficit of about 4 radians (is_tip), its neighbours not tips. Each edge from the
  // apex collapses onto the apex, whichever way the edge points: the neighbour goes, the apex
  // stays put. Without keep_tips (the interval cleanup's collapses) eq. 3.1 puts the merged vertex
  // on the edge, below the apex.
  TriMesh mesh = test::make_icosphere(2, 3.0);
  const auto apex = mesh.vertex_handle(0);
  mesh.point(apex) *= 1.6;
  const Vec3 tip = mesh.point(apex);
  REQUIRE(geom::angle_deficit(mesh, apex) > 3.0);
  REQUIRE(is_tip(mesh, apex));
  int planned = 0, plain_planned = 0, from_apex = 0, to_apex = 0;  // from / to: the edge's stored direction
  for (auto h : mesh.voh_range(apex)) {
    const auto other = mesh.to_vertex_handle(h);
    CHECK_FALSE(is_tip(mesh, other));
    const EdgeHandle e = mesh.edge_handle(h);
    CollapsePlan plan;
    if (!plan_collapse(mesh, e, 1.0, 1e9, plan)) continue;
    ++planned;
    ++(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)) == apex ? from_apex : to_apex);
    CHECK(plan.position == tip);
    CHECK(mesh.from_vertex_handle(plan.halfedge) == other);
    CHECK(mesh.to_vertex_handle(plan.halfedge) == apex);
    CollapsePlan plain;
    if (plan_collapse(mesh, e, 1.0, 1e9, plain, /*keep_tips=*/false)) {
      ++plain_planned;
      CHECK((plain.position - tip).norm() > 0.5);
    }
  }
  CHECK(planned >= 4);
  CHECK(plain_planned > 0);
  CHECK(from_apex > 0);
  CHECK(to_apex > 0);
  // Applied, the collapses leave the apex where it was.
  int applied = 0;
  for (int round = 0; round < 3; ++round) {
    for (auto h : mesh.voh_range(apex)) {
      CollapsePlan plan;
      if (!plan_collapse(mesh, mesh.edge_handle(h), 1.0, 1e9, plan)) continue;
      CHECK(apply_collapse(mesh, plan) == apex);
      ++applied;
      break;
    }
  }
  CHECK(applied >= 2);
  mesh.garbage_collection();
  CHECK(test::check_mesh_valid(mesh) == "");
  bool found = false;
  for (auto v : mesh.vertices()) found = found || mesh.point(v) == tip;
  CHECK(found);
}

TEST_CASE("a collapse does not fold the faces that become neighbours", "[steps]") {
  // Each face a collapse removes leaves the two faces across its other edges adjacent. On a torus
  // whose tube is too thin for the target (and crumpled, so that faces bend sharply), every
  // collapse plan_collapse allows is carried out on a copy: each such new pair of neighbours must
  // meet at a normal cosine of at least kMinAdjacentCos, or no sharper than before. The normals are
  // taken from the collapsed mesh itself.
  TriMesh base = test::make_torus(40, 8, 5.0, 0.5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-0.15, 0.15);
  for (auto v : base.vertices()) base.point(v) += Vec3(d(rng), d(rng), d(rng));
  auto unit_normal = [](const TriMesh& m, OpenMesh::FaceHandle f) {
    Vec3 p[3];
    int k = 0;
    for (auto w : m.fv_range(f)) p[k++] = m.point(w);
    return ((p[1] - p[0]) % (p[2] - p[0])).normalize();
  };
  std::size_t collapses = 0;
  for (auto e : base.edges()) {
    CollapsePlan plan;
    if (!plan_collapse(base, e, 1.5, 1e9, plan)) continue;
    // The faces across the other two edges of each removed face.
    std::vector<std::pair<OpenMesh::FaceHandle, OpenMesh::FaceHandle>> pairs;
    for (auto g : {plan.halfedge, base.opposite_halfedge_handle(plan.halfedge)}) {
      if (base.is_boundary(g)) continue;
      pairs.emplace_back(base.opposite_face_handle(base.next_halfedge_handle(g)),
                         base.opposite_face_handle(base.prev_halfedge_handle(g)));
    }
    std::vector<double> before;
    for (const auto& [a, b] : pairs) before.push_back(unit_normal(base, a) | unit_normal(base, b));
    TriMesh mesh = base;
    apply_collapse(mesh, plan);
    ++collapses;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const auto [a, b] = pairs[i];
      // They now share an edge ...
      bool adjacent = false;
      for (auto g : mesh.ff_range(a)) adjacent = adjacent || g == b;
      CHECK(adjacent);
      // ... and meet no more sharply than allowed.
      const double after = unit_normal(mesh, a) | unit_normal(mesh, b);
      CHECK(after >= std::min(geom::kMinAdjacentCos, before[i]) - 1e-9);
    }
  }
  CHECK(collapses > 50);
}

TEST_CASE("an interior edge between two boundary vertices is never collapsed", "[steps]") {
  TriMesh strip = test::make_open_grid(1, 6, 1.0);  // every vertex on the boundary
  std::size_t interior = 0;
  for (auto e : strip.edges()) {
    if (strip.is_boundary(e)) continue;
    ++interior;
    CollapsePlan plan;
    CHECK_FALSE(plan_collapse(strip, e, 10.0, 1e9, plan));
  }
  CHECK(interior >= 6);
}

TEST_CASE("a tetrahedron does not collapse away", "[steps]") {
  TriMesh mesh = tetrahedron();
  for (auto e : mesh.edges()) {
    CollapsePlan plan;
    CHECK_FALSE(plan_collapse(mesh, e, 10.0, 1e9, plan));
  }
}

TEST_CASE("a collapse is refused only in a component of 4 vertices or fewer", "[steps]") {
  // In one mesh: a sphere, a square of two triangles (4 vertices: without the rule, its boundary
  // edges and its diagonal could collapse) and a square pyramid without its base (5 vertices: its
  // edges may collapse). The search from a vertex stays in its component.
  TriMesh mesh = test::make_icosphere(2);
  const std::size_t sphere = mesh.n_vertices();
  auto add = [&](std::initializer_list<Vec3> points, std::initializer_list<std::array<int, 3>> faces) {
    std::vector<OpenMesh::VertexHandle> v;
    for (const Vec3& p : points) v.push_back(mesh.add_vertex(p));
    for (const auto& f : faces) mesh.add_face(v[f[0]], v[f[1]], v[f[2]]);
    return v;
  };
  const auto square = add({Vec3(5, 0, 0), Vec3(6, 0, 0), Vec3(6, 1, 0), Vec3(5, 1, 0)}, {{0, 1, 2}, {0, 2, 3}});
  const auto pyramid = add({Vec3(10, 0, 0), Vec3(11, 0, 0), Vec3(11, 1, 0), Vec3(10, 1, 0), Vec3(10.5, 0.5, 0.3)},
                           {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
  const auto on_sphere = mesh.vertex_handle(0);
  CHECK(component_larger_than(mesh, on_sphere, 4));
  CHECK(component_larger_than(mesh, on_sphere, sphere - 1));
  CHECK_FALSE(component_larger_than(mesh, on_sphere, sphere));
  CHECK(component_larger_than(mesh, square[0], 0));
  CHECK(component_larger_than(mesh, square[0], 3));
  CHECK_FALSE(component_larger_than(mesh, square[0], 4));
  CHECK(component_larger_than(mesh, pyramid[4], 4));
  CHECK_FALSE(component_larger_than(mesh, pyramid[4], 5));
  std::size_t allowed[3] = {0, 0, 0};  // sphere, square, pyramid
  for (auto e : mesh.edges()) {
    CollapsePlan plan;
    const int v = mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    const int part = v < static_cast<int>(sphere) ? 0 : v < square[3].idx() + 1 ? 1 : 2;
    allowed[part] += plan_collapse(mesh, e, 10.0, 1e9, plan);
  }
  CHECK(allowed[0] > 0);
  CHECK(allowed[1] == 0);
  CHECK(allowed[2] > 0);
}

TEST_CASE("eq. 3.1 places the vertex at the minimiser", "[steps]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    std::vector<Vec3> neighbours;
    for (int k = 0; k < 3 + trial % 6; ++k) neighbours.emplace_back(u(rng), u(rng), u(rng));
    const double target = 1.0 + 0.02 * trial;
    const double t = equalizing_parameter(a, b, neighbours, target);
    REQUIRE(t >= 0.0);
    REQUIRE(t <= 1.0);
    // Brute force, recomputing E(t) here.
    auto energy = [&](double s) {
      const Vec3 p = a + (b - a) * s;
      double e = 0;
      for (const Vec3& v : neighbours) e += ((p - v).norm() - target) * ((p - v).norm() - target);
      return e;
    };
    double best = energy(0);
    for (int i = 1; i <= 20000; ++i) best = std::min(best, energy(i / 20000.0));
    CHECK(energy(t) <= best + 1e-6);
  }
}

TEST_CASE("a flip is kept only under the valence-and-angle rule", "[steps]") {
  for (double f : {0.0, 0.5, 0.9}) {
    TriMesh mesh = test::make_open_grid(10, 10, 1.0);  // interior valences 4 and 8
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2);
    for (auto v : mesh.vertices())
      if (!mesh.is_boundary(v)) mesh.point(v) += Vec3(jitter(rng), jitter(rng), 0);
    std::size_t accepted = 0;
    for (auto e : mesh.edges()) {
      if (mesh.is_boundary(e)) {
        CHECK_FALSE(flip_improves(mesh, e, f));
        continue;
      }
      // The rule, recomputed on a flipped copy.
      auto h0 = mesh.halfedge_handle(e, 0), h1 = mesh.halfedge_handle(e, 1);
      OpenMesh::VertexHandle q[4] = {mesh.from_vertex_handle(h0), mesh.to_vertex_handle(h0),
                                     mesh.to_vertex_handle(mesh.next_halfedge_handle(h0)),
                                     mesh.to_vertex_handle(mesh.next_halfedge_handle(h1))};
      auto dev = [&](const TriMesh& m) {
        int d = 0;
        for (auto v : q) d += std::abs(static_cast<int>(m.valence(v)) - (m.is_boundary(v) ? 4 : 6));
        return d;
      };
      const bool says = flip_improves(mesh, e, f);
      if (!mesh.is_flip_ok(e)) {
        CHECK_FALSE(says);
        continue;
      }
      TriMesh copy = mesh;
      const int dev_before = dev(copy);
      const double angle_before = two_face_min_angle(copy, e);
      copy.flip(e);
      const bool rule = dev(copy) < dev_before && two_face_min_angle(copy, e) >= f * angle_before - 1e-12;
      if (says) {
        CHECK(rule);
        ++accepted;
      }
    }
    CHECK(accepted > 0);
    std::size_t flips = valence_flips(mesh, f, 3);
    CHECK(flips > 0);
    CHECK(test::check_mesh_valid(mesh) == "");
  }
}

TEST_CASE("the filter moves vertices tangentially only and never moves boundary vertices", "[steps]") {
  SECTION("open flat patch") {
    TriMesh mesh = test::make_open_grid(12, 12, 1.0);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> jitter(-0.25, 0.25);
    for (auto v : mesh.vertices())
      if (!mesh.is_boundary(v)) mesh.point(v) += Vec3(jitter(rng), jitter(rng), 0);
    TriMesh before = mesh;
    for (int rings : {1, 2, 3}) {
      const auto moves = low_pass_displacements(mesh, rings, 2);
      for (auto v : mesh.vertices()) {
        if (mesh.is_boundary(v)) CHECK(moves[v.idx()].norm() == 0.0);
        CHECK(std::abs(moves[v.idx()][2]) < 1e-12);
      }
    }
    low_pass_filter(mesh, 2, 2);
    std::size_t moved = 0;
    for (auto v : mesh.vertices()) {
      if (mesh.is_boundary(v)) CHECK(mesh.point(v) == before.point(v));
      else moved += (mesh.point(v) - before.point(v)).norm() > 1e-6;
    }
    CHECK(moved > 50);
  }
  SECTION("curved closed surface") {
    TriMesh mesh = test::make_torus(30, 15, 3.0, 1.0);
    const auto moves = low_pass_displacements(mesh, 2, 2);
    double largest = 0;
    for (auto v : mesh.vertices()) {
      CHECK(std::abs(moves[v.idx()] | normal_of(mesh, v)) < 1e-9 * (1 + moves[v.idx()].norm()));
      largest = std::max(largest, moves[v.idx()].norm());
    }
    CHECK(largest > 1e-4);
  }
}

TEST_CASE("the reference's creases are lines of sharp edges, with corners where they end or bend", "[steps]") {
  const double tol = 1e-9;
  SECTION("a cylinder of 128 segments: its rims") {
    const TriMesh cylinder = test::make_sliver_cylinder(128, 1.0, 2.0);
    const CreaseLines creases(cylinder);
    CHECK(creases.size() == 256);  // the rims; the side facets meet at 2.8 degrees
    for (int i = 0; i < 128; i += 17) {
      const double a = 2 * M_PI * i / 128, b = 2 * M_PI * (i + 1) / 128;
      const Vec3 p(std::cos(a), std::sin(a), 2.0), q(std::cos(b), std::sin(b), 2.0);
      // A rim vertex: a bend of 2.8 degrees, the line goes on to its neighbours on the rim.
      const CreaseLines::Where at = creases.locate(p, tol);
      REQUIRE(at.kind == CreaseLines::Kind::Line);
      const Vec3 before(std::cos(a - 2 * M_PI / 128), std::sin(a - 2 * M_PI / 128), 2.0);
      CHECK(std::min((at.ahead - q).norm() + (at.back - before).norm(),
                     (at.ahead - before).norm() + (at.back - q).norm()) < 1e-12);
      // Between two rim vertices: their segment.
      const CreaseLines::Where mid = creases.locate(0.3 * p + 0.7 * q, tol);
      REQUIRE(mid.kind == CreaseLines::Kind::Line);
      CHECK(std::min((mid.ahead - q).norm() + (mid.back - p).norm(), (mid.ahead - p).norm() + (mid.back - q).norm()) <
            1e-12);
    }
    CHECK(creases.locate(Vec3(0, 0, 2), tol).kind == CreaseLines::Kind::None);  // the cap's centre
    CHECK(creases.locate(Vec3(1, 0, 1), tol).kind == CreaseLines::Kind::None);  // on the side
    CHECK(creases.locate(Vec3(1, 0, 2 - 1e-6), tol).kind == CreaseLines::Kind::None);
  }
  SECTION("a cylinder of 10 segments: its rims bend by 36 degrees at every vertex") {
    const TriMesh cylinder = test::make_sliver_cylinder(10, 1.0, 2.0);
    const CreaseLines creases(cylinder);
    CHECK(creases.size() == 20);
    CHECK(creases.locate(Vec3(1, 0, 0), tol).kind == CreaseLines::Kind::Corner);
    const Vec3 q(std::cos(2 * M_PI / 10), std::sin(2 * M_PI / 10), 0);
    CHECK(creases.locate(0.5 * (Vec3(1, 0, 0) + q), tol).kind == CreaseLines::Kind::Line);
  }
  SECTION("a spike is no crease: fewer than kMinCreaseEdges sharp edges together") {
    TriMesh grid = test::make_open_grid(8, 8, 1.0);
    OpenMesh::VertexHandle spike;
    for (auto v : grid.vertices())
      if (grid.point(v) == Vec3(3, 4, 0)) spike = v;
    REQUIRE(spike.is_valid());
    REQUIRE(grid.valence(spike) == 4);
    grid.point(spike)[2] = 3;  // 8 edges of about 90 degrees: its 4 spokes and the 4 around them
    CHECK(CreaseLines(grid).empty());
  }
}

TEST_CASE("the filter moves a vertex on a crease along it only", "[steps]") {
  const TriMesh cylinder = test::make_sliver_cylinder(128, 1.0, 2.0);
  const CreaseLines creases(cylinder);
  const auto free = low_pass_displacements(cylinder, 2, 2);
  const auto held = low_pass_displacements(cylinder, 2, 2, &creases, 1e-9);
  std::size_t rim = 0, across = 0;
  for (auto v : cylinder.vertices()) {
    const Vec3 p = cylinder.point(v);
    if (std::abs(std::hypot(p[0], p[1]) - 1) > 1e-12) {  // a cap's centre: as without creases
      CHECK(held[v.idx()] == free[v.idx()]);
      continue;
    }
    ++rim;
    // Along the rim to a neighbour on it, no farther: the moved point lies on one of its two
    // rim segments.
    const double a = std::atan2(p[1], p[0]), step = 2 * M_PI / 128;
    const Vec3 moved = p + held[v.idx()];
    double off = 1e9;
    for (double b : {a - step, a + step})
      off = std::min(off, (geom::closest_point_on_segment(moved, p, Vec3(std::cos(b), std::sin(b), p[2])) - moved).norm());
    CHECK(off < 1e-12);
    // Without the creases the filter pulls every rim vertex off the rim (towards the cap's centre).
    const Vec3 tangent(-p[1], p[0], 0);
    across += (free[v.idx()] % tangent).norm() > 1e-3;
  }
  CHECK(rim == 256);
  CHECK(across == 256);
}

namespace {

/// A strip folded at a right angle along the y axis: 12 edges on the fold, and on either side one
/// vertex 0.4 across from the middle of each of them. (A flip of a fold edge tilts its new faces by
/// 49 degrees against the old: allowed, kMinNormalCos. With vertices 0.8 across: 62, refused.)
TriMesh make_folded_strip() {
  TriMesh mesh;
  std::vector<OpenMesh::VertexHandle> f, l, r;
  for (int k = 0; k <= 12; ++k) f.push_back(mesh.add_vertex(Vec3(0, k, 0)));
  for (int k = 0; k < 12; ++k) {
    l.push_back(mesh.add_vertex(Vec3(-0.4, k + 0.5, 0)));
    r.push_back(mesh.add_vertex(Vec3(0, k + 0.5, 0.4)));
  }
  for (int k = 0; k < 12; ++k) {
    mesh.add_face(f[k], l[k], f[k + 1]);
    mesh.add_face(f[k + 1], r[k], f[k]);
    if (k + 1 < 12) {
      mesh.add_face(l[k], l[k + 1], f[k + 1]);
      mesh.add_face(r[k], f[k + 1], r[k + 1]);
    }
  }
  return mesh;
}

OpenMesh::EdgeHandle edge_between(const TriMesh& mesh, const Vec3& a, const Vec3& b) {
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    const Vec3 &p = mesh.point(mesh.from_vertex_handle(h)), &q = mesh.point(mesh.to_vertex_handle(h));
    if (((p - a).norm() < 1e-12 && (q - b).norm() < 1e-12) || ((p - b).norm() < 1e-12 && (q - a).norm() < 1e-12))
      return e;
  }
  return OpenMesh::EdgeHandle();
}

}  // namespace

TEST_CASE("the crease guard: no flip of an edge along a crease", "[steps]") {
  const TriMesh mesh = make_folded_strip();
  const CreaseLines creases(mesh);
  REQUIRE(creases.size() == 12);
  const CreaseGuard guard(creases, 1e-9);
  std::size_t along = 0, flippable = 0;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    const Vec3 &a = mesh.point(mesh.from_vertex_handle(h)), &b = mesh.point(mesh.to_vertex_handle(h));
    const bool on_fold = a[0] == 0 && b[0] == 0 && a[2] == 0 && b[2] == 0 && a[1] != b[1];
    CHECK(guard.along(a, b) == on_fold);
    if (!on_fold) continue;
    ++along;
    // A flip across the fold passes every other rule: the remeshed surface would cut the crease.
    if (!flip_is_safe(mesh, e, 0.0)) continue;
    ++flippable;
    CHECK_FALSE(flip_is_safe(mesh, e, 0.0, nullptr, false, &guard));
  }
  CHECK(along == 12);
  CHECK(flippable > 0);
}

TEST_CASE("the crease guard: splits and collapses keep a bent crease", "[steps]") {
  // The reference: a cylinder of 32 segments; the mesh: one of 16, whose rim edges are chords of
  // two of the reference's rim segments (their midpoints 0.0144 inside the crease).
  const TriMesh reference = test::make_sliver_cylinder(32, 1.0, 2.0);
  const CreaseLines creases(reference);
  const CreaseGuard guard(creases, 1e-9);
  const Vec3 p0(1, 0, 2), p1(std::cos(M_PI / 8), std::sin(M_PI / 8), 2);
  SECTION("a split of a rim edge puts its vertex on the rim") {
    for (const bool guarded : {false, true}) {
      TriMesh mesh = test::make_sliver_cylinder(16, 1.0, 2.0);
      const auto e = edge_between(mesh, p0, p1);
      REQUIRE(e.is_valid());
      REQUIRE(guard.along(p0, p1));
      const auto v = split_edge(mesh, e, 0.2, guarded ? &guard : nullptr);
      REQUIRE(v.is_valid());
      CHECK(guard.on(mesh.point(v)) == guarded);
      CHECK(test::check_mesh_valid(mesh) == "");
    }
  }
  SECTION("a collapse along the rim puts its vertex on the rim; one onto the rim keeps the rim vertex") {
    TriMesh mesh = test::make_sliver_cylinder(16, 1.0, 2.0);
    CollapsePlan plan;
    REQUIRE(plan_collapse(mesh, edge_between(mesh, p0, p1), 0.2, 10.0, plan, true, &guard));
    CHECK(guard.on(plan.position));
    CHECK_FALSE(plan.kept_in_place);
    REQUIRE(plan_collapse(mesh, edge_between(mesh, p0, p1), 0.2, 10.0, plan, true, nullptr));
    CHECK_FALSE(guard.on(plan.position));  // eq. 3.1's point on the chord
    // A spoke (the cap's centre to the rim): the rim end stays.
    REQUIRE(plan_collapse(mesh, edge_between(mesh, Vec3(0, 0, 2), p0), 0.2, 10.0, plan, true, &guard));
    CHECK(plan.kept_in_place);
    CHECK(plan.position == p0);
    CHECK(mesh.point(mesh.to_vertex_handle(plan.halfedge)) == p0);
  }
  SECTION("an edge between two creases is not collapsed") {
    TriMesh mesh = test::make_sliver_cylinder(16, 1.0, 2.0);
    const auto side = edge_between(mesh, Vec3(1, 0, 0), Vec3(1, 0, 2));
    REQUIRE(side.is_valid());
    CollapsePlan plan;
    CHECK_FALSE(plan_collapse(mesh, side, 0.2, 10.0, plan, true, &guard));
  }
}

TEST_CASE("the crease guard moves a vertex along its crease only", "[steps]") {
  const TriMesh reference = test::make_sliver_cylinder(128, 1.0, 2.0);
  const CreaseLines creases(reference);
  const Vec3 p(1, 0, 2);
  const CreaseLines::Where at = creases.locate(p, 1e-9);
  REQUIRE(at.kind == CreaseLines::Kind::Line);
  const Vec3 moved = CreaseGuard::constrain(p, at, Vec3(0.5, 0.5, 1.7));
  CHECK(moved != p);
  CHECK(creases.locate(moved, 1e-9).kind != CreaseLines::Kind::None);
  CHECK(CreaseGuard::constrain(p, CreaseLines::Where{CreaseLines::Kind::Corner, {}, {}}, Vec3(0, 0, 0)) == p);
  CHECK(CreaseGuard::constrain(p, CreaseLines::Where{}, Vec3(0, 0, 0)) == Vec3(0, 0, 0));
}

TEST_CASE("a crease joins two points along it, not two creases side by side", "[steps]") {
  const TriMesh cylinder = test::make_sliver_cylinder(128, 1.0, 2.0);
  const CreaseLines creases(cylinder);
  // The k-th point of a rim (the input's vertices; the rims are polylines through them).
  auto rim = [](int k, double z) {
    const double a = 2 * M_PI * k / 128;
    return Vec3(std::cos(a), std::sin(a), z);
  };
  // Along the top rim over 4 segments (a chord of 0.1960, an arc of 0.1963), the path's segments
  // with it.
  std::vector<std::array<Vec3, 2>> path;
  CHECK(creases.joined(rim(0, 2), rim(4, 2), 1e-9, 0.2, &path));
  CHECK(path.size() == 4);
  CHECK_FALSE(creases.joined(rim(0, 2), rim(4, 2), 1e-9, 0.195));  // the arc is longer
  CHECK(creases.joined(0.5 * (rim(0, 2) + rim(1, 2)), rim(4, 2), 1e-9, 0.2));  // from inside a segment
  // Not from the top rim to the bottom one (parallel creases 2 apart), nor from off a crease.
  CHECK_FALSE(creases.joined(rim(0, 2), rim(0, 0), 1e-9, 10.0));
  CHECK_FALSE(creases.joined(Vec3(0, 0, 2), rim(0, 2), 1e-9, 10.0));
  // The crease guard's rule: an edge along the rim is along a crease, a side edge is not.
  const CreaseGuard guard(creases, 1e-9);
  CHECK(guard.along(rim(0, 2), rim(4, 2)));
  CHECK_FALSE(guard.along(rim(0, 2), rim(0, 0)));
  CHECK_FALSE(guard.along(rim(0, 2), rim(36, 0)));
  // onto(): a point of the chord goes to the rim between its ends.
  const Vec3 mid = 0.5 * (rim(0, 2) + rim(4, 2));
  const Vec3 q = guard.onto(mid, rim(0, 2), rim(4, 2));
  CHECK(guard.on(q));
  CHECK((q - mid).norm() < 0.005);
  CHECK(guard.onto(mid, rim(0, 2), rim(0, 0)) == mid);  // no crease joins them
}

TEST_CASE("project_vertices puts the placed vertices on the reference, the others stay", "[steps]") {
  const TriMesh reference = test::make_icosphere(3, 10.0);
  const ReferenceSurface surface(reference);
  TriMesh mesh = reference;
  // Every 7th vertex pushed 2 % inwards (a split's point on its edge's chord lies under a sphere).
  std::vector<OpenMesh::VertexHandle> placed;
  for (auto v : mesh.vertices())
    if (v.idx() % 7 == 0) mesh.point(v) *= 0.98, placed.push_back(v);
  const OpenMesh::VertexHandle other = mesh.vertex_handle(1);
  mesh.point(other) *= 0.98;  // pushed too, but not placed
  TriMesh twin = mesh;
  CHECK(project_vertices(mesh, placed, surface) == placed.size());
  for (auto v : placed) CHECK(test::brute_distance(reference, mesh.point(v)) < 1e-9);
  CHECK(test::brute_distance(reference, mesh.point(other)) > 0.1);
  CHECK(test::check_mesh_valid(mesh) == "");
  // With the iterations' kd-tree answers (filled by a projection of another mesh, so that every
  // vertex's search starts from a cache or a neighbour's, none of them this point's) and two
  // threads: the same points.
  std::vector<NeighbourCache> caches;
  TriMesh projected = reference;
  for (auto v : projected.vertices()) projected.point(v) *= 1.01;
  project_onto_reference(projected, surface, 1, &caches);
  caches.resize(caches.size() / 2);  // the upper half of the vertices take a neighbour's
  TriMesh single = twin;
  CHECK(project_vertices(twin, placed, surface, 2, &caches) == placed.size());
  for (auto v : twin.vertices()) CHECK((twin.point(v) - mesh.point(v)).norm() < 1e-12);
  // The same caches on one thread: the same points, bit for bit.
  CHECK(project_vertices(single, placed, surface, 1, &caches) == placed.size());
  for (auto v : twin.vertices()) CHECK(twin.point(v) == single.point(v));
}

TEST_CASE("the interval guard projects every vertex it leaves half way, moved once or more", "[steps]") {
  // A vertex moved tangentially off a sphere breaks its edges; the guard moves it back half way
  // (twice in one round when two of its edges broke) and then onto the reference. Before, a vertex
  // moved twice in its first round was left a quarter of the way back, 2.1e-3 off the sphere.
  const TriMesh sphere = test::make_icosphere(3, 1.0);
  const ReferenceSurface reference(sphere);
  double lo = 1e9, hi = 0;
  for (auto e : sphere.edges()) lo = std::min(lo, sphere.calc_edge_length(e)), hi = std::max(hi, sphere.calc_edge_length(e));
  for (const double share : {0.3, 0.6, 1.2}) {
    TriMesh mesh = sphere;
    const std::vector<Vec3> before = snapshot_points(mesh);
    const auto v = mesh.vertex_handle(0);
    const Vec3 n = mesh.point(v).normalized();
    Vec3 t = Vec3(0, 0, 1) % n;
    if (t.norm() < 1e-6) t = Vec3(1, 0, 0) % n;
    mesh.point(v) += t.normalized() * (share * hi);
    INFO("moved by " << share << " of the longest edge");
    REQUIRE(undo_interval_breaks(mesh, before, 0.8 * lo, 1.25 * hi, 3, &reference) > 0);
    CHECK((reference.closest_point(mesh.point(v)) - mesh.point(v)).norm() < 1e-12);
    CHECK(test::plain_inside_fraction(mesh, 0.8 * lo, 1.25 * hi) == 1.0);
  }
}

TEST_CASE("a chord across a flat cap is no crease edge, though a crease joins its ends", "[steps]") {
  // A cylinder whose caps are fans from a rim vertex (as CAD exports write them): the cap's chords
  // join two rim points, a crease of 90 degrees or less joins them, but the chord's faces are flat.
  const int n = 64;
  const TriMesh mesh = test::make_rim_fanned_cylinder(n, 1.0, 2.0);
  auto rim = [&](int i) {  // vertex i of the bottom rim (the generator adds them bottom, top, bottom, ...)
    return mesh.vertex_handle(static_cast<unsigned>(2 * i));
  };
  const CreaseLines creases(mesh);
  REQUIRE(creases.size() == 2 * n);
  const CreaseGuard guard(creases, 1e-9);
  const auto chord = edge_between(mesh, mesh.point(rim(0)), mesh.point(rim(16)));
  const auto along_rim = edge_between(mesh, mesh.point(rim(0)), mesh.point(rim(1)));
  REQUIRE(chord.is_valid());
  REQUIRE(along_rim.is_valid());
  CHECK(guard.along(mesh.point(rim(0)), mesh.point(rim(16))));  // a quarter of the rim joins them
  CHECK_FALSE(guard.along(mesh, chord));
  CHECK(guard.along(mesh, along_rim));
  // Flippable, and a split keeps its point on the chord.
  CHECK(flip_is_safe(mesh, chord, 0.0, nullptr, false, &guard));
  TriMesh split = mesh;
  const auto v = split_edge(split, edge_between(split, split.point(rim(0)), split.point(rim(16))), 0.1, &guard);
  REQUIRE(v.is_valid());
  CHECK(std::abs(split.point(v)[2]) < 1e-12);
  CHECK(std::hypot(split.point(v)[0], split.point(v)[1]) < 0.9);
  CHECK(test::check_mesh_valid(split) == "");
}

TEST_CASE("the interval guard moves back, half way at a time, what took edges out of the interval", "[steps]") {
  // Every edge 1.5, inside [1.2, 1.8]; a random move of up to 0.35 per coordinate takes many out.
  for (const int halvings : {0, 3}) {
    TriMesh mesh = test::make_hex_lattice_patch(14, 14, 1.5);
    const std::vector<Vec3> before = snapshot_points(mesh);
    std::mt19937 rng(static_cast<unsigned>(17 + halvings));
    std::uniform_real_distribution<double> jitter(-0.35, 0.35);
    for (auto v : mesh.vertices()) mesh.point(v) += Vec3(jitter(rng), jitter(rng), 0);
    const std::vector<Vec3> moved = snapshot_points(mesh);
    const double broken_before = 1.0 - test::plain_inside_fraction(mesh, 1.2, 1.8);
    REQUIRE(broken_before > 0.05);
    const std::size_t moves = undo_interval_breaks(mesh, before, 1.2, 1.8, halvings);
    CHECK(moves > 0);
    // Every edge is inside again (all were inside before) ...
    CHECK(test::plain_inside_fraction(mesh, 1.2, 1.8) == 1.0);
    // ... and each vertex lies where it was, where it moved, or 1/2, 1/4 or 1/8 of the way (none of
    // those with no halvings).
    std::size_t kept = 0, back = 0, partly = 0;
    for (auto v : mesh.vertices()) {
      const Vec3 &was = before[v.idx()], &to = moved[v.idx()], &now = mesh.point(v);
      if (now == to) {
        ++kept;
      } else if (now == was) {
        ++back;
      } else {
        bool on_the_way = false;
        for (double t : {0.5, 0.25, 0.125})
          on_the_way = on_the_way || (now - (was + (to - was) * t)).norm() < 1e-12;
        CHECK(on_the_way);
        ++partly;
      }
    }
    CHECK(kept > 0);  // not a plain undo: vertices whose edges stayed inside keep their move
    CHECK(back + partly > 0);
    if (halvings == 0) CHECK(partly == 0);
    if (halvings == 3) CHECK(partly > 0);
  }
}

TEST_CASE("projection lands on the reference surface", "[steps]") {
  const TriMesh sphere = test::make_icosphere(4, 1.0);  // edge ~0.077: chord error < 1e-3
  const ReferenceSurface reference(sphere);
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> r(0.9, 1.1);
  for (int i = 0; i < 500; ++i) {
    Vec3 d(g(rng), g(rng), g(rng));
    d.normalize();
    const Vec3 p = d * r(rng);
    const Vec3 c = reference.closest_point(p, d);
    CHECK(std::abs(c.norm() - 1.0) < 2e-3);
    CHECK((c - d).norm() < 0.08);  // near the radial projection
    // Nothing on the sphere mesh is closer than c (brute force over all triangles).
    CHECK((c - p).norm() <= test::brute_distance(sphere, p) + 1e-12);
  }
  TriMesh mesh = test::make_icosphere(2, 1.07);
  const double moved = project_onto_reference(mesh, reference, 2);
  CHECK(moved > 0.05);
  for (auto v : mesh.vertices()) CHECK(std::abs(mesh.point(v).norm() - 1.0) < 2e-3);
}

TEST_CASE("a reused neighbour cache gives the kd-tree's closest point", "[steps]") {
  // A bumpy torus: uneven vertex spacing, so that cached sets are often not the nearest ones.
  TriMesh torus = test::make_torus(48, 24, 10.0, 3.0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (auto v : torus.vertices()) torus.point(v) += Vec3(jitter(rng), jitter(rng), jitter(rng));
  const ReferenceSurface reference(torus);
  std::normal_distribution<double> g(0, 1);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(torus.n_vertices()) - 1);
  std::size_t reused = 0, refilled = 0, refilled_after_move = 0;
  for (int walker = 0; walker < 40; ++walker) {
    NeighbourCache cache;
    Vec3 p = torus.point(torus.vertex_handle(pick(rng)));
    for (int step = 0; step < 60; ++step) {
      const double size = step % 10 == 9 ? 3.0 : 0.05;  // mostly small moves, now and then a jump
      p += Vec3(g(rng), g(rng), g(rng)) * size;
      const Vec3 hint(g(rng), g(rng), g(rng));
      const Vec3 before = cache.query;
      const bool was_filled = cache.count > 0;
      const Vec3 cached = reference.closest_point(p, hint, cache);
      const Vec3 fresh = reference.closest_point(p, hint);
      CHECK(std::abs((cached - p).norm() - (fresh - p).norm()) < 1e-12);
      CHECK((cached - fresh).norm() < 1e-9);
      if (cache.query == p && before != p) {
        ++refilled;
        // A refill is the kd-tree's answer, in its order, whether or not the old cache bounded
        // the search (it does after a move).
        std::uint32_t nearest[NeighbourCache::kCacheSize];
        REQUIRE(reference.nearest_vertices(p, NeighbourCache::kCacheSize, nearest) == cache.count);
        CHECK(std::equal(nearest, nearest + cache.count, cache.idx));
        if (was_filled) ++refilled_after_move;
      } else {
        ++reused;
      }
    }
  }
  CHECK(reused > 0);
  CHECK(refilled > 40);  // every walker's first query, and jumps
  CHECK(refilled_after_move > 40);
}

TEST_CASE("the interval cleanup is safe, keeps vertices on the reference and is idempotent", "[steps]") {
  const TriMesh sphere = test::make_icosphere(5, 20.0);  // fine reference, edge ~0.7
  const ReferenceSurface reference(sphere);
  TriMesh mesh = test::make_icosphere(3, 20.0);  // edge ~2.7: everything too long
  // Bring it near the interval [1.2, 1.8] without cleanup: split every edge once, then project.
  {
    const std::size_t n = mesh.n_edges();
    for (unsigned i = 0; i < n; ++i) split_edge(mesh, mesh.edge_handle(i), 1.5);
    project_onto_reference(mesh, reference, 2);
  }
  auto outside = [](const TriMesh& m) {
    std::size_t n = 0;
    for (auto e : m.edges()) {
      const double l = m.calc_edge_length(e);
      n += (l < 1.2 || l > 1.8);
    }
    return n;
  };
  const std::size_t before = outside(mesh);
  REQUIRE(before > 0);
  {
    // A stop requested before it starts: the cleanup fixes nothing and the mesh stays as it was.
    std::stop_source stopped;
    stopped.request_stop();
    CleanupOptions options;
    options.stop = stopped.get_token();
    TriMesh copy = mesh;
    const CleanupCounts none = interval_cleanup(copy, reference, 1.2, 1.8, 0.5, options);
    CHECK(none.flips + none.collapses + none.splits + none.relocations + none.patches == 0);
    CHECK(outside(copy) == before);
    CHECK(test::check_mesh_valid(copy) == "");
  }
  const CleanupCounts counts = interval_cleanup(mesh, reference, 1.2, 1.8, 0.5);
  CHECK(counts.outside_before == before);
  CHECK(counts.outside_after == outside(mesh));
  CHECK(outside(mesh) < before);
  CHECK(test::check_mesh_valid(mesh) == "");
  CHECK(test::euler_characteristic(mesh) == 2);
  for (auto v : mesh.vertices()) CHECK(std::abs(mesh.point(v).norm() - 20.0) < 0.05);
  // Run again: never worse; on a mesh with every edge inside it changes nothing.
  const std::size_t after_first = outside(mesh);
  interval_cleanup(mesh, reference, 1.2, 1.8, 0.5);
  CHECK(outside(mesh) <= after_first);
  TriMesh inside = test::make_icosphere(2, 1.0);
  const TriMesh copy = inside;
  const ReferenceSurface unit(inside);
  const CleanupCounts none = interval_cleanup(inside, unit, 0.01, 100.0, 0.5);
  CHECK(none.flips + none.collapses + none.splits + none.relocations == 0);
  for (auto v : inside.vertices()) CHECK(inside.point(v) == copy.point(v));
}

TEST_CASE("with protect_tips the interval cleanup moves no tip", "[steps]") {
  // Spheres with six spikes (vertices pulled out to 1.15-1.25 times the radius: tips, is_tip),
  // scaled to a mean edge of 1.45, so that the spikes' edges are too long for [1.2, 1.8]. With
  // protect_tips each tip's position is still a vertex of the mesh afterwards, the cleanup
  // mending what it can around them; without it the cleanup takes some of them away (measured:
  // the patch relaxations move every tip of the 1.25 spikes). The meshes stay valid either way.
  std::size_t kept_without = 0, tips = 0, fixes = 0;  // fixes: edges mended with protect_tips
  for (const double spike : {1.15, 1.2, 1.25}) {
    INFO("spike " << spike);
    TriMesh base = test::make_icosphere(3, 1.0);
    for (int i = 0; i < 12; i += 2) base.point(base.vertex_handle(i)) *= spike;
    test::scale_mean_edge(base, 1.45);
    std::vector<Vec3> tip_points;
    for (auto v : base.vertices())
      if (is_tip(base, v)) tip_points.push_back(base.point(v));
    REQUIRE(tip_points.size() == 6);
    const ReferenceSurface reference(base);
    auto count_kept = [&](const TriMesh& m) {
      std::size_t n = 0;
      for (const Vec3& t : tip_points) {
        bool found = false;
        for (auto v : m.vertices()) found = found || m.point(v) == t;
        n += found;
      }
      return n;
    };
    for (const bool protect : {true, false}) {
      TriMesh mesh = base;
      CleanupOptions options;
      options.rounds = 6;
      options.protect_tips = protect;
      const CleanupCounts c = interval_cleanup(mesh, reference, 1.2, 1.8, 0.5, options);
      CHECK(test::check_mesh_valid(mesh) == "");
      if (protect) {
        fixes += c.outside_before - c.outside_after;
        CHECK(count_kept(mesh) == tip_points.size());
      } else {
        kept_without += count_kept(mesh);
      }
    }
    tips += tip_points.size();
  }
  CHECK(fixes > 10);  // the cleanup still mends edges (splitting those at the tips)
  CHECK(kept_without < tips);
}

TEST_CASE("a mesh snapshot rebuilds the live vertices and faces in their order", "[steps]") {
  TriMesh mesh = test::make_torus(20, 10, 3.0, 1.0);
  // Delete a few elements without garbage collection, as a run leaves them between steps.
  int collapsed = 0;
  for (auto h : mesh.halfedges())
    if (collapsed < 5 && !mesh.status(h).deleted() && mesh.is_collapse_ok(h)) mesh.collapse(h), ++collapsed;
  REQUIRE(collapsed == 5);
  std::vector<Vec3> points;
  for (auto v : mesh.vertices())
    if (!mesh.status(v).deleted()) points.push_back(mesh.point(v));
  std::vector<std::array<Vec3, 3>> faces;
  for (auto f : mesh.faces()) {
    if (mesh.status(f).deleted()) continue;
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(mesh, f, c);
    faces.push_back({mesh.point(c[0]), mesh.point(c[1]), mesh.point(c[2])});
  }
  TriMesh rebuilt = test::make_hex_lattice_patch(4, 4, 1.5);  // replaced whole by the snapshot's mesh
  MeshSnapshot(mesh).rebuild(rebuilt);
  CHECK(test::check_mesh_valid(rebuilt) == "");
  CHECK(test::euler_characteristic(rebuilt) == 0);
  REQUIRE(rebuilt.n_vertices() == points.size());
  REQUIRE(rebuilt.n_faces() == faces.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    CHECK(rebuilt.point(rebuilt.vertex_handle(static_cast<unsigned>(i))) == points[i]);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(rebuilt, rebuilt.face_handle(static_cast<unsigned>(i)), c);
    // The same corners in the same cyclic order (the orientation), from whichever corner.
    int same = 0;
    for (int r = 0; r < 3; ++r)
      same += rebuilt.point(c[r]) == faces[i][0] && rebuilt.point(c[(r + 1) % 3]) == faces[i][1] &&
              rebuilt.point(c[(r + 2) % 3]) == faces[i][2];
    CHECK(same == 1);
  }
}

TEST_CASE("the cleanup's failure memory changes nothing but the work", "[steps]") {
  // Meshes with edges no fix can mend (a tube too thin for the interval, a jittered sphere): the
  // cleanup with the memory (edges and relocations passed over while nothing near them changed)
  // and without it must give the same mesh, vertex for vertex and face for face, and the same
  // counts. The last case, a thin tube with short edges, fails when a relocation is remembered
  // over 1 ring instead of 2.
  std::mt19937 rng(5);
  std::normal_distribution<double> jitter(0.0, 0.25);
  struct Case {
    TriMesh reference, mesh;
  };
  std::vector<Case> cases;
  cases.push_back({test::make_torus(80, 16, 8.0, 0.6), test::make_torus(34, 5, 8.0, 0.6)});
  cases.push_back({test::make_icosphere(5, 12.0), test::make_icosphere(3, 12.0)});
  cases.push_back({test::make_torus(90, 30, 9.0, 3.0), test::make_torus(40, 12, 9.0, 3.0)});
  cases.push_back({test::make_torus(70, 10, 7.0, 0.45), test::make_torus(30, 4, 7.0, 0.45)});
  cases.push_back({test::make_icosphere(5, 9.0), test::make_icosphere(3, 9.0)});
  cases.push_back({test::make_torus(100, 14, 7.0, 0.5), test::make_torus(100, 14, 7.0, 0.5)});
  std::size_t skipped = 0;
  for (std::size_t c = 0; c < cases.size(); ++c) {
    CAPTURE(c);
    TriMesh& start = cases[c].mesh;
    for (auto v : start.vertices()) start.point(v) += Vec3(jitter(rng), jitter(rng), jitter(rng));
    const ReferenceSurface reference(cases[c].reference);
    project_onto_reference(start, reference, 2);
    // [1.42, 1.58]: a tight interval, where most edges stay outside and the memory answers far
    // more queries than there are fixes.
    for (const auto& [lo, hi] : {std::pair{1.2, 1.8}, std::pair{1.42, 1.58}})
    for (const std::size_t budget : {std::size_t{0}, std::size_t{4}, std::size_t{16}}) {  // 0: the default
      CAPTURE(lo, hi, budget);
      TriMesh with = start, without = start;
      CleanupOptions options;
      options.rounds = 12;
      options.patch_budget = budget;
      const CleanupCounts a = interval_cleanup(with, reference, lo, hi, 0.5, options);
      options.remember_failures = false;
      const CleanupCounts b = interval_cleanup(without, reference, lo, hi, 0.5, options);
      skipped += a.skipped;
      CHECK(b.skipped == 0);
      CHECK(a.flips == b.flips);
      CHECK(a.collapses == b.collapses);
      CHECK(a.splits == b.splits);
      CHECK(a.relocations == b.relocations);
      CHECK(a.patches == b.patches);
      CHECK(a.outside_after == b.outside_after);
      REQUIRE(with.n_vertices() == without.n_vertices());
      REQUIRE(with.n_faces() == without.n_faces());
      for (auto v : with.vertices()) CHECK(with.point(v) == without.point(v));
      for (auto f : with.faces()) {
        OpenMesh::VertexHandle x[3], y[3];
        geom::face_vertices(with, f, x);
        geom::face_vertices(without, f, y);
        CHECK((x[0] == y[0] && x[1] == y[1] && x[2] == y[2]));
      }
    }
  }
  CHECK(skipped > 0);  // the memory was used
}

TEST_CASE("a patch relaxation that failed in two cleanups in a row rests for one, longer as the row goes on", "[steps]") {
  // The memory alone: an edge whose ends both had failures in the last two cleanups (a rest
  // between two does not break the row) rests in the next cleanup, then is tried again; a failure
  // at one end rests nothing; a mesh rebuilt from scratch starts afresh.
  auto has_memory = [](const TriMesh& m) {
    return std::any_of(m.vprops_begin(), m.vprops_end(),
                       [](const OpenMesh::BaseProperty* p) { return p && p->name() == "remesh:patch_failed"; });
  };
  TriMesh mesh = test::make_icosphere(2, 1.0);
  const auto a = mesh.vertex_handle(0), b = mesh.vertex_handle(1), c = mesh.vertex_handle(2);
  {
    PatchRest rest(mesh);
    rest.begin();  // 1
    CHECK(has_memory(mesh));
    CHECK_FALSE(rest.resting(a, b));
    rest.failed(a, b);
    rest.begin();  // 2
    CHECK_FALSE(rest.resting(a, b));  // one failure
    rest.failed(a, b);
    rest.failed(a, c);
    rest.begin();  // 3
    CHECK(rest.resting(a, b));
    CHECK(rest.resting(b, a));
    CHECK_FALSE(rest.resting(a, c));  // c failed once
    rest.begin();  // 4: rested in 3, tried again
    CHECK_FALSE(rest.resting(a, b));
    rest.failed(a, b);
    rest.begin();  // 5: the row goes on across the rest
    CHECK(rest.resting(a, b));
    rest.begin();  // 6
    rest.begin();  // 7: nothing failed in 6
    CHECK_FALSE(rest.resting(a, b));
    // A row that goes on rests longer: failures at 1, 2, 4 and now 7 (right after the rest of 2
    // the third gave) make a row of four, which rests 4 cleanups; the fifth, at 12, rests 8, the
    // longest.
    auto rests_through = [&](int first, int last) {  // the cleanups first..last, a and b resting in each
      for (int cleanup = first; cleanup <= last; ++cleanup) {
        CAPTURE(cleanup);
        rest.begin();
        CHECK(rest.resting(a, b));
      }
    };
    rest.failed(a, b);
    rests_through(8, 11);
    rest.begin();  // 12
    CHECK_FALSE(rest.resting(a, b));
    rest.failed(a, b);
    rests_through(13, 20);
    rest.begin();  // 21
    CHECK_FALSE(rest.resting(a, b));
    rest.begin();  // 22
    rest.begin();  // 23: tried at 21, but no failure since 12: the row ended, nothing rests
    rest.failed(a, b);
    rest.begin();  // 24: one failure in a new row
    CHECK_FALSE(rest.resting(a, b));
    free_mesh(mesh);
    mesh = test::make_icosphere(2, 1.0);
    CHECK_FALSE(has_memory(mesh));
    rest.begin();
    CHECK(has_memory(mesh));
    CHECK_FALSE(rest.resting(a, b));
  }
  CHECK_FALSE(has_memory(mesh));
  {
    // A mesh that comes with the property (another run's numbers): the first begin() drops them.
    OpenMesh::VPropHandleT<PatchRest::Failures> old;
    mesh.add_property(old, PatchRest::kName);
    mesh.property(old, a) = mesh.property(old, b) = PatchRest::Failures{1, 5};
    PatchRest rest(mesh);
    rest.begin();  // 1
    rest.begin();  // 2: a and b would rest with the old numbers
    CHECK_FALSE(rest.resting(a, b));
  }
  CHECK_FALSE(has_memory(mesh));
  {
    // The memory follows its vertices through garbage collection; new vertices start with none.
    PatchRest rest(mesh);
    rest.begin();
    const Vec3 pa = mesh.point(a), pb = mesh.point(b);
    rest.failed(a, b);
    rest.begin();
    rest.failed(a, b);
    rest.begin();
    const auto far = mesh.vertex_handle(static_cast<unsigned>(mesh.n_vertices() - 1));
    REQUIRE(far != a);
    REQUIRE(far != b);
    // Collapse an edge away from a and b, then renumber.
    OpenMesh::HalfedgeHandle gone;
    for (auto h : mesh.voh_range(far))
      if (mesh.to_vertex_handle(h) != a && mesh.to_vertex_handle(h) != b && mesh.is_collapse_ok(h)) gone = h;
    REQUIRE(gone.is_valid());
    const OpenMesh::VertexHandle remover = mesh.from_vertex_handle(gone);
    mesh.collapse(gone);
    collect_garbage(mesh);
    (void)remover;
    OpenMesh::VertexHandle na, nb;
    for (auto v : mesh.vertices()) {
      if (mesh.point(v) == pa) na = v;
      if (mesh.point(v) == pb) nb = v;
    }
    REQUIRE(na.is_valid());
    REQUIRE(nb.is_valid());
    CHECK(rest.resting(na, nb));
    const auto fresh = mesh.add_vertex(Vec3(9, 9, 9));
    CHECK_FALSE(rest.resting(na, fresh));
  }

  // In the cleanup: a thin jittered tube, whose edges no fix can all mend. Cleanups in a row with
  // the memory rest patches from the third on, each resting one from the budget; the mesh stays
  // valid and on the reference.
  std::mt19937 rng(11);
  std::normal_distribution<double> jitter(0.0, 0.05);
  const TriMesh tube = test::make_torus(70, 10, 7.0, 0.45);
  const ReferenceSurface reference(tube);
  TriMesh thin = test::make_torus(30, 4, 7.0, 0.45);
  for (auto v : thin.vertices()) thin.point(v) += Vec3(jitter(rng), jitter(rng), jitter(rng));
  project_onto_reference(thin, reference, 2);
  REQUIRE(test::check_mesh_valid(thin) == "");
  PatchRest rest(thin);
  CleanupOptions options;
  options.rest = &rest;
  options.patch_budget = 8;
  std::size_t rested = 0;
  for (int i = 0; i < 6; ++i) {
    CAPTURE(i);
    const CleanupCounts counts = interval_cleanup(thin, reference, 1.2, 1.8, 0.5, options);
    if (i < 2) CHECK(counts.rested == 0);
    CHECK(counts.patches + counts.rested <= options.patch_budget);
    rested += counts.rested;
    CHECK(counts.outside_after > 0);
    CHECK(test::check_mesh_valid(thin) == "");
    for (auto v : thin.vertices()) CHECK(test::brute_distance(tube, thin.point(v)) < 1e-6);
  }
  CHECK(rested > 0);
}
