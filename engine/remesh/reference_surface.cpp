#include "remesh/reference_surface.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "remesh/geometry.h"
#include "remesh/kd_tree.h"

namespace remesh {

namespace {

/// Compressed lists: items of key i are items[offsets[i] .. offsets[i+1]).
struct Csr {
  std::vector<std::uint32_t> offsets, items;
};

}  // namespace

/// Triangles a query has looked at already (each is incident to up to three of the nearest
/// vertices), per thread: stamp[t] == the query's epoch. 4 bytes per reference triangle and
/// thread, kept for the thread's next query on the same surface.
struct Seen {
  std::uint64_t surface = 0;
  std::uint32_t epoch = 0;
  std::vector<std::uint32_t> stamp;
  /// A fresh epoch for a query on `surface` with `triangles` triangles.
  std::uint32_t next(std::uint64_t id, std::size_t triangles) {
    if (surface != id || stamp.size() != triangles || ++epoch == 0) {
      stamp.assign(triangles, 0);
      surface = id;
      epoch = 1;
    }
    return epoch;
  }
};

struct ReferenceSurface::Impl {
  std::vector<Vec3> points;
  /// What a query reads of a triangle, in one record (one or two cache lines instead of four arrays:
  /// the candidate loop of closest_point visits ~100 triangles per query, scattered in memory).
  /// Measured alone: armadillo's queries 1.75 -> 1.57 us; small references, which stay in the
  /// cache, gain nothing (cheese 2.85 -> 2.88, cow 1.19 -> 1.17).
  struct Triangle {
    Vec3 centre;                          ///< centroid
    double radius = 0;                    ///< largest distance centroid -> corner
    Vec3 normal;                          ///< unit normal (zero for a degenerate triangle)
    std::array<std::uint32_t, 3> corners{};
    /// folded back onto a larger neighbour (see kFoldCos); never a candidate
    std::uint32_t folded = 0;
  };
  std::vector<Triangle> triangles;
  Csr vertex_triangles;             ///< triangles incident to each vertex
  /// per vertex: its longest incident edge, so every incident triangle lies within this distance
  std::vector<double> vertex_reach;
  /// Per vertex: a sphere around its incident triangles (the centre of their corners' bounding box,
  /// the distance to the farthest corner), for closest_point's test of a whole vertex. Tighter
  /// than the sphere of vertex_reach around the vertex itself, which reaches a whole longest edge
  /// past the vertex in every direction: cheese's 30 candidates a query had 3 vertices passed
  /// over with that one, 14 with this (its reference has slivers 3.6 by 0.17 around its holes).
  struct Star {
    Vec3 centre;
    double radius = 0;
  };
  std::vector<Star> stars;
  /// Per vertex: a cone around its triangles' unit normals (unit axis, cosine and sine of the
  /// half-angle, widened by kConeMargin; a half-angle of pi when the normals have no common
  /// direction), for opposite_side's test of a whole vertex (with the early stop: thin_parts.h's
  /// figures). Floats, built on the first query (build_cones): 20 bytes a vertex, and only for the
  /// surfaces whose thickness is asked (the input; not the feature snap's copies of the mesh).
  struct Cone {
    float axis[3] = {0, 0, 0};
    float cos_half = -1, sin_half = 0;
  };
  static constexpr double kConeMargin = 1e-5;  ///< covers the floats' rounding (about 1e-7)
  mutable std::vector<Cone> cones;
  mutable std::once_flag cones_built;
  void build_cones() const;
  /// opposite_side_distance's search: the vertices within limit + search_reach of the query find
  /// every triangle whose longest edge is at most search_reach (a point of a triangle lies within
  /// its longest edge of each corner); the longer triangles, a hundredth of them, are in
  /// long_triangles (and long_tree). An uneven input has a few very long edges (cheese:
  /// median 0.64, longest 9.5, scaled for the simplification): a search radius of the longest
  /// edge took in much of the mesh, 760 000 instructions a query.
  double search_reach = 0;
  std::vector<std::uint32_t> long_triangles;
  /// The long triangles' centres in a kd-tree of their own, and their largest radius: a triangle
  /// nearer than d to p has its centre within d + long_reach of p. (Looked at one by one, the
  /// long hundredth of nefertiti's 207 000 triangles was 2 000 tests a query.)
  std::vector<Vec3> long_centres;
  PointCloud long_cloud;
  std::unique_ptr<KdTree> long_tree;
  double long_reach = 0;
  /// per triangle: the triangle across its edge (corner k, corner k+1), or kNone (boundary edge)
  std::vector<std::array<std::uint32_t, 3>> across;
  static constexpr std::uint32_t kNone = UINT32_MAX;
  Csr vertex_boundary;              ///< other end of each boundary edge at a vertex
  std::size_t boundary_edges = 0;
  std::size_t neighbours = 30;
  std::uint64_t id = 0;  ///< unique per surface, for NeighbourCache
  PointCloud cloud;
  std::unique_ptr<KdTree> tree;

