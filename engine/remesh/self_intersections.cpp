#include "remesh/self_intersections.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/parallel.h"
#include "remesh/geometry.h"

namespace remesh {

namespace {

/// Six times the signed volume of (a, b, c, d): positive when d lies on the side of (a, b, c)
/// its normal points to; 0 when rounding could have decided its sign. The filter is Shewchuk's
/// for orient3d ("Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
/// Predicates", 1997: the computed value is within (7 + 56 eps) eps of the permanent, the same
/// expression over absolute values, of the exact one), with a margin. Without it, four coplanar
/// points gave signs by rounding: nefertiti split 1-to-4 at its edges' midpoints had 296 crossing
/// pairs by this test and none by CGAL's exact one (meshqa), each split face's pieces meeting at a
/// rounded midpoint; such pairs now go to the coplanar test, which finds them touching.
constexpr double kOrient3dBound = 1e-15;
double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 u = b - a, v = c - a, w = d - a;
  const double det = (u % v) | w;
  const double permanent = (std::abs(u[0] * v[1]) + std::abs(u[1] * v[0])) * std::abs(w[2]) +
                           (std::abs(u[1] * v[2]) + std::abs(u[2] * v[1])) * std::abs(w[0]) +
                           (std::abs(u[2] * v[0]) + std::abs(u[0] * v[2])) * std::abs(w[1]);
  return std::abs(det) > kOrient3dBound * permanent ? det : 0.0;
}

/// Does segment pq pass through the inside of triangle abc (strictly: touching does not count)?
bool segment_crosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double sp = orient(a, b, c, p), sq = orient(a, b, c, q);
  if (!((sp > 0 && sq < 0) || (sp < 0 && sq > 0))) return false;
  const double u = orient(p, q, a, b), v = orient(p, q, b, c), w = orient(p, q, c, a);
  return (u > 0 && v > 0 && w > 0) || (u < 0 && v < 0 && w < 0);
}

/// Twice the signed area of (p, q, r) in the plane of axes i and j; 0 when rounding could have
/// decided its sign (Shewchuk's filter for orient2d, (3 + 16 eps) eps, with a margin).
constexpr double kOrient2dBound = 5e-16;
double orient2d(const Vec3& p, const Vec3& q, const Vec3& r, int i, int j) {
  const double left = (q[i] - p[i]) * (r[j] - p[j]), right = (q[j] - p[j]) * (r[i] - p[i]);
  const double det = left - right;
  return std::abs(det) > kOrient2dBound * (std::abs(left) + std::abs(right)) ? det : 0.0;
}

/// Is a line through an edge of t one that the whole of u lies on or beyond, on the side away
/// from t (in the plane of axes i and j)?
bool separates(const Vec3 t[3], const Vec3 u[3], int i, int j) {
  const double own = orient2d(t[0], t[1], t[2], i, j);
  for (int k = 0; k < 3; ++k) {
    const Vec3 &p = t[k], &q = t[(k + 1) % 3];
    bool all_beyond = true;
    for (int l = 0; l < 3 && all_beyond; ++l) {
      const double side = orient2d(p, q, u[l], i, j);
      all_beyond = own > 0 ? side <= 0 : side >= 0;
    }
    if (all_beyond) return true;
  }
  return false;
}

/// Do the insides of two triangles in one plane overlap? In the plane of the two axes the normal
/// leans on least, they do unless a line through an edge of one has the other wholly on or beyond
/// it (two convex polygons whose insides are apart are parted by such a line); touching along an
/// edge or at a corner leaves them apart.
bool coplanar_overlap(const Vec3 t[3], const Vec3 u[3], const Vec3& normal) {
  const Vec3 m(std::abs(normal[0]), std::abs(normal[1]), std::abs(normal[2]));
  const int drop = m[0] >= m[1] && m[0] >= m[2] ? 0 : (m[1] >= m[2] ? 1 : 2);
  const int i = (drop + 1) % 3, j = (drop + 2) % 3;
  return !separates(t, u, i, j) && !separates(u, t, i, j);
}

}  // namespace

