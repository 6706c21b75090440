#include "dual/relax_bonds.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/parallel.h"
#include "dual/dual_stats.h"
#include "remesh/reference_surface.h"

namespace remesh {

namespace {

/// Iterations without a new high of bonds inside before the relaxation stops.
constexpr int kPatience = 8;
/// Share of the way to the spring target a vertex moves per iteration (Jacobi: all at once).
constexpr double kStep = 0.5;
/// Bonds shorter than this share of the rest length count as two atoms in one place.
constexpr double kCoincident = 1e-9;
/// The longest move per iteration, as a share of the rest length.
constexpr double kMaxStep = 0.5;

/// Newell's normal of a face (not normalised): robust for the dual's non-planar polygons.
Vec3 newell_normal(const PolyMesh& dual, PolyMesh::FaceHandle f) {
  Vec3 n(0, 0, 0);
  for (auto h : dual.fh_range(f)) {
    const Vec3& a = dual.point(dual.from_vertex_handle(h));
    const Vec3& b = dual.point(dual.to_vertex_handle(h));
    n += Vec3((a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1]));
  }
  return n;
}

}  // namespace

BondRelaxation relax_bonds(PolyMesh& dual, double e_min, double e_max, const ReferenceSurface& reference,
                           unsigned threads, std::stop_token stop, int max_iterations) {
  const auto start = std::chrono::steady_clock::now();
  auto inside = [&](const DualStats& s) { return s.bonds - s.short_bonds - s.long_bonds; };
  const DualStats first = dual_stats(dual, e_min, e_max);
  BondRelaxation r;
  r.bonds = first.bonds;
  r.inside_before = r.inside_after = inside(first);
  const double bond_min = first.bond_min, bond_max = first.bond_max, mean = first.mean;
  // The rest length: the middle of the interval, but within the bonds' own range (an interval
  // open upward, e_max up to the bounding box's diagonal, would fling the atoms across the model).
  const double hi = std::max(bond_min, std::min(bond_max, 1.25 * mean));
  const double lo = std::min(hi, std::max(bond_min, 0.8 * mean));  // an interval far below the bonds: hi
  const double rest = std::clamp(0.5 * (bond_min + bond_max), lo, hi);
  const std::size_t nv = dual.n_vertices(), nf = dual.n_faces();
  std::vector<char> movable(nv, 0);
  for (auto v : dual.vertices()) movable[v.idx()] = !dual.is_boundary(v) && dual.valence(v) == 3;
  std::vector<Vec3> best(nv), before(nv), target(nv), free(nv), settled(nv), normal(nv), face_normal(nf);
  std::vector<NeighbourCache> caches(nv);  // each vertex's last kd-tree answer (reference_surface.h)
  for (auto v : dual.vertices()) best[v.idx()] = dual.point(v);
  int since_best = 0;
  while (r.inside_after < r.bonds && r.iterations < max_iterations && since_best < kPatience &&
         !stop.stop_requested()) {
    ++r.iterations;
    parallel_for(nf, threads, [&](std::size_t f) { face_normal[f] = newell_normal(dual, dual.face_handle(f)); });
    // A vertex's normal: the sum of its faces' (unit) normals.
    parallel_for(nv, threads, [&](std::size_t i) {
      Vec3 n(0, 0, 0);
      for (auto f : dual.vf_range(dual.vertex_handle(static_cast<unsigned>(i)))) {
        const double len = face_normal[f.idx()].norm();
        if (len > 0) n += face_normal[f.idx()] / len;
      }
      const double len = n.norm();
      normal[i] = len > 0 ? n / len : n;
    });
    parallel_for(nv, threads, [&](std::size_t i) {
      const auto v = dual.vertex_handle(static_cast<unsigned>(i));
      const Vec3 x = dual.point(v);
      target[i] = free[i] = x;
      if (!movable[i]) return;
      Vec3 move(0, 0, 0), around(0, 0, 0);
      int n = 0;
      for (auto w : dual.vv_range(v)) around += dual.point(w) / 3.0;
      for (auto w : dual.vv_range(v)) {
        Vec3 d = x - dual.point(w);
        double l = d.norm();
        // Two atoms in one place (the projection can put two centroids on one point of a thin
        // part): apart along the direction from the other to this one's other neighbours.
        if (!(l > kCoincident * rest)) {
          d = (around * 3.0 - dual.point(w)) / 2.0 - dual.point(w);
          l = d.norm();
          if (!(l > 0)) continue;
          d *= kCoincident * rest / l;
          l = kCoincident * rest;
        }
        move += dual.point(w) + d * (rest / l) - x;
        ++n;
      }
      if (n == 0) return;
      move /= n;
      move -= (move | normal[i]) * normal[i];
      // A step of at most half the rest length: no atom jumps past its neighbours.
      const double length = kStep * move.norm();
      free[i] = x + (length > kMaxStep * rest ? kMaxStep * rest / length : 1.0) * kStep * move;
      const Vec3 projected = reference.closest_point(free[i], normal[i], caches[i]);
      if (std::isfinite(free[i][0]) && std::isfinite(free[i][1]) && std::isfinite(free[i][2]) &&
          std::isfinite(projected[0]) && std::isfinite(projected[1]) && std::isfinite(projected[2]))
        target[i] = projected;
      else
        free[i] = x;
    });
    // Where the projection would put two bonded atoms in one place (a reference corner that every
    // point nearby projects to: the three centroids around a valence-3 vertex at cheese's sharp
    // corners), the atom stays off the surface by its short move instead.
    parallel_for(nv, threads, [&](std::size_t i) {
      if (!movable[i]) return;
      for (auto w : dual.vv_range(dual.vertex_handle(static_cast<unsigned>(i))))
        if ((target[w.idx()] - target[i]).norm() <= kCoincident * rest) {
          settled[i] = free[i];
          return;
        }
      settled[i] = target[i];
    });
    for (std::size_t i = 0; i < nv; ++i)
      if (movable[i]) target[i] = settled[i];
    for (std::size_t i = 0; i < nv; ++i) {
      const auto v = dual.vertex_handle(static_cast<unsigned>(i));
      before[i] = dual.point(v);
      dual.point(v) = target[i];
    }
    // Undo the moves around a face turned over, until none is (each round undoes at least one).
    for (bool undone = true; undone;) {
      undone = false;
      for (auto f : dual.faces()) {
        // A ring with no area (its atoms in one place) has no side to turn over to.
        if (face_normal[f.idx()].sqrnorm() == 0 || (newell_normal(dual, f) | face_normal[f.idx()]) > 0) continue;
        for (auto v : dual.fv_range(f))
          if (dual.point(v) != before[v.idx()]) dual.point(v) = before[v.idx()], undone = true;
      }
    }
    const std::size_t now = inside(dual_stats(dual, e_min, e_max));
    if (now > r.inside_after) {
      r.inside_after = now;
      since_best = 0;
      for (auto v : dual.vertices()) best[v.idx()] = dual.point(v);
    } else {
      ++since_best;
    }
  }
  for (auto v : dual.vertices()) dual.point(v) = best[v.idx()];
  dual.update_normals();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace remesh