  static constexpr std::size_t kMaxK = 64;
  /// The min(k, kMaxK) reference vertices nearest to p, nearest first, into idx.
  std::size_t nearest(const Vec3& p, std::uint32_t* idx, std::size_t k) const {
    double dist2[kMaxK];
    k = std::min({k, kMaxK, points.size()});
    const double q[3] = {p[0], p[1], p[2]};
    return tree->knnSearch(q, k, idx, dist2);
  }

  /// nearest(p, idx, neighbours), answered from `cache` when that is exact (file comment of the
  /// header), else from the kd-tree, refilling the cache.
  std::size_t nearest(const Vec3& p, std::uint32_t* idx, NeighbourCache& cache) const {
    const std::size_t k = std::min({neighbours, kMaxK, points.size()});
    const std::size_t size = std::min(NeighbourCache::kCacheSize, points.size());
    // On a miss, the cached vertices still bound the search: the `size` nearest to p lie no farther
    // than the farthest of them (squared, with a margin against rounding; 0 = no bound).
    double bound = 0;
    if (cache.surface == id && cache.count >= k) {
      std::pair<double, std::uint32_t> by_distance[NeighbourCache::kCacheSize];
      for (std::uint32_t i = 0; i < cache.count; ++i)
        by_distance[i] = {(points[cache.idx[i]] - p).sqrnorm(), cache.idx[i]};
      // The k nearest, unordered but for the nearest first (closest_point prunes by it). The order
      // of std::pair, spelt out: C++20 derives pair's < from <=>, whose partial ordering of doubles
      // cost a third of this function.
      auto closer = [](const std::pair<double, std::uint32_t>& a, const std::pair<double, std::uint32_t>& b) {
        return a.first < b.first || (!(b.first < a.first) && a.second < b.second);
      };
      std::nth_element(by_distance, by_distance + (k - 1), by_distance + cache.count, closer);
      const double kth = by_distance[k - 1].first;
      std::iter_swap(by_distance, std::min_element(by_distance, by_distance + k, closer));
      const double moved = (p - cache.query).norm();
      if (std::sqrt(kth) + moved < cache.radius) {
        for (std::size_t i = 0; i < k; ++i) idx[i] = by_distance[i].second;
        return k;
      }
      if (cache.count == size) {
        for (std::uint32_t i = 0; i < cache.count; ++i) bound = std::max(bound, by_distance[i].first);
        bound = bound * (1 + 1e-9) + 1e-300;
      }
    }
    double dist2[NeighbourCache::kCacheSize];
    const double q[3] = {p[0], p[1], p[2]};
    std::size_t found = 0;
    if (bound > 0) {
      // nanoflann's k-nearest search, its worst distance starting at the bound instead of infinity,
      // so that it prunes from the first leaf on. When it fills all `size` places, those are the
      // nearest, in the same order as without the bound (a vertex nearer than the last of them is
      // nearer than the bound: it is visited, in the same order); else the plain search runs.
      // Measured (one thread, callgrind): cheese refined 13.04e9 -> 12.77e9 instructions, cow
      // 5.21e9 -> 5.16e9; the same meshes.
      nanoflann::KNNResultSet<double, std::uint32_t> result(size);
      result.init(cache.idx, dist2);
      dist2[size - 1] = bound;
      tree->findNeighbors(result, q, nanoflann::SearchParams());
      found = result.size();
    }
    if (found < size) found = tree->knnSearch(q, size, cache.idx, dist2);
    cache.surface = id;
    cache.query = p;
    cache.count = static_cast<std::uint32_t>(found);
    // With every reference vertex in the cache, any point may reuse it.
    cache.radius = found == points.size() ? std::numeric_limits<double>::infinity()
                                          : std::sqrt(dist2[found - 1]);
    std::copy_n(cache.idx, std::min(k, found), idx);
    return std::min(k, found);
  }