Sphere face_sphere(const TriMesh& mesh, OpenMesh::FaceHandle f) {
  OpenMesh::VertexHandle c[3];
  geom::face_vertices(mesh, f, c);
  Sphere s{(mesh.point(c[0]) + mesh.point(c[1]) + mesh.point(c[2])) / 3.0, 0};
  for (auto v : c) s.radius = std::max(s.radius, (mesh.point(v) - s.centre).norm());
  return s;
}

FaceSpheres face_spheres(const TriMesh& mesh) {
  FaceSpheres s;
  s.centres.resize(mesh.n_faces());
  s.radii.resize(mesh.n_faces());
  s.corners.resize(mesh.n_faces());
  for (auto f : mesh.faces()) {
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(mesh, f, c);
    for (int k = 0; k < 3; ++k) s.corners[f.idx()][k] = c[k].idx();
    const Sphere sphere = face_sphere(mesh, f);
    s.centres[f.idx()] = sphere.centre;
    s.radii[f.idx()] = sphere.radius;
    s.largest = std::max(s.largest, sphere.radius);
  }
  return s;
}

namespace {

/// faces_cross for faces with corners x and y (vertex indices).
bool corners_cross(const TriMesh& mesh, const std::array<int, 3>& x, const std::array<int, 3>& y) {
  int shared = 0;
  for (int u : x)
    for (int w : y) shared += u == w;
  if (shared >= 2) return false;
  auto point = [&](int i) -> const Vec3& { return mesh.point(OpenMesh::VertexHandle(i)); };
  return triangles_cross(point(x[0]), point(x[1]), point(x[2]), point(y[0]), point(y[1]), point(y[2]));
}

std::array<int, 3> corners_of(const TriMesh& mesh, OpenMesh::FaceHandle f) {
  OpenMesh::VertexHandle c[3];
  geom::face_vertices(mesh, f, c);
  return {c[0].idx(), c[1].idx(), c[2].idx()};
}

}  // namespace

bool faces_cross(const TriMesh& mesh, OpenMesh::FaceHandle f, OpenMesh::FaceHandle g) {
  return corners_cross(mesh, corners_of(mesh, f), corners_of(mesh, g));
}

bool triangles_cross(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e, const Vec3& f) {
  const Vec3 t[3] = {a, b, c}, u[3] = {d, e, f};
  int shared_t = -1, shared_u = -1, shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (t[i] == u[j]) shared_t = i, shared_u = j, ++shared;
  if (shared >= 2) return false;
  // In one plane (every corner of each on the other's plane, within the rounding that orient()
  // allows, as on a CAD model's flat face, whose points the projection puts on it): the
  // orientation tests below are all zero, and overlapping insides, a fold within the plane, would
  // count as touching.
  const Vec3 nt = (b - a) % (c - a), nu = (e - d) % (f - d);
  if (nt.sqrnorm() > 0 && nu.sqrnorm() > 0 && orient(a, b, c, d) == 0 && orient(a, b, c, e) == 0 &&
      orient(a, b, c, f) == 0 && orient(d, e, f, a) == 0 && orient(d, e, f, b) == 0 && orient(d, e, f, c) == 0) {
    const Vec3 n(std::abs(nt[0]) + std::abs(nu[0]), std::abs(nt[1]) + std::abs(nu[1]), std::abs(nt[2]) + std::abs(nu[2]));
    return coplanar_overlap(t, u, n);
  }
  if (shared == 1) {
    // Both planes hold the line through the common corner s along which they meet; the part both
    // triangles hold, if any, starts at s and ends where it leaves one of them, through the edge
    // opposite s.
    const Vec3 &p = t[(shared_t + 1) % 3], &q = t[(shared_t + 2) % 3];
    const Vec3 &r = u[(shared_u + 1) % 3], &s = u[(shared_u + 2) % 3];
    return segment_crosses(p, q, d, e, f) || segment_crosses(r, s, a, b, c);
  }
  // Two triangles in general position meet along a segment whose ends lie on edges of them.
  for (int i = 0; i < 3; ++i) {
    if (segment_crosses(t[i], t[(i + 1) % 3], d, e, f)) return true;
    if (segment_crosses(u[i], u[(i + 1) % 3], a, b, c)) return true;
  }
  return false;
}

