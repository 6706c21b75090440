// Crossing faces (self_intersections.h) and the step that moves them apart (untangle.h): the
// detector against a brute-force test of every pair, the untangle on sheets folded through
// themselves.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <stop_token>
#include <utility>
#include <vector>

#include "remesh/crease_lines.h"
#include "remesh/geometry.h"
#include "remesh/reference_surface.h"
#include "remesh/self_intersections.h"
#include "remesh/untangle.h"
#include "support/mesh_generators.h"
#include "test_helpers.h"

using namespace remesh;

namespace {

using Pairs = std::vector<std::pair<unsigned, unsigned>>;

/// A point as a sortable key: vertices are matched by position where edits renumber them.
std::array<double, 3> key_of(const Vec3& p) { return {p[0], p[1], p[2]}; }

/// Every vertex's position as a key, sorted (for std::binary_search).
std::vector<std::array<double, 3>> sorted_points(const TriMesh& mesh) {
  std::vector<std::array<double, 3>> points;
  for (auto v : mesh.vertices()) points.push_back(key_of(mesh.point(v)));
  std::sort(points.begin(), points.end());
  return points;
}

/// Every pair of live faces sharing at most one vertex that triangles_cross, by testing all pairs.
Pairs brute_force_pairs(const TriMesh& mesh) {
  Pairs out;
  auto deleted = [&](unsigned f) { return mesh.status(mesh.face_handle(f)).deleted(); };
  for (unsigned i = 0; i < mesh.n_faces(); ++i)
    for (unsigned j = i + 1; j < mesh.n_faces(); ++j) {
      if (deleted(i) || deleted(j)) continue;
      OpenMesh::VertexHandle x[3], y[3];
      geom::face_vertices(mesh, mesh.face_handle(i), x);
      geom::face_vertices(mesh, mesh.face_handle(j), y);
      int shared = 0;
      for (auto u : x)
        for (auto w : y) shared += u == w;
      if (shared < 2 && triangles_cross(mesh.point(x[0]), mesh.point(x[1]), mesh.point(x[2]), mesh.point(y[0]),
                                        mesh.point(y[1]), mesh.point(y[2])))
        out.emplace_back(i, j);
    }
  return out;
}

/// Moves every vertex by a random offset of up to `amount` in each coordinate.
void jitter(TriMesh& mesh, double amount, std::mt19937& rng) {
  std::uniform_real_distribution<double> d(-amount, amount);
  for (auto v : mesh.vertices()) mesh.point(v) += Vec3(d(rng), d(rng), d(rng));
}

/// `reference` with the vertices within `radius` of a centre moved at random (seeded) by up to one
/// edge of the hex lattice across (1.5 in x and y) and 0.4 up or down: a crumpled patch.
TriMesh crumpled(const TriMesh& reference, const std::vector<Vec3>& centres, double radius, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> across(-1.5, 1.5), up(-0.4, 0.4);
  TriMesh mesh = reference;
  for (auto v : mesh.vertices())
    if (std::any_of(centres.begin(), centres.end(), [&](const Vec3& c) { return (reference.point(v) - c).norm() < radius; }))
      mesh.point(v) += Vec3(across(rng), across(rng), up(rng));
  return mesh;
}

/// Sign of the z component of every face normal, +1 or -1 (0 when they disagree or one is flat).
int facing(const TriMesh& mesh) {
  int sign = 0;
  for (auto f : mesh.faces()) {
    const double z = geom::face_normal(mesh, f)[2];
    const int s = z > 0 ? 1 : (z < 0 ? -1 : 0);
    if (s == 0 || (sign != 0 && s != sign)) return 0;
    sign = s;
  }
  return sign;
}

}  // namespace