  Vec3 closest_point(const Vec3& p, const Vec3& normal_hint, const std::uint32_t* idx, std::size_t found) const;
  void walk(const Vec3& p, const Vec3& normal_hint, std::uint32_t& t, Vec3& c, double& d2, Seen& seen,
            std::uint32_t epoch) const;
  double opposite_side(const Vec3& p, const Vec3& normal, double limit, bool first) const;
};

ReferenceSurface::ReferenceSurface(const TriMesh& mesh, std::size_t neighbours)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.neighbours = std::max<std::size_t>(1, neighbours);
  std::vector<std::uint32_t> index(mesh.n_vertices(), UINT32_MAX);
  // Reserved: a capacity doubled by push_back would hold up to twice the memory (bunny_zipper's
  // peak: +10 MiB with the 72-byte triangle records).
  m.points.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    if (mesh.status(v).deleted()) continue;
    index[v.idx()] = static_cast<std::uint32_t>(m.points.size());
    m.points.push_back(mesh.point(v));
  }
  std::vector<std::uint32_t> face_index(mesh.n_faces(), Impl::kNone);
  m.triangles.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    if (mesh.status(f).deleted()) continue;
    face_index[f.idx()] = static_cast<std::uint32_t>(m.triangles.size());
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(mesh, f, c);
    Impl::Triangle t;
    t.corners = {index[c[0].idx()], index[c[1].idx()], index[c[2].idx()]};
    m.triangles.push_back(t);
  }
  // Triangles across each edge, from the mesh's halfedges: corners c0, c1, c2 are the ends of
  // h, next(h), next(next(h)) (geom::face_vertices), so edge (c_k, c_k+1) is next^(k+1)(h).
  m.across.reserve(m.triangles.size());
  for (auto f : mesh.faces()) {
    if (mesh.status(f).deleted()) continue;
    std::array<std::uint32_t, 3> across{Impl::kNone, Impl::kNone, Impl::kNone};
    auto h = mesh.halfedge_handle(f);
    for (int k = 0; k < 3; ++k) {
      h = mesh.next_halfedge_handle(h);
      const auto g = mesh.opposite_face_handle(h);
      if (g.is_valid()) across[k] = face_index[g.idx()];
    }
    m.across.push_back(across);
  }
  if (m.triangles.empty()) throw MeshError("reference surface has no triangles");
  const std::size_t nv = m.points.size(), nt = m.triangles.size();
  std::vector<double> areas(nt);
  m.vertex_triangles.offsets.assign(nv + 1, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    Impl::Triangle& tri = m.triangles[t];
    const Vec3 &a = m.points[tri.corners[0]], &b = m.points[tri.corners[1]], &c = m.points[tri.corners[2]];
    Vec3 n = geom::cross_normal(a, b, c);
    const double len = n.norm();
    tri.normal = len > 0 ? n / len : Vec3(0, 0, 0);
    areas[t] = 0.5 * len;
    tri.centre = (a + b + c) / 3.0;
    tri.radius = std::sqrt(std::max({(a - tri.centre).sqrnorm(), (b - tri.centre).sqrnorm(),
                                     (c - tri.centre).sqrnorm()}));
    for (auto v : tri.corners) ++m.vertex_triangles.offsets[v + 1];
  }
  m.vertex_reach.assign(nv, 0.0);
  std::vector<double> longest(nt, 0.0);  // per triangle
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& corners = m.triangles[t].corners;
      const std::uint32_t a = corners[k], b = corners[(k + 1) % 3];
      const double l = (m.points[a] - m.points[b]).norm();
      m.vertex_reach[a] = std::max(m.vertex_reach[a], l);
      m.vertex_reach[b] = std::max(m.vertex_reach[b], l);
      longest[t] = std::max(longest[t], l);
    }
  {
    std::vector<double> sorted = longest;
    const std::size_t rank = nt - 1 - nt / 100;
    std::nth_element(sorted.begin(), sorted.begin() + rank, sorted.end());
    m.search_reach = sorted[rank];
    for (std::size_t t = 0; t < nt; ++t)
      if (longest[t] > m.search_reach) m.long_triangles.push_back(static_cast<std::uint32_t>(t));
  }
  for (std::size_t v = 0; v < nv; ++v) m.vertex_triangles.offsets[v + 1] += m.vertex_triangles.offsets[v];
  m.vertex_triangles.items.resize(m.vertex_triangles.offsets[nv]);
  {
    std::vector<std::uint32_t> fill(m.vertex_triangles.offsets.begin(), m.vertex_triangles.offsets.end() - 1);
    for (std::size_t t = 0; t < nt; ++t)
      for (auto v : m.triangles[t].corners) m.vertex_triangles.items[fill[v]++] = static_cast<std::uint32_t>(t);
  }
  m.stars.resize(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    const std::uint32_t* begin = m.vertex_triangles.items.data() + m.vertex_triangles.offsets[v];
    const std::uint32_t* end = m.vertex_triangles.items.data() + m.vertex_triangles.offsets[v + 1];
    Vec3 lo = m.points[v], hi = lo;
    for (const std::uint32_t* t = begin; t != end; ++t)
      for (auto c : m.triangles[*t].corners) lo.minimize(m.points[c]), hi.maximize(m.points[c]);
    Impl::Star& star = m.stars[v];
    star.centre = 0.5 * (lo + hi);
    double r2 = 0;
    for (const std::uint32_t* t = begin; t != end; ++t)
      for (auto c : m.triangles[*t].corners) r2 = std::max(r2, (m.points[c] - star.centre).sqrnorm());
    star.radius = std::sqrt(r2) * (1 + 1e-9) + 1e-12;  // a margin against rounding
  }
  // A triangle whose normal is nearly opposite to that of a larger neighbour across an edge lies
  // folded back onto it: a defect of the input (nefertiti has 96 such pairs: slivers that close
  // T-junctions of its base with their third corner on the wrong side). Its normal is noise, and a
  // vertex that follows it into the fold gets squeezed between the sheets. The neighbours cover the
  // same place, so the projection ignores it. A genuine blade sharper than 18 degrees would lose the
  // row of smaller triangles along its edge the same way (none among the shared meshes; the rule
  // does not check that the larger triangle covers the smaller one).
  constexpr double kFoldCos = -0.95;
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = m.across[t][k];
      if (u != Impl::kNone && (m.triangles[t].normal | m.triangles[u].normal) < kFoldCos &&
          areas[u] > areas[t])
        m.triangles[t].folded = 1;
    }
  // Boundary edges, listed at both ends.
  m.vertex_boundary.offsets.assign(nv + 1, 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> segments;
  for (auto e : mesh.edges()) {
    if (mesh.status(e).deleted() || !mesh.is_boundary(e)) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    const std::uint32_t a = index[mesh.from_vertex_handle(h).idx()], b = index[mesh.to_vertex_handle(h).idx()];
    segments.emplace_back(a, b);
    ++m.vertex_boundary.offsets[a + 1];
    ++m.vertex_boundary.offsets[b + 1];
  }
  m.boundary_edges = segments.size();
  for (std::size_t v = 0; v < nv; ++v) m.vertex_boundary.offsets[v + 1] += m.vertex_boundary.offsets[v];
  m.vertex_boundary.items.resize(m.vertex_boundary.offsets[nv]);
  {
    std::vector<std::uint32_t> fill(m.vertex_boundary.offsets.begin(), m.vertex_boundary.offsets.end() - 1);
    for (auto [a, b] : segments) {
      m.vertex_boundary.items[fill[a]++] = b;
      m.vertex_boundary.items[fill[b]++] = a;
    }
  }
  m.cloud.points = &m.points;
  m.tree = std::make_unique<KdTree>(3, m.cloud, nanoflann::KDTreeSingleIndexAdaptorParams(kKdTreeLeafSize));
  m.tree->buildIndex();
  if (!m.long_triangles.empty()) {
    for (std::uint32_t t : m.long_triangles) {
      m.long_centres.push_back(m.triangles[t].centre);
      m.long_reach = std::max(m.long_reach, m.triangles[t].radius);
    }
    m.long_reach = m.long_reach * (1 + 1e-9) + 1e-12;  // a margin against rounding
    m.long_cloud.points = &m.long_centres;
    m.long_tree =
        std::make_unique<KdTree>(3, m.long_cloud, nanoflann::KDTreeSingleIndexAdaptorParams(kKdTreeLeafSize));
    m.long_tree->buildIndex();
  }
  static std::atomic<std::uint64_t> next_id{1};
  m.id = next_id++;
}