bool sphere_meets(const Box& box, const Vec3& centre, double radius, double grow) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double below = box.lo[k] - grow - centre[k], above = centre[k] - box.hi[k] - grow;
    const double d = std::max({below, above, 0.0});
    d2 += d * d;
  }
  // With a margin: for a sphere through a corner of the box, rounding can put the corner just
  // outside the sphere computed from it.
  const double reach = radius * (1 + 1e-9) + 1e-300;
  return d2 <= reach * reach;
}

namespace {

/// The broad phase of find_self_intersections: calls test(i, j, block) once for every pair of
/// `faces` whose bounding spheres overlap (and for a few more), from parallel blocks numbered
/// 0 .. out.size() - 1 (out is resized to hold one result vector per block). Once `halt` (when
/// given) is set, the blocks stop at their next face (a cell of faces stacked in place can hold
/// thousands).
/// A uniform grid with cells of side h, twice the 99th percentile of the radii: two faces whose
/// radii are at most h / 2 and whose spheres overlap have their centres within h of each other in
/// every coordinate, so in the same cell or in adjacent ones, and each pair of adjacent cells is
/// visited once. The few faces with a larger radius are tested against every cell within their
/// reach and against each other.
template <typename Test, typename Out>
void for_overlapping_spheres(const FaceSpheres& spheres, const std::vector<unsigned>& faces, unsigned threads,
                             Test&& test, std::vector<Out>& out, const std::atomic<bool>* halt = nullptr) {
  auto halted = [&] { return halt && halt->load(std::memory_order_relaxed); };
  const std::size_t n = faces.size();
  auto overlap = [&](unsigned i, unsigned j) {
    return spheres_overlap({spheres.centres[i], spheres.radii[i]}, {spheres.centres[j], spheres.radii[j]});
  };
  if (n == 0) {
    out.clear();
    return;
  }
  std::vector<double> radii(n);
  Vec3 lo = spheres.centres[faces[0]], hi = lo;
  for (std::size_t k = 0; k < n; ++k) {
    radii[k] = spheres.radii[faces[k]];
    lo.minimize(spheres.centres[faces[k]]);
    hi.maximize(spheres.centres[faces[k]]);
  }
  const auto p99 = radii.begin() + static_cast<std::ptrdiff_t>(n * 99 / 100);
  std::nth_element(radii.begin(), p99, radii.end());
  // At most 2^20 cells along an axis (keys of 21 bits per axis).
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  double h = std::max(2 * *p99, extent / (1 << 20));
  if (!(h > 0)) h = 1;
  auto coord = [&](double x, int axis) {
    return static_cast<std::int64_t>(std::clamp(std::floor((x - lo[axis]) / h), 0.0, double((1 << 21) - 1)));
  };
  auto key_of = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<std::uint64_t>(x) << 42 | static_cast<std::uint64_t>(y) << 21 | static_cast<std::uint64_t>(z);
  };
  auto cell_of = [](std::uint64_t key) {
    return std::array<std::int64_t, 3>{static_cast<std::int64_t>(key >> 42),
                                       static_cast<std::int64_t>(key >> 21 & 0x1FFFFF),
                                       static_cast<std::int64_t>(key & 0x1FFFFF)};
  };
  std::vector<std::pair<std::uint64_t, unsigned>> entries;
  std::vector<unsigned> big;
  entries.reserve(n);
  for (unsigned f : faces) {
    if (spheres.radii[f] > h / 2) {
      big.push_back(f);
      continue;
    }
    const Vec3& c = spheres.centres[f];
    entries.emplace_back(key_of(coord(c[0], 0), coord(c[1], 1), coord(c[2], 2)), f);
  }
  std::sort(entries.begin(), entries.end());
  std::vector<std::uint64_t> keys;
  std::vector<std::size_t> begins;
  for (std::size_t e = 0; e < entries.size(); ++e)
    if (e == 0 || entries[e].first != entries[e - 1].first) keys.push_back(entries[e].first), begins.push_back(e);
  begins.push_back(entries.size());
  auto cell = [&](std::uint64_t key) -> std::ptrdiff_t {
    const auto it = std::lower_bound(keys.begin(), keys.end(), key);
    return it != keys.end() && *it == key ? it - keys.begin() : -1;
  };
  constexpr std::size_t kBlock = 256;
  const std::size_t cell_blocks = block_count(keys.size(), kBlock);
  out.assign(cell_blocks + big.size(), Out());
  // Small faces: each cell with itself and its 13 neighbours that come after it.
  parallel_blocks(keys.size(), kBlock, threads, [&](std::size_t b, std::size_t e, std::size_t block) {
    for (std::size_t c = b; c < e && !halted(); ++c) {
      const std::uint64_t key = keys[c];
      const auto [x, y, z] = cell_of(key);
      for (std::size_t u = begins[c]; u < begins[c + 1] && !halted(); ++u)
        for (std::size_t v = u + 1; v < begins[c + 1]; ++v)
          if (overlap(entries[u].second, entries[v].second)) test(entries[u].second, entries[v].second, block);
      for (int dx = 0; dx <= 1; ++dx)
        for (int dy = dx == 0 ? 0 : -1; dy <= 1; ++dy)
          for (int dz = dx == 0 && dy == 0 ? 1 : -1; dz <= 1; ++dz) {
            if (x + dx < 0 || y + dy < 0 || z + dz < 0 || y + dy >= (1 << 21) || z + dz >= (1 << 21)) continue;
            const std::ptrdiff_t d = cell(key_of(x + dx, y + dy, z + dz));
            if (d < 0) continue;
            for (std::size_t u = begins[c]; u < begins[c + 1] && !halted(); ++u)
              for (std::size_t v = begins[d]; v < begins[d + 1]; ++v)
                if (overlap(entries[u].second, entries[v].second)) test(entries[u].second, entries[v].second, block);
          }
    }
  });
  // Big faces: against the small faces of the cells within their reach, and against the big faces
  // after them.
  parallel_blocks(big.size(), 1, threads, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t k = b; k < e && !halted(); ++k) {
      const unsigned f = big[k];
      const std::size_t block = cell_blocks + k;
      const Vec3& c = spheres.centres[f];
      const double reach = spheres.radii[f] + h / 2;
      std::int64_t from[3], to[3];
      double cells = 1;
      for (int a = 0; a < 3; ++a) {
        from[a] = coord(c[a] - reach, a), to[a] = coord(c[a] + reach, a);
        cells *= double(to[a] - from[a] + 1);
      }
      auto visit = [&](std::size_t d) {
        for (std::size_t v = begins[d]; v < begins[d + 1]; ++v)
          if (overlap(f, entries[v].second)) test(f, entries[v].second, block);
      };
      if (cells > double(keys.size())) {
        for (std::size_t d = 0; d < keys.size(); ++d) {
          const auto [x, y, z] = cell_of(keys[d]);
          if (x >= from[0] && x <= to[0] && y >= from[1] && y <= to[1] && z >= from[2] && z <= to[2]) visit(d);
        }
      } else {
        for (std::int64_t x = from[0]; x <= to[0]; ++x)
          for (std::int64_t y = from[1]; y <= to[1]; ++y)
            for (std::int64_t z = from[2]; z <= to[2]; ++z)
              if (const std::ptrdiff_t d = cell(key_of(x, y, z)); d >= 0) visit(static_cast<std::size_t>(d));
      }
      for (std::size_t l = k + 1; l < big.size(); ++l)
        if (overlap(f, big[l])) test(f, big[l], block);
    }
  });
}