TEST_CASE("triangles_cross tells crossing triangles from touching and separate ones", "[untangle]") {
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  // An edge of the second passes through the inside of the first.
  CHECK(triangles_cross(a, b, c, Vec3(0.5, 0.5, -1), Vec3(0.6, 0.5, 1), Vec3(0.5, 1.5, 1)));
  // The same lifted away.
  CHECK_FALSE(triangles_cross(a, b, c, Vec3(0.5, 0.5, 4), Vec3(0.6, 0.5, 6), Vec3(0.5, 1.5, 6)));
  // A common corner, and the opposite edge of the second through the first: a fold inside a star.
  CHECK(triangles_cross(a, b, c, a, Vec3(1, 0.5, -1), Vec3(0.5, 1, 1)));
  // A common corner, the second pointing away: they touch at the corner only.
  CHECK_FALSE(triangles_cross(a, b, c, a, Vec3(-1, -1, 1), Vec3(-1, 0, -1)));
  // A common edge never counts, even folded flat onto each other.
  CHECK_FALSE(triangles_cross(a, b, c, a, b, Vec3(0.5, 0.5, 0)));
  // In one plane (exactly: a CAD model's flat face), insides that overlap count: a corner inside
  // the other, edges crossing, one inside the other along its edges, a common corner with the
  // second turned into the first (a fold within the plane).
  CHECK(triangles_cross(a, b, c, Vec3(0.5, 0.5, 0), Vec3(3, 0.5, 0), Vec3(3, 3, 0)));
  CHECK(triangles_cross(a, b, c, Vec3(1, -1, 0), Vec3(1, 3, 0), Vec3(3, 1, 0)));
  CHECK(triangles_cross(a, b, c, Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)));
  CHECK(triangles_cross(a, b, c, a, Vec3(1, 0.2, 0), Vec3(3, 3, 0)));
  // ... also where only touching contacts bound the overlap and neither centroid is inside the
  // other (found in review): edges along edges, and a common corner.
  CHECK(triangles_cross(a, b, c, Vec3(1, 0, 0), Vec3(4, 0, 0), Vec3(1, 1, 0)));
  CHECK(triangles_cross(a, b, c, a, Vec3(1.5, 0.5, 0), Vec3(3, -1, 0)));
  // ... and the same triangles lifted off the plane by a little do not, nor do coplanar ones that
  // only touch: along an edge, at a corner, or a corner on an edge.
  CHECK_FALSE(triangles_cross(a, b, c, Vec3(0.5, 0.5, 1e-9), Vec3(3, 0.5, 1e-9), Vec3(3, 3, 1e-9)));
  CHECK_FALSE(triangles_cross(a, b, c, b, c, Vec3(2, 2, 0)));
  CHECK_FALSE(triangles_cross(a, b, c, a, Vec3(-1, 0, 0), Vec3(0, -1, 0)));
  CHECK_FALSE(triangles_cross(a, b, c, Vec3(1, 1, 0), Vec3(2, 2, 0), Vec3(3, 1, 0)));
  CHECK_FALSE(triangles_cross(a, b, c, Vec3(3, 0, 0), Vec3(4, 0, 0), Vec3(3, 1, 0)));
  // The answer does not depend on the order of the triangles or of their corners.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-1, 1);
  int crossing = 0;
  for (int k = 0; k < 2000; ++k) {
    Vec3 p[6];
    for (auto& q : p) q = Vec3(d(rng), d(rng), d(rng));
    const bool x = triangles_cross(p[0], p[1], p[2], p[3], p[4], p[5]);
    CHECK(x == triangles_cross(p[3], p[4], p[5], p[0], p[1], p[2]));
    CHECK(x == triangles_cross(p[1], p[2], p[0], p[5], p[3], p[4]));
    CHECK(x == triangles_cross(p[0], p[2], p[1], p[3], p[5], p[4]));
    crossing += x;
  }
  CHECK(crossing > 100);  // the random triangles do cross often
  // The same in one plane (z = 0), where the orientation tests are exactly zero.
  int overlapping = 0;
  for (int k = 0; k < 2000; ++k) {
    Vec3 p[6];
    for (auto& q : p) q = Vec3(d(rng), d(rng), 0);
    const bool x = triangles_cross(p[0], p[1], p[2], p[3], p[4], p[5]);
    CHECK(x == triangles_cross(p[3], p[4], p[5], p[0], p[1], p[2]));
    CHECK(x == triangles_cross(p[1], p[2], p[0], p[5], p[3], p[4]));
    CHECK(x == triangles_cross(p[0], p[2], p[1], p[3], p[5], p[4]));
    overlapping += x;
  }
  CHECK(overlapping > 100);
}

TEST_CASE("triangles_cross finds no crossing among the pieces of flat faces split at rounded midpoints",
          "[untangle]") {
  // Two triangles sharing an edge, in a random plane, each split 1-to-4 at its edges' midpoints:
  // eight pieces of one flat surface, which touch but never cross. The midpoints are rounded, so
  // the pieces are coplanar but for rounding, where the orientation tests' signs are noise (the
  // test took 91 pairs of eight.off split twice for crossings, 296 of nefertiti split once; CGAL's
  // exact test none). A piece tilted through the face at a small angle still crosses it: the
  // middle piece with one corner lifted and one lowered by a millionth of the face's size.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-100.0, 100.0), u(0.0, 1.0);
  int pairs = 0;
  for (int trial = 0; trial < 300; ++trial) {
    INFO("trial " << trial);
    const Vec3 a(d(rng), d(rng), d(rng)), b(d(rng), d(rng), d(rng)), c(d(rng), d(rng), d(rng));
    const Vec3 e = a + (0.2 + 0.6 * u(rng)) * (b - a) - (0.3 + 0.7 * u(rng)) * (c - a);  // across ab from c
    std::vector<std::array<Vec3, 3>> pieces;
    auto split = [&](const Vec3& p, const Vec3& q, const Vec3& r) {
      const Vec3 pq = 0.5 * (p + q), qr = 0.5 * (q + r), rp = 0.5 * (r + p);
      pieces.push_back({p, pq, rp});
      pieces.push_back({pq, q, qr});
      pieces.push_back({rp, qr, r});
      pieces.push_back({pq, qr, rp});
    };
    split(a, b, c);
    split(b, a, e);
    for (std::size_t i = 0; i < pieces.size(); ++i)
      for (std::size_t j = i + 1; j < pieces.size(); ++j) {
        const auto &x = pieces[i], &y = pieces[j];
        CHECK_FALSE(triangles_cross(x[0], x[1], x[2], y[0], y[1], y[2]));
        ++pairs;
      }
    const auto& middle = pieces[3];
    const Vec3 lift = 1e-6 * ((b - a) % (c - a)).normalized() * (b - a).norm();
    CHECK(triangles_cross(a, b, c, middle[0] + lift, middle[1] - lift, middle[2]));
  }
  CHECK(pairs == 300 * 28);
}