ReferenceSurface::~ReferenceSurface() = default;
ReferenceSurface::ReferenceSurface(ReferenceSurface&&) noexcept = default;
ReferenceSurface& ReferenceSurface::operator=(ReferenceSurface&&) noexcept = default;

std::size_t ReferenceSurface::n_vertices() const { return impl_->points.size(); }
std::size_t ReferenceSurface::n_triangles() const { return impl_->triangles.size(); }
bool ReferenceSurface::has_boundary() const { return impl_->boundary_edges > 0; }

void ReferenceSurface::Impl::build_cones() const {
  const std::size_t nv = points.size();
  cones.assign(nv, Cone{});
  for (std::size_t v = 0; v < nv; ++v) {
    Vec3 sum(0, 0, 0);
    for (std::uint32_t j = vertex_triangles.offsets[v]; j < vertex_triangles.offsets[v + 1]; ++j)
      sum += triangles[vertex_triangles.items[j]].normal;
    const double len = sum.norm();
    if (!(len > 1e-9)) continue;  // the whole sphere of directions
    const Vec3 axis = sum / len;
    double c = 1;
    for (std::uint32_t j = vertex_triangles.offsets[v]; j < vertex_triangles.offsets[v + 1]; ++j) {
      const Vec3& n = triangles[vertex_triangles.items[j]].normal;
      if (n.sqrnorm() > 0) c = std::min(c, n | axis);
    }
    c -= kConeMargin;  // wider: the test may read the float axis a little off
    if (c <= -1) continue;
    Cone& cone = cones[v];
    for (int k = 0; k < 3; ++k) cone.axis[k] = static_cast<float>(axis[k]);
    // Rounded the way that widens the cone.
    cone.cos_half = std::nextafter(static_cast<float>(c), -1.0f);
    cone.sin_half = std::nextafter(static_cast<float>(std::sqrt(std::max(0.0, 1.0 - c * c))), 2.0f);
  }
}