/// What one block of the broad phase found: its crossing pairs (when asked for) and how many pairs
/// of overlapping spheres it met. A cache line each: two threads count into neighbouring blocks.
struct alignas(64) BlockFinds {
  std::vector<std::pair<unsigned, unsigned>> pairs;
  std::size_t overlaps = 0;
};

/// Pairs of overlapping spheres a search may meet: `per_face` a face looked at, and at least
/// `at_least`; no limit without `per_face`.
struct OverlapLimit {
  std::optional<std::size_t> per_face;
  std::size_t at_least = 0;
};

/// The search behind find_self_intersections and its variants. The faces looked at: all, or those
/// within reach of `region` (the faces meeting it, and every face that can cross one of them: its
/// sphere meets theirs, so it meets the region grown by their largest diameter); deleted faces are
/// passed over (face_spheres leaves them a sphere of radius 0 at the origin). With `cross`, the
/// pairs that cross are collected (with a region, those with a face meeting it). With a limit, the
/// pairs of overlapping spheres are counted, each block adding its count to the shared one every
/// kShare pairs, and the blocks stop once that is over the limit: nullopt then. Over the limit only
/// when more pairs than the limit overlap, and exact when the blocks ran to their end: the answer
/// does not depend on the threads' timing.
std::optional<std::vector<std::pair<unsigned, unsigned>>> search(const TriMesh& mesh, unsigned threads,
                                                                const Box* region, bool cross, OverlapLimit limit) {
  const FaceSpheres spheres = face_spheres(mesh);
  auto live = [&](std::size_t i) {
    return !mesh.has_face_status() || !mesh.status(OpenMesh::FaceHandle(static_cast<int>(i))).deleted();
  };
  std::vector<unsigned> faces;
  std::vector<char> in_region;
  if (region) {
    in_region.assign(mesh.n_faces(), 0);
    double largest = 0;
    for (std::size_t i = 0; i < mesh.n_faces(); ++i)
      if (live(i) && sphere_meets(*region, spheres.centres[i], spheres.radii[i]))
        in_region[i] = 1, largest = std::max(largest, spheres.radii[i]);
    for (std::size_t i = 0; i < mesh.n_faces(); ++i)
      if (in_region[i] || (live(i) && sphere_meets(*region, spheres.centres[i], spheres.radii[i], 2 * largest)))
        faces.push_back(static_cast<unsigned>(i));
  } else {
    faces.reserve(mesh.n_faces());
    for (std::size_t i = 0; i < mesh.n_faces(); ++i)
      if (live(i)) faces.push_back(static_cast<unsigned>(i));
  }
  const bool limited = limit.per_face.has_value();
  const std::size_t most = limited ? std::max(*limit.per_face * faces.size(), limit.at_least) : 0;
  constexpr std::size_t kShare = 4096;
  std::atomic<std::size_t> shared{0};
  std::atomic<bool> over{false};
  std::vector<BlockFinds> found;
  for_overlapping_spheres(spheres, faces, threads, [&](unsigned i, unsigned j, std::size_t block) {
    BlockFinds& b = found[block];
    if (limited && ++b.overlaps % kShare == 0 && shared.fetch_add(kShare, std::memory_order_relaxed) + kShare > most)
      over.store(true, std::memory_order_relaxed);
    if (!cross || (region && !in_region[i] && !in_region[j])) return;
    if (corners_cross(mesh, spheres.corners[i], spheres.corners[j]))
      b.pairs.emplace_back(std::min(i, j), std::max(i, j));
  }, found, limited ? &over : nullptr);
  if (limited) {
    std::size_t total = 0;
    for (const BlockFinds& b : found) total += b.overlaps;
    if (over.load() || total > most) return std::nullopt;
  }
  std::vector<std::pair<unsigned, unsigned>> pairs;
  for (BlockFinds& b : found) pairs.insert(pairs.end(), b.pairs.begin(), b.pairs.end());
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace

std::vector<std::pair<unsigned, unsigned>> find_self_intersections(const TriMesh& mesh, unsigned threads,
                                                                   const Box* region) {
  return *search(mesh, threads, region, true, {});
}

bool lies_over_itself(const TriMesh& mesh, unsigned threads) {
  return !search(mesh, threads, nullptr, false, {kLayeredOverlapsPerFace});
}

std::optional<std::vector<std::pair<unsigned, unsigned>>> find_self_intersections_unless_layered(const TriMesh& mesh,
                                                                                                unsigned threads) {
  return search(mesh, threads, nullptr, true, {kLayeredOverlapsPerFace});
}

std::optional<std::vector<std::pair<unsigned, unsigned>>> find_input_self_intersections(const TriMesh& mesh,
                                                                                       unsigned threads) {
  return search(mesh, threads, nullptr, true, {kLayeredOverlapsPerFace, kInputOverlapsAtLeast});
}

}  // namespace remesh