TEST_CASE("find_self_intersections finds the pairs a brute-force test finds", "[untangle]") {
  std::mt19937 rng(11);
  struct Case {
    const char* name;
    TriMesh mesh;
    double jitter;
  };
  std::vector<Case> cases;
  cases.push_back({"sphere, clean", test::make_icosphere(3, 10.0), 0.0});
  cases.push_back({"sphere, crumpled", test::make_icosphere(3, 10.0), 1.5});
  cases.push_back({"torus, crumpled", test::make_torus(40, 12, 3.0, 1.0), 0.25});
  cases.push_back({"double torus, crumpled", test::make_double_torus(1.0, 2), 0.3});
  {
    // Faces of very different sizes: two large triangles through a sphere and through each other
    // (the detector treats faces far above the usual size apart).
    TriMesh m = test::make_icosphere(3, 10.0);
    auto add = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
      m.add_face(m.add_vertex(a), m.add_vertex(b), m.add_vertex(c));
    };
    add(Vec3(-30, -20, 0.5), Vec3(30, -20, -0.5), Vec3(0, 30, 0.3));
    add(Vec3(0.2, -25, -25), Vec3(-0.3, 25, -25), Vec3(0.1, 0, 30));
    cases.push_back({"sphere with two large triangles through it", std::move(m), 0.3});
  }
  for (auto& c : cases) {
    INFO(c.name);
    jitter(c.mesh, c.jitter, rng);
    const Pairs expected = brute_force_pairs(c.mesh);
    CHECK(find_self_intersections(c.mesh, 1) == expected);
    CHECK(find_self_intersections(c.mesh, 2) == expected);
    if (c.jitter == 0) {
      CHECK(expected.empty());
      continue;
    }
    CHECK(expected.size() > 10);
    // With a region: the pairs with a face whose bounding sphere meets it.
    const FaceSpheres spheres = face_spheres(c.mesh);
    for (int k = 0; k < 5; ++k) {
      const Vec3 at = c.mesh.point(c.mesh.vertex_handle(static_cast<unsigned>(k * 37 % c.mesh.n_vertices())));
      const Box box{at - Vec3(1, 1, 1), at + Vec3(1, 2, 0.5)};
      Pairs near;
      for (const auto& [f, g] : expected)
        if (sphere_meets(box, spheres.centres[f], spheres.radii[f]) ||
            sphere_meets(box, spheres.centres[g], spheres.radii[g]))
          near.emplace_back(f, g);
      CHECK(find_self_intersections(c.mesh, 2, &box) == near);
    }
  }
}

TEST_CASE("lies_over_itself tells a surface stacked on itself from crossing and clean ones", "[untangle]") {
  std::mt19937 rng(5);
  TriMesh crumpled = test::make_icosphere(3, 10.0);
  jitter(crumpled, 1.5, rng);
  REQUIRE(find_self_intersections(crumpled, 1).size() > 100);
  TriMesh torus = test::make_torus(40, 12, 3.0, 1.0);
  jitter(torus, 0.25, rng);
  for (unsigned threads : {1u, 2u}) {
    INFO(threads << " threads");
    // Faces through each other here and there, however many: not layered, and the search that
    // tells finds every crossing pair.
    CHECK_FALSE(lies_over_itself(test::make_icosphere(3, 10.0), threads));
    CHECK_FALSE(lies_over_itself(crumpled, threads));
    CHECK_FALSE(lies_over_itself(torus, threads));
    for (const TriMesh* m : {&crumpled, &torus}) {
      const auto found = find_self_intersections_unless_layered(*m, threads);
      REQUIRE(found);
      CHECK(*found == brute_force_pairs(*m));
    }
    // A sphere four times at one place: each face over three others, about 4 x 7 overlapping
    // spheres a face, under the limit of 64. Sixteen times: over it.
    CHECK_FALSE(lies_over_itself(test::stacked_copies(test::make_icosphere(3, 10.0), 4), threads));
    CHECK(lies_over_itself(test::stacked_copies(test::make_icosphere(3, 10.0), 16), threads));
    CHECK_FALSE(find_self_intersections_unless_layered(test::stacked_copies(test::make_icosphere(3, 10.0), 16), threads));
    // Sixteen copies side by side, apart: not layered.
    TriMesh apart = test::stacked_copies(test::make_icosphere(3, 10.0), 16, Vec3(25, 0, 0));
    CHECK_FALSE(lies_over_itself(apart, threads));
  }
}