namespace {

/// A nanoflann result set that hands each point within sqrt(*radius2) of the query to `visit(index,
/// squared distance)` as the search finds it, keeping none; the search stops when visit returns
/// false, and prunes by *radius2, which visit may shrink.
template <class Visit>
struct VisitEach {
  double* radius2;
  Visit* visit;
  void init() {}
  std::size_t size() const { return 0; }
  bool full() const { return true; }
  double worstDist() const { return *radius2; }
  bool addPoint(double d2, std::uint32_t i) { return (*visit)(i, d2); }
};

}  // namespace

/// Reference vertices and long triangles opposite_side() visits at most per query. A reference
/// whose long triangles reach across most of it (a fan of 40 000 spokes round one vertex) made
/// every query visit all of it; with an output of thousands of vertices to measure, thin_parts()
/// held a cancelled job for minutes. Measured (thin_parts() on the 24 Table 4.2 outputs): at most
/// 1 735 visits (cheese refined; 683 nefertiti simplified, 22-231 on average).
constexpr std::size_t kMaxOppositeVisits = std::size_t{1} << 14;

/// opposite_side_distance's search. With `first`, it stops at the first triangle nearer than
/// `limit` (whose distance it returns, not the least). After kMaxOppositeVisits it stops with what
/// it has found.
double ReferenceSurface::Impl::opposite_side(const Vec3& p, const Vec3& normal, double limit, bool first) const {
  constexpr double kOpposite = -0.3;
  if (!(limit > 0)) return std::numeric_limits<double>::infinity();
  std::call_once(cones_built, [this] { build_cones(); });
  double best2 = limit * limit, best = limit;  // the nearest found (squared and not), else the limit
  bool any = false;
  auto consider = [&](const Triangle& tri) {
    if ((tri.normal | normal) >= kOpposite) return;
    // Every point of the triangle lies within its radius of its centre (the margin keeps the test
    // conservative against rounding).
    const double reach = (best + tri.radius) * (1.0 + 1e-9);
    if ((tri.centre - p).sqrnorm() > reach * reach) return;
    const Vec3 c = geom::closest_point_on_triangle(p, points[tri.corners[0]], points[tri.corners[1]],
                                                   points[tri.corners[2]]);
    const double c2 = (c - p).sqrnorm();
    if (c2 < best2) best2 = c2, best = std::sqrt(c2), any = true;
  };
  // A triangle nearer than `limit` (later: than the nearest found) has every corner v within that
  // distance plus vertex_reach[v] of p; those with an edge longer than search_reach are found
  // through long_tree (Impl::search_reach).
  double radius2 = (limit + search_reach) * (limit + search_reach);
  std::size_t visits = 0;
  auto visit = [&](std::uint32_t v, double d2) {
    if (++visits > kMaxOppositeVisits) return false;
    const double reach = best + vertex_reach[v];
    if (d2 > reach * reach) return true;
    // Passed over whole: a star that lies farther than the nearest found, or whose triangles all
    // face too much the same way as `normal` (its cone: their normals lie within its half-angle
    // of its axis, so none is more than the axis' angle to `normal` plus that half-angle from it).
    const Star& star = stars[v];
    const double star_reach = best + star.radius;
    if ((star.centre - p).sqrnorm() > star_reach * star_reach) return true;
    const Cone& cone = cones[v];
    const double ca = std::clamp(cone.axis[0] * normal[0] + cone.axis[1] * normal[1] + cone.axis[2] * normal[2], -1.0, 1.0);
    const double sa = std::sqrt(1.0 - ca * ca);
    if (ca * cone.sin_half + sa * cone.cos_half > kConeMargin &&
        ca * cone.cos_half - sa * cone.sin_half >= kOpposite + kConeMargin)
      return true;
    for (std::uint32_t j = vertex_triangles.offsets[v]; j < vertex_triangles.offsets[v + 1]; ++j)
      consider(triangles[vertex_triangles.items[j]]);
    if (any && first) return false;
    const double r = best + search_reach;
    radius2 = std::min(radius2, r * r);
    return true;
  };
  VisitEach<decltype(visit)> each{&radius2, &visit};
  const double q[3] = {p[0], p[1], p[2]};
  tree->findNeighbors(each, q, nanoflann::SearchParams(32, 0.0f, false));
  if (long_tree && !(any && first) && visits <= kMaxOppositeVisits) {
    double long_radius2 = (best + long_reach) * (best + long_reach);
    auto visit_long = [&](std::uint32_t i, double) {
      if (++visits > kMaxOppositeVisits) return false;
      consider(triangles[long_triangles[i]]);
      if (any && first) return false;
      const double r = best + long_reach;
      long_radius2 = std::min(long_radius2, r * r);
      return true;
    };
    VisitEach<decltype(visit_long)> each_long{&long_radius2, &visit_long};
    long_tree->findNeighbors(each_long, q, nanoflann::SearchParams(32, 0.0f, false));
  }
  return any ? best : std::numeric_limits<double>::infinity();
}

