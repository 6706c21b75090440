/// \file topology.cpp
/// Edge manifoldness, consistent orientation and pinched-vertex splitting on a triangle soup.

#include <algorithm>
#include <numeric>
#include <string>

#include "io/parse_util.h"
#include "io/repair.h"

namespace remesh::io {

namespace {

/// True if the triangle runs its edge from a to b (rather than b to a).
bool runs_forward(const Tri& t, std::uint32_t a, std::uint32_t b) {
  return (t[0] == a && t[1] == b) || (t[1] == a && t[2] == b) || (t[2] == a && t[0] == b);
}

std::vector<EdgeUse> edge_uses(const TriSoup& soup) {
  std::vector<EdgeUse> uses;
  uses.reserve(soup.tris.size() * 3);
  for (std::uint32_t t = 0; t < soup.tris.size(); ++t)
    for (std::uint8_t c = 0; c < 3; ++c) {
      std::uint32_t a = soup.tris[t][c], b = soup.tris[t][(c + 1) % 3];
      uses.push_back({std::min(a, b), std::max(a, b), t});
    }
  std::sort(uses.begin(), uses.end());
  return uses;
}

/// Calls f(use_a, use_b) for every edge with exactly two faces.
template <class F>
void for_manifold_pairs(const std::vector<EdgeUse>& uses, F&& f) {
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    if (j - i == 2) f(uses[i], uses[i + 1]);
    i = j;
  }
}

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

std::string face_name(const TriSoup& soup, const RawSoup& raw, std::uint32_t t) {
  const std::uint32_t f = soup.source[t];
  return "face " + std::to_string(f) + raw.face_where(f);
}

}  // namespace

std::vector<EdgeUse> check_edges_and_orient(TriSoup& soup, const RawSoup& raw, std::vector<Repair>& repairs) {
  std::vector<EdgeUse> uses = edge_uses(soup);
  // Edges with more than two faces cannot be repaired without guessing: refuse.
  std::size_t bad = 0;
  std::string first;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    if (j - i > 2) {
      if (bad++ == 0)
        first = "vertices " + std::to_string(uses[i].lo) + " and " + std::to_string(uses[i].hi) + " (shared by " +
                std::to_string(j - i) + " faces, e.g. " + face_name(soup, raw, uses[i].tri) + ")";
    }
    i = j;
  }
  if (bad > 0)
    fail("non-manifold mesh: " + std::to_string(bad) + (bad == 1 ? " edge is" : " edges are") +
         " shared by more than 2 faces; the first joins " + first);

  // Orientation: neighbours across an edge must run it in opposite directions. Breadth-first
  // search gives each face a parity relative to its component's first face.
  const std::size_t n = soup.tris.size();
  std::vector<std::uint32_t> adj_start(n + 1, 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  std::vector<bool> same;
  for_manifold_pairs(uses, [&](const EdgeUse& a, const EdgeUse& b) {
    const bool same_dir = runs_forward(soup.tris[a.tri], a.lo, a.hi) == runs_forward(soup.tris[b.tri], b.lo, b.hi);
    pairs.push_back({a.tri, b.tri});
    same.push_back(same_dir);
  });
  for (const auto& [a, b] : pairs) ++adj_start[a + 1], ++adj_start[b + 1];
  for (std::size_t i = 0; i < n; ++i) adj_start[i + 1] += adj_start[i];
  std::vector<std::pair<std::uint32_t, bool>> links(adj_start[n]);
  {
    std::vector<std::uint32_t> fill(adj_start.begin(), adj_start.end() - 1);
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      links[fill[pairs[k].first]++] = {pairs[k].second, same[k]};
      links[fill[pairs[k].second]++] = {pairs[k].first, same[k]};
    }
  }
  std::vector<std::int8_t> flip(n, -1);
  std::vector<std::uint32_t> queue, component;
  std::size_t flipped = 0, components_flipped = 0;
  for (std::uint32_t seed = 0; seed < n; ++seed) {
    if (flip[seed] >= 0) continue;
    component.clear();
    queue.assign(1, seed);
    flip[seed] = 0;
    std::size_t count_flipped = 0;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const std::uint32_t t = queue[q];
      component.push_back(t);
      count_flipped += static_cast<std::size_t>(flip[t]);
      for (std::uint32_t k = adj_start[t]; k < adj_start[t + 1]; ++k) {
        const auto [u, same_dir] = links[k];
        const std::int8_t want = static_cast<std::int8_t>(flip[t] ^ (same_dir ? 1 : 0));
        if (flip[u] < 0) {
          flip[u] = want;
          queue.push_back(u);
        } else if (flip[u] != want) {
          fail("non-orientable surface (e.g. a Moebius strip): the component containing " +
               face_name(soup, raw, seed) + " cannot be oriented consistently (conflict at " +
               face_name(soup, raw, u) + ")");
        }
      }
    }
    const bool invert = 2 * count_flipped > component.size();  // keep the majority's orientation
    std::size_t here = 0;
    for (std::uint32_t t : component) {
      if ((flip[t] != 0) != invert) {
        std::swap(soup.tris[t][1], soup.tris[t][2]);
        ++here;
      }
    }
    if (here > 0) ++components_flipped;
    flipped += here;
  }
  if (flipped > 0)
    repairs.push_back({"faces_reoriented", flipped,
                       std::to_string(flipped) + " faces flipped to agree with their neighbours in " +
                           std::to_string(components_flipped) + " component(s)"});
  return uses;
}