TEST_CASE("find_self_intersections passes over deleted faces", "[untangle]") {
  // The untangling's collapses leave deleted faces until its end (untangle.cpp): the search must
  // neither report them nor miss a pair of live faces, with or without a region; the same pairs,
  // renumbered, after the garbage collection.
  std::mt19937 rng(5);
  TriMesh mesh = test::make_icosphere(3, 10.0);
  jitter(mesh, 1.5, rng);
  const std::size_t before = brute_force_pairs(mesh).size();
  REQUIRE(before > 10);
  std::size_t collapsed = 0;
  for (auto h : mesh.halfedges()) {
    if (collapsed == 40) break;
    if (mesh.status(h).deleted() || h.idx() % 7 != 0 || !mesh.is_collapse_ok(h)) continue;
    mesh.collapse(h);
    ++collapsed;
  }
  REQUIRE(collapsed == 40);
  const Pairs expected = brute_force_pairs(mesh);
  CHECK(find_self_intersections(mesh, 1) == expected);
  CHECK(find_self_intersections(mesh, 2) == expected);
  const Box box{Vec3(-12, -12, -3), Vec3(12, 12, 4)};
  const FaceSpheres spheres = face_spheres(mesh);
  Pairs near;
  for (const auto& [f, g] : expected)
    if (sphere_meets(box, spheres.centres[f], spheres.radii[f]) || sphere_meets(box, spheres.centres[g], spheres.radii[g]))
      near.emplace_back(f, g);
  CHECK(near.size() < expected.size());
  CHECK(find_self_intersections(mesh, 2, &box) == near);
  // Renumbered by the collection: the same pairs as a search of the collected mesh.
  std::vector<OpenMesh::FaceHandle> faces;
  for (const auto& [f, g] : expected) faces.emplace_back(static_cast<int>(f)), faces.emplace_back(static_cast<int>(g));
  collect_garbage(mesh, faces);
  Pairs renumbered;
  for (std::size_t i = 0; i < expected.size(); ++i)
    renumbered.emplace_back(std::min(faces[2 * i].idx(), faces[2 * i + 1].idx()),
                            std::max(faces[2 * i].idx(), faces[2 * i + 1].idx()));
  std::sort(renumbered.begin(), renumbered.end());
  CHECK(find_self_intersections(mesh, 1) == renumbered);
}

TEST_CASE("untangle removes the crossings of crumpled patches, folds nothing new, leaves the rest alone",
          "[untangle]") {
  // A flat hex lattice (every edge 1.5, inside [1.2, 1.8]) is the reference. In the mesh a patch is
  // crumpled at random (vertices within 3 of a point moved by up to one edge across and 0.4 up or
  // down), so that a few rings of faces lie folded through each other, as on nefertiti's base.
  // Crossing faces need faces turned upside down: a surface whose faces all face up is a height
  // field, which cannot cross itself.
  const TriMesh reference = test::make_hex_lattice_patch(20, 20, 1.5);
  const ReferenceSurface surface(reference);
  const int side = facing(reference);
  REQUIRE(side != 0);
  const Vec3 centre(15, 13, 0);
  int tangled = 0, by_moves = 0, by_flattening = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    INFO("seed " << seed);
    TriMesh mesh = crumpled(reference, {centre}, 3, seed);
    const std::size_t before = find_self_intersections(mesh, 1).size();
    if (before == 0) continue;  // this draw did not tangle; `tangled` counts those that did
    ++tangled;
    auto upside_down = [&] {
      std::size_t n = 0;
      for (auto f : mesh.faces()) n += geom::face_normal(mesh, f)[2] * side <= 0;
      return n;
    };
    const std::size_t away = upside_down();
    const UntangleCounts counts = untangle(mesh, surface, 1.2, 1.8, 1);
    CHECK(counts.pairs_before == before);
    CHECK(counts.left.empty());
    CHECK(find_self_intersections(mesh, 1).empty());
    CHECK(upside_down() <= away);
    if (upside_down() == 0) CHECK(test::check_mesh_valid(mesh) == "");
    (counts.flattened > 0 ? by_flattening : by_moves) += 1;
    // Near the reference plane (within the flattening limit, e_min)...
    for (auto v : mesh.vertices()) CHECK(std::abs(mesh.point(v)[2]) <= 1.2);
    // ...and the lattice far from the tangle untouched, its boundary included: each such point of
    // the reference is still a vertex, where it was (looked up by position: a collapse renumbers).
    const std::vector<std::array<double, 3>> points = sorted_points(mesh);
    for (auto v : reference.vertices())
      if ((reference.point(v) - centre).norm() > 12 || reference.is_boundary(v))
        CHECK(std::binary_search(points.begin(), points.end(), key_of(reference.point(v))));
  }
  CHECK(tangled >= 6);
  // Both means were needed: some tangles yield to vertex moves, others only to a flattened disk.
  CHECK(by_moves > 0);
  CHECK(by_flattening > 0);
}