double ReferenceSurface::opposite_side_distance(const Vec3& p, const Vec3& normal, double limit) const {
  return impl_->opposite_side(p, normal, limit, /*first=*/false);
}

bool ReferenceSurface::opposite_side_within(const Vec3& p, const Vec3& normal, double limit) const {
  return impl_->opposite_side(p, normal, limit, /*first=*/true) < limit;
}

std::size_t ReferenceSurface::nearest_vertices(const Vec3& p, std::size_t k, std::uint32_t* out) const {
  return impl_->nearest(p, out, k);
}

// A point that is not finite (an overflow upstream) has no nearest vertices: it is returned as it is,
// for the caller's checks to refuse, instead of a read past the kd-tree's empty answer.
Vec3 ReferenceSurface::closest_point(const Vec3& p, const Vec3& normal_hint) const {
  std::uint32_t idx[Impl::kMaxK];
  const std::size_t found = impl_->nearest(p, idx, impl_->neighbours);
  return found == 0 ? p : impl_->closest_point(p, normal_hint, idx, found);
}

Vec3 ReferenceSurface::closest_point(const Vec3& p, const Vec3& normal_hint, NeighbourCache& cache) const {
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return p;
  std::uint32_t idx[Impl::kMaxK];
  const std::size_t found = impl_->nearest(p, idx, cache);
  return found == 0 ? p : impl_->closest_point(p, normal_hint, idx, found);
}