void drop_crowding_zero_area(TriSoup& soup, DroppedFaces& dropped) {
  const std::vector<EdgeUse> uses = edge_uses(soup);
  std::vector<bool> keep(soup.tris.size(), true);
  bool any = false;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    if (j - i > 2)
      for (std::size_t k = i; k < j; ++k) {
        const std::uint32_t t = uses[k].tri;
        if (!soup.zero_area[t] || !keep[t]) continue;
        keep[t] = false;
        dropped.add_zero_area(soup.source[t]);
        any = true;
      }
    i = j;
  }
  if (any) soup.retain(keep);
}

void split_pinched_vertices(TriSoup& soup, const std::vector<EdgeUse>& uses, std::vector<Repair>& repairs) {
  const std::size_t n = soup.tris.size();
  // Corners around a vertex are one fan when consecutive faces share an edge at that vertex.
  UnionFind fans(3 * n);
  auto corner_of = [&](std::uint32_t t, std::uint32_t v) {
    const Tri& tri = soup.tris[t];
    return 3 * t + (tri[0] == v ? 0u : tri[1] == v ? 1u : 2u);
  };
  for_manifold_pairs(uses, [&](const EdgeUse& a, const EdgeUse& b) {
    for (std::uint32_t v : {a.lo, a.hi}) fans.unite(corner_of(a.tri, v), corner_of(b.tri, v));
  });
  std::vector<std::uint32_t> fan_vertex(3 * n, UINT32_MAX);
  std::vector<bool> claimed(soup.points.size(), false), split(soup.points.size(), false);
  std::size_t split_count = 0, copies = 0;
  std::string first;
  for (std::uint32_t t = 0; t < n; ++t)
    for (std::uint32_t c = 0; c < 3; ++c) {
      const std::uint32_t v = soup.tris[t][c];
      const std::uint32_t root = fans.find(3 * t + c);
      if (fan_vertex[root] == UINT32_MAX) {
        if (!claimed[v]) {
          claimed[v] = true;
          fan_vertex[root] = v;
        } else {
          if (!split[v]) {
            split[v] = true;
            if (split_count++ == 0) first = std::to_string(v);
          }
          fan_vertex[root] = static_cast<std::uint32_t>(soup.points.size());
          soup.points.push_back(soup.points[v]);
          ++copies;
        }
      }
      soup.tris[t][c] = fan_vertex[root];
    }
  if (split_count > 0)
    repairs.push_back({"nonmanifold_vertices_split", split_count,
                       std::to_string(split_count) + " non-manifold (pinched) vertices split into " +
                           std::to_string(split_count + copies) + " (first: vertex " + first + ")"});
}

}  // namespace remesh::io