TEST_CASE("untangle flattens tangles side by side in one pass and reports what is left exactly", "[untangle]") {
  // Three patches of the hex lattice crumpled as above, their centres 5 apart, so that one
  // flattening pass flattens several disks, each beside faces the ones before it moved. It indexes
  // the faces once; each disk's faces are reshaped (returned by every query wherever they are),
  // and single moves bound how far the rest have drifted (untangle.cpp, kReindexDrift). (With
  // centres 4.5 apart, 5 of 60 draws keep a crossing pair, the same with an index rebuilt after
  // every disk.) Given the crossing pairs (as equalize's second round gives them), untangle does
  // the same as when it searches for them itself.
  const TriMesh reference = test::make_hex_lattice_patch(24, 20, 1.5);
  const ReferenceSurface surface(reference);
  const std::vector<Vec3> centres{Vec3(11, 13, 0), Vec3(16, 13, 0), Vec3(21, 13, 0)};
  int tangled = 0, flattened = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    INFO("seed " << seed);
    TriMesh mesh = crumpled(reference, centres, 2.5, seed);
    if (find_self_intersections(mesh, 1).empty()) continue;
    ++tangled;
    TriMesh given = mesh;
    const UntangleCounts counts = untangle(mesh, surface, 1.2, 1.8, 1);
    CHECK(counts.left == find_self_intersections(mesh, 1));
    const UntangleCounts again = untangle(given, surface, 1.2, 1.8, 2, nullptr, find_self_intersections(given, 1));
    CHECK(again.moved == counts.moved);
    CHECK(sorted_points(given) == sorted_points(mesh));
    flattened += counts.flattened > 0;
    CHECK(counts.left.empty());
    CHECK(brute_force_pairs(mesh).empty());
    for (auto v : mesh.vertices()) CHECK(std::abs(mesh.point(v)[2]) <= 1.2);
  }
  CHECK(tangled >= 8);
  CHECK(flattened >= 4);
}

TEST_CASE("untangle makes no pair of adjacent faces sharper than an edit may", "[untangle]") {
  // A rippled reference (not aligned with the edges), crumpled at random as above: whatever the
  // untangle moves, an edge whose faces met at less than kMinAdjacentCos before may not be sharper
  // after, and none may become that sharp. Over many draws some tangles are flattened into disks
  // on the ripples, where faces of the disk could otherwise fold against each other.
  using geom::kMinAdjacentCos;
  // Each interior edge's cosine by its ends' positions: flips and collapses change which vertices
  // an edge joins and renumber the edges, so an edge is the same edge only by where its ends are.
  using Ends = std::array<std::array<double, 3>, 2>;
  auto edge_cos = [](const TriMesh& m) {
    std::map<Ends, double> cos;
    for (auto e : m.edges()) {
      if (m.is_boundary(e)) continue;
      const auto h = m.halfedge_handle(e, 0);
      const Vec3 a = geom::face_normal(m, m.face_handle(h)), b = geom::face_normal(m, m.opposite_face_handle(h));
      Ends ends{key_of(m.point(m.from_vertex_handle(h))), key_of(m.point(m.to_vertex_handle(h)))};
      std::sort(ends.begin(), ends.end());
      cos[ends] = (a | b) / (a.norm() * b.norm());
    }
    return cos;
  };
  const Vec3 centre(15, 13, 0);
  int flattened = 0;
  for (double amplitude : {0.6, 1.2}) {
    TriMesh reference = test::make_hex_lattice_patch(20, 20, 1.5);
    for (auto v : reference.vertices()) {
      Vec3& p = reference.point(v);
      p[2] = amplitude * std::sin(2.1 * p[0] + 0.7 * p[1]);
    }
    const ReferenceSurface surface(reference);
    for (unsigned seed = 1; seed <= 40; ++seed) {
      INFO("amplitude " << amplitude << ", seed " << seed);
      std::mt19937 rng(seed);
      std::uniform_real_distribution<double> across(-1.5, 1.5), up(-0.4, 0.4);
      TriMesh mesh = reference;
      for (auto v : mesh.vertices())
        if ((reference.point(v) - centre).norm() < 3.5) mesh.point(v) += Vec3(across(rng), across(rng), up(rng));
      const std::map<Ends, double> before = edge_cos(mesh);
      double sharpest_before = 1;
      for (const auto& [ends, c] : before) sharpest_before = std::min(sharpest_before, c);
      const std::size_t pairs = find_self_intersections(mesh, 1).size();
      const UntangleCounts counts = untangle(mesh, surface, 1.2, 1.8, 1);
      CHECK(counts.left.size() <= pairs);
      CHECK(counts.left == find_self_intersections(mesh, 1));
      flattened += counts.flattened > 0;
      // An edge that was there before is not sharper than then (or than the limit); an edge that a
      // flip or collapse made is not sharper than the sharpest before (or than the limit).
      for (const auto& [ends, c] : edge_cos(mesh)) {
        const auto was = before.find(ends);
        CHECK(c >= std::min(kMinAdjacentCos, was == before.end() ? sharpest_before : was->second) - 1e-12);
      }
    }
  }
  CHECK(flattened >= 5);
}