/// The closest point to p on the triangles incident to the reference vertices idx[0..found) (folded
/// ones skipped), improved by walk().
Vec3 ReferenceSurface::Impl::closest_point(const Vec3& p, const Vec3& normal_hint, const std::uint32_t* idx,
                                           std::size_t found) const {
  const Impl& m = *this;
  constexpr std::uint32_t kNone = Impl::kNone;

  // Best candidate overall and best candidate whose normal agrees with the hint. The agreeing one
  // wins when it is nearly as close (two sheets close together: stay on the vertex's own sheet).
  const bool use_hint = normal_hint.sqrnorm() > 0;
  constexpr double kInf = std::numeric_limits<double>::max();
  Vec3 best = m.points[idx[0]], best_agree = best;
  double best_d2 = kInf, agree_d2 = kInf, best_d = kInf, agree_d = kInf;
  std::uint32_t best_t = kNone, agree_t = kNone;
  thread_local Seen seen;
  const std::uint32_t epoch = seen.next(id, triangles.size());
  for (std::size_t i = 0; i < found; ++i) {
    const std::uint32_t v = idx[i];
    // Skip the vertex when all its triangles (within its star's sphere) are farther than any
    // candidate they could beat: one test instead of one per triangle (most of the 30 vertices are
    // two or three rings away). Measured (Table 4.2 setup, 2 threads): cheese refined and
    // simplified 8 % faster than with the sphere of vertex_reach around the vertex; the same meshes.
    if (const double bound = use_hint ? std::max(best_d, agree_d) : best_d; bound < kInf) {
      const double reach = m.stars[v].radius + bound;
      if ((p - m.stars[v].centre).sqrnorm() > reach * reach) continue;
    }
    for (std::uint32_t j = m.vertex_triangles.offsets[v]; j < m.vertex_triangles.offsets[v + 1]; ++j) {
      const std::uint32_t t = m.vertex_triangles.items[j];
      // Once per query: a triangle passed over stays passed over (the bounds only shrink), and
      // one measured cannot win again (strictly closer only). Same answers, half the visits
      // (cheese: 175 -> 100 triangles a query; 4 % of its run).
      if (seen.stamp[t] == epoch) continue;
      seen.stamp[t] = epoch;
      const Triangle& tri = m.triangles[t];
      if (tri.folded) continue;
      const bool agrees = use_hint && (tri.normal | normal_hint) > 0;
      // Skip a triangle whose bounding sphere is farther than the candidate it could beat.
      const double bound = agrees ? std::max(best_d, agree_d) : best_d;
      if (bound < kInf) {
        const Vec3 from_centre = p - tri.centre;
        const double reach = tri.radius + bound;
        if (from_centre.sqrnorm() > reach * reach) continue;
        // ... or whose plane is: a sliver's bounding sphere is wide (cheese.off: triangles 3.6 by
        // 0.17 around its holes; this test makes its run 15 % faster). The margin keeps the test
        // conservative against rounding.
        if (std::abs(tri.normal | from_centre) > bound * (1.0 + 1e-9) + 1e-12) continue;
      }
      const Vec3 c = geom::closest_point_on_triangle(p, m.points[tri.corners[0]], m.points[tri.corners[1]],
                                                     m.points[tri.corners[2]]);
      const double d2 = (c - p).sqrnorm();
      if (d2 < best_d2) best_d2 = d2, best_d = std::sqrt(d2), best = c, best_t = t;
      if (agrees && d2 < agree_d2) agree_d2 = d2, agree_d = std::sqrt(d2), best_agree = c, agree_t = t;
    }
  }
  // "Nearly as close": within twice the distance of the closest candidate (plus a hair for points
  // already on the surface).
  if (use_hint && agree_t != kNone) {
    // Walked before the comparison: a large triangle the candidates missed can bring the vertex's
    // own sheet nearer.
    walk(p, normal_hint, agree_t, best_agree, agree_d2, seen, epoch);
    const double scale = 1e-12 * (1.0 + p.sqrnorm());
    if (agree_d2 <= 4.0 * best_d2 + scale) return best_agree;
  }
  // With a hint, the closest candidate here disagrees with it, and the walk only enters agreeing
  // triangles: it moves only where that candidate is nearly parallel to the hint.
  if (best_t != kNone) walk(p, normal_hint, best_t, best, best_d2, seen, epoch);
  return best;
}