namespace {

/// A closed finger along z: `rings` rings of `sectors` vertices of radius `radius`, `spacing`
/// apart (staggered by half a sector, so that no three corners lie on a line), capped by an apex
/// `spacing` above the last ring and a centre vertex `spacing` below the first.
TriMesh make_finger(double radius, double spacing, int rings, int sectors) {
  TriMesh m;
  const double pi = std::acos(-1.0);
  std::vector<std::vector<OpenMesh::VertexHandle>> ring(rings);
  for (int i = 0; i < rings; ++i)
    for (int k = 0; k < sectors; ++k) {
      const double a = 2 * pi * (k + 0.5 * (i % 2)) / sectors;
      ring[i].push_back(m.add_vertex(Vec3(radius * std::cos(a), radius * std::sin(a), i * spacing)));
    }
  const auto apex = m.add_vertex(Vec3(0, 0, rings * spacing)), base = m.add_vertex(Vec3(0, 0, -spacing));
  for (int k = 0; k < sectors; ++k) {
    const int l = (k + 1) % sectors;
    for (int i = 0; i + 1 < rings; ++i) {
      // Rings alternate their stagger: the diagonal runs to the nearer corner of the next ring.
      if (i % 2 == 0) {
        m.add_face(ring[i][k], ring[i][l], ring[i + 1][k]);
        m.add_face(ring[i][l], ring[i + 1][l], ring[i + 1][k]);
      } else {
        m.add_face(ring[i][k], ring[i + 1][l], ring[i + 1][k]);
        m.add_face(ring[i][k], ring[i][l], ring[i + 1][l]);
      }
    }
    m.add_face(ring[rings - 1][k], ring[rings - 1][l], apex);
    m.add_face(ring[0][l], ring[0][k], base);
  }
  return m;
}

}  // namespace

TEST_CASE("untangle never cuts a thin protrusion off: the finger's tip stays near the mesh", "[untangle]") {
  // A finger 0.5 thick and 9 long is the reference. In the mesh its tip is crumpled at random
  // (vertices within 2 of the apex moved by up to 0.5 in each direction) so that faces cross. A
  // disk whose rim girds the finger below the tangle would flatten into a membrane across the
  // finger, within e_min of its sides, with the tip gone: untangle may leave crossings, but every
  // vertex position it had stays within e_min (1.2) of the mesh, the apex's included.
  const TriMesh reference = make_finger(0.5, 0.75, 12, 8);
  const ReferenceSurface surface(reference);
  REQUIRE(test::check_mesh_valid(reference) == "");
  const Vec3 apex(0, 0, 9.0);
  int tangled = 0, flattened = 0, collapsed = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    INFO("seed " << seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> d(-0.5, 0.5);
    TriMesh mesh = reference;
    for (auto v : mesh.vertices())
      if ((reference.point(v) - apex).norm() < 2.0) mesh.point(v) += Vec3(d(rng), d(rng), d(rng));
    if (find_self_intersections(mesh, 1).empty()) continue;
    ++tangled;
    const TriMesh before = mesh;
    const UntangleCounts counts = untangle(mesh, surface, 1.2, 1.8, 1);
    CHECK(counts.left == find_self_intersections(mesh, 1));
    flattened += counts.flattened > 0;
    collapsed += counts.collapsed > 0;
    // A collapse removes a vertex and keeps the topology (a closed sphere: V - E + F = 2).
    CHECK(mesh.n_vertices() + counts.collapsed == before.n_vertices());
    CHECK(static_cast<long>(mesh.n_vertices()) - static_cast<long>(mesh.n_edges()) + static_cast<long>(mesh.n_faces()) == 2);
    // Every face a triangle, none degenerate, no element deleted, every vertex manifold (the
    // crumpled faces may fold: no fold test).
    CHECK(test::check_mesh_valid(mesh, 1e-12, 1.0) == "");
    for (auto v : before.vertices()) CHECK(test::brute_distance(mesh, before.point(v)) <= 1.2 + 1e-9);
    CHECK(test::brute_distance(mesh, apex) <= 1.2);
  }
  CHECK(tangled >= 10);
  // Collapses mend some of these tangles (measured: in 20 of the 27 draws that tangled), and keep
  // the tip: the distances above.
  CHECK(collapsed >= 5);
  // A disk that keeps the finger is still flattened (measured: 1 of 27 draws; without the rule, 16
  // were, their tips cut off by 1.6 to 3.8).
  CHECK(flattened > 0);
}

TEST_CASE("untangle's flips and collapses keep the topology and the boundary", "[untangle]") {
  // The rippled reference of the test above, crumpled at random. Flips change which vertices a
  // face joins; collapses remove a vertex onto a neighbour that stays where it is. Neither changes
  // the Euler characteristic or the boundary; flips and vertex moves take no edge out of
  // [e_min, e_max] (a collapse may leave a short one, a flattened disk any), and each kept edit
  // lowers the crossings, so the pairs left are never more.
  auto outside = [](const TriMesh& m) {
    std::size_t n = 0;
    for (auto e : m.edges()) {
      const double l = m.calc_edge_length(e);
      n += l < 1.2 || l > 1.8;
    }
    return n;
  };
  auto euler = [](const TriMesh& m) {
    return static_cast<long>(m.n_vertices()) - static_cast<long>(m.n_edges()) + static_cast<long>(m.n_faces());
  };
  auto boundary = [](const TriMesh& m) {
    std::vector<std::array<double, 3>> points;
    for (auto v : m.vertices())
      if (m.is_boundary(v)) points.push_back(key_of(m.point(v)));
    std::sort(points.begin(), points.end());
    return points;
  };
  const Vec3 centre(15, 13, 0);
  TriMesh reference = test::make_hex_lattice_patch(20, 20, 1.5);
  for (auto v : reference.vertices()) {
    Vec3& p = reference.point(v);
    p[2] = 1.2 * std::sin(2.1 * p[0] + 0.7 * p[1]);
  }
  const ReferenceSurface surface(reference);
  int flipped = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    INFO("seed " << seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> across(-1.5, 1.5), up(-0.4, 0.4);
    TriMesh mesh = reference;
    for (auto v : mesh.vertices())
      if ((reference.point(v) - centre).norm() < 3.5) mesh.point(v) += Vec3(across(rng), across(rng), up(rng));
    const std::size_t pairs = find_self_intersections(mesh, 1).size(), out = outside(mesh);
    const TriMesh before = mesh;
    const UntangleCounts counts = untangle(mesh, surface, 1.2, 1.8, 1);
    CHECK(euler(mesh) == euler(before));
    CHECK(boundary(mesh) == boundary(before));
    CHECK(mesh.n_vertices() + counts.collapsed == before.n_vertices());
    CHECK(counts.left.size() <= pairs);
    CHECK(counts.left == find_self_intersections(mesh, 1));
    if (counts.flattened == 0 && counts.collapsed == 0) CHECK(outside(mesh) <= out);
    flipped += counts.flipped > 0;
    // A valid mesh whatever the edits: no deleted element left, triangles only, no degenerate face
    // (folds are allowed: the crumpled lattice has turned faces the untangling may leave).
    CHECK(test::check_mesh_valid(mesh, 1e-12, 1.0) == "");
  }
  // Measured: flips were kept in 28 of the 40 draws (collapses in none: on this lattice the vertex
  // moves and flips mend what a collapse could; the finger test above has them).
  CHECK(flipped >= 10);
}