/// Not in Alg. 6: a triangle far larger than its neighbours can lie under p while none of its
/// corners is among the nearest reference vertices (nefertiti's base: triangles 10-22 units long
/// beside a dense rim), and then the candidates' closest point sits on the edge line of a
/// neighbouring triangle. From the winning triangle t, step to the triangle across an edge while
/// that gets closer, only onto nearly coplanar triangles (kWalkCos) whose normal agrees with the
/// hint, so a walk never turns round a fold of the reference onto another sheet.
/// A triangle the query has seen (`seen` at `epoch`) is not measured again: the candidate loop
/// measured it, or ruled it out, against a bound no nearer than the walk's current distance, and a
/// step of the walk that passed over it had a nearer one; either way it cannot be the next step.
void ReferenceSurface::Impl::walk(const Vec3& p, const Vec3& normal_hint, std::uint32_t& t, Vec3& c, double& d2,
                                  Seen& seen, std::uint32_t epoch) const {
  constexpr int kWalkSteps = 16;  // a descent: each step strictly closer; the bound caps its cost
  // About 25 degrees. Measured (Table 4.2 setup): 45 degrees changes nothing on nefertiti, cow and
  // camelhead, and ends cheese at 99.18 % inside instead of 99.24 %.
  constexpr double kWalkCos = 0.9;
  const bool use_hint = normal_hint.sqrnorm() > 0;
  for (int step = 0; step < kWalkSteps; ++step) {
    std::uint32_t next = kNone;
    Vec3 next_c = c;
    double next_d2 = d2 * (1.0 - 1e-9);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = across[t][k];
      if (u == kNone || seen.stamp[u] == epoch) continue;
      seen.stamp[u] = epoch;
      const Triangle& tri = triangles[u];
      if (tri.folded || (tri.normal | triangles[t].normal) < kWalkCos) continue;
      if (use_hint && (tri.normal | normal_hint) <= 0) continue;
      const Vec3 q = geom::closest_point_on_triangle(p, points[tri.corners[0]], points[tri.corners[1]],
                                                     points[tri.corners[2]]);
      const double e2 = (q - p).sqrnorm();
      if (e2 < next_d2) next = u, next_c = q, next_d2 = e2;
    }
    if (next == kNone) return;
    t = next, c = next_c, d2 = next_d2;
  }
}

Vec3 ReferenceSurface::closest_boundary_point(const Vec3& p) const {
  const Impl& m = *impl_;
  if (m.boundary_edges == 0) return closest_point(p);
  std::uint32_t idx[Impl::kMaxK];
  const std::size_t found = m.nearest(p, idx, m.neighbours);
  Vec3 best(0, 0, 0);
  double best_d2 = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < found; ++i) {
    const std::uint32_t v = idx[i];
    for (std::uint32_t j = m.vertex_boundary.offsets[v]; j < m.vertex_boundary.offsets[v + 1]; ++j) {
      const Vec3 c = geom::closest_point_on_segment(p, m.points[v], m.points[m.vertex_boundary.items[j]]);
      const double d2 = (c - p).sqrnorm();
      if (d2 < best_d2) best_d2 = d2, best = c;
    }
  }
  if (best_d2 == std::numeric_limits<double>::max()) return closest_point(p);
  return best;
}

}  // namespace remesh