TEST_CASE("untangle with the crease guard leaves a box's edges where they are", "[untangle]") {
  // A box of 12 unit cells, its 12 edges creases (crease_lines.h). Near the middle of one edge the
  // vertices off the edges are crumpled: moved in their face's plane by up to 2 (across the edge,
  // some of them) and in or out by up to 0.8, so that faces at the crease cross each other and the
  // faces across it. The untangling moves the crease's own vertices too (they are corners of
  // crossing faces): without the guard it takes the box's edge out of the surface, with it the
  // edge stays on the mesh. Seed 166 crumples a crease edge's two faces flat: the guard's test of
  // their angle would let the edge be flipped (0.014 off; found by a review).
  const int n = 12;
  const TriMesh box = test::make_box(n);
  const ReferenceSurface surface(box);
  const CreaseLines lines(box);
  REQUIRE_FALSE(lines.empty());
  const CreaseGuard guard(lines, 1e-9);
  const Vec3 centre(6, 0, 0);  // on the edge y = z = 0
  // The farthest point of that edge (every 0.05) from the mesh's faces near it.
  auto edge_off = [&](const TriMesh& mesh) {
    double worst = 0;
    for (int k = 0; k <= 20 * n; ++k) {
      const Vec3 p(k / 20.0, 0, 0);
      double best = 1e300;
      for (auto f : mesh.faces()) {
        Vec3 q[3];
        int i = 0;
        for (auto v : mesh.fv_range(f)) q[i++] = mesh.point(v);
        if ((q[0] - p).norm() > 4) continue;  // no face of the crumpled patch reaches that far
        best = std::min(best, (geom::closest_point_on_triangle(p, q[0], q[1], q[2]) - p).norm());
      }
      worst = std::max(worst, best);
    }
    return worst;
  };
  int tangled = 0, cut_without = 0;
  std::size_t crossings_before = 0, crossings_after = 0, crossings_after_guard = 0, crossings_after_both = 0;
  for (unsigned seed = 1; seed <= 170; ++seed) {
    INFO("seed " << seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> along(-2, 2), off(-0.8, 0.8);
    TriMesh mesh = box;
    for (auto v : mesh.vertices()) {
      Vec3& p = mesh.point(v);
      if ((p - centre).norm() > 2.5 || guard.on(p)) continue;
      const int normal_axis = p[1] == 0 ? 1 : 2;  // the face y = 0 or z = 0
      for (int axis = 0; axis < 3; ++axis) p[axis] += axis == normal_axis ? off(rng) : along(rng);
    }
    const std::size_t before = find_self_intersections(mesh, 1).size();
    if (before == 0) continue;
    ++tangled;
    TriMesh unguarded = mesh, both = mesh;
    const UntangleCounts counts = untangle(mesh, surface, 0.9, 1.5, 1, &guard);
    CHECK(counts.pairs_before == before);
    CHECK(edge_off(mesh) < 1e-9);
    crossings_before += before;
    const std::size_t left = find_self_intersections(mesh, 1).size();
    crossings_after += left;
    // The crease rule first, then free moves for what it leaves (equalize with keep_creases), on
    // the first 40 tangles.
    if (tangled <= 40) {
      const UntangleCounts second = untangle_creases_first(both, surface, 0.9, 1.5, 1, &guard);
      CHECK(second.pairs_before == before);
      CHECK(second.left.size() == find_self_intersections(both, 1).size());
      crossings_after_both += second.left.size();
      crossings_after_guard += left;
    }
    if (tangled <= 16) {
      untangle(unguarded, surface, 0.9, 1.5, 1);
      cut_without += edge_off(unguarded) > 1e-3;
    }
  }
  CHECK(tangled >= 80);
  CHECK(cut_without > 0);                          // the guard is what keeps the edge
  CHECK(4 * crossings_after < 3 * crossings_before);  // and it still untangles (about half of them)
  CHECK(crossings_after_both < crossings_after_guard);  // the free pass mends more of what is left
}

TEST_CASE("untangle stops between edits when asked, and within its budget on a mesh crumpled all over",
          "[untangle]") {
  const TriMesh reference = test::make_hex_lattice_patch(20, 20, 1.5);
  const ReferenceSurface surface(reference);
  // A patch crumpled as above: with the stop asked for before it starts, nothing moves.
  TriMesh patch = crumpled(reference, {Vec3(15, 13, 0)}, 3, 2);
  const Pairs before = find_self_intersections(patch, 1);
  REQUIRE_FALSE(before.empty());
  const TriMesh given = patch;
  std::stop_source stop;
  stop.request_stop();
  const UntangleCounts stopped = untangle(patch, surface, 1.2, 1.8, 1, nullptr, std::nullopt, stop.get_token());
  CHECK(stopped.cut_short);
  CHECK(stopped.moved == 0);
  CHECK(stopped.left == before);
  CHECK(sorted_points(patch) == sorted_points(given));
  // Not asked, the same patch is untangled within its budget.
  const UntangleCounts done = untangle(patch, surface, 1.2, 1.8, 1);
  CHECK_FALSE(done.cut_short);
  CHECK(done.left.empty());
  CHECK(done.work <= untangle_budget(patch.n_faces()));
  // Every vertex of a larger lattice moved by up to two edges across and up: thousands of crossing
  // pairs, more than the budget lets it mend. It stops there, with the mesh whole: every face
  // valid, the pairs it reports left the ones there are.
  const TriMesh wide = test::make_hex_lattice_patch(40, 40, 1.5);
  const ReferenceSurface wide_surface(wide);
  TriMesh mesh = wide;
  std::mt19937 rng(5);
  jitter(mesh, 3.0, rng);
  const std::size_t tangled = find_self_intersections(mesh, 1).size();
  CAPTURE(tangled);
  REQUIRE(tangled > 1000);
  const UntangleCounts counts = untangle(mesh, wide_surface, 1.2, 1.8, 1);
  CHECK(counts.cut_short);
  // The edit under way when the budget ran out finishes: past it by at most one edit's tests (a
  // vertex move's candidates, each against the faces near it), far below the work it would take.
  CHECK(counts.work > untangle_budget(mesh.n_faces()));
  CHECK(counts.work < 2 * untangle_budget(mesh.n_faces()));
  CHECK(mesh.n_vertices() > 0);
  CHECK(counts.left == find_self_intersections(mesh, 1));
  CHECK(counts.left.size() < tangled);
}
