#pragma once
/// \file untangle.h
/// Not in the thesis: the last step of a run, after the feature snap, that moves apart faces that
/// cross each other (self_intersections.h says how they come about). Four means, in turn:
/// - vertex moves: a vertex of a crossing face goes part of the way to its ring's centroid,
///   projected onto the reference or not, when that lowers its faces' crossings, folds nothing and
///   leaves no more of its edges outside [e_min, e_max];
/// - flips: an edge of a crossing face is flipped when that lowers its two faces' crossings, takes
///   no edge out of the interval and passes the valence flips' rule but for the agreement of old
///   and new normals (a tangle's faces are turned already). Then vertex moves again;
/// - collapses: an edge of a crossing face is collapsed, one end onto the other where it stands,
///   when that lowers the crossings of the ends' faces and passes the rules of Algorithm 3's
///   collapses (no edge longer than e_max) but, again, for the agreement of normals. A collapse may
///   leave a short edge: tangles lie where the surface is thinner than the interval allows. Then
///   vertex moves again. Flips and collapses are tried again while they lower the crossings;
/// - flattening: what single moves cannot mend (a pleat: a few rings of faces folded over each
///   other, on a crumpled part of the reference) is replaced by a membrane. The vertices within a
///   few rings of the tangle are placed where each is the mean of its neighbours, with the
///   rest of the mesh held (a harmonic disk, whose shadow on the plane of its rim is a Tutte
///   embedding, so it cannot fold when that shadow is valid), then projected onto the reference
///   when that keeps it untangled. The disk grows ring by ring until one works. A disk is kept only
///   if it passes within e_min of every position its vertices had: a disk whose rim girds a thin
///   protrusion would otherwise span it there and cut its end off (cow.obj, simplification setup:
///   a leg 6 units shorter, Hausdorff 5.6 -> 14.9 % of the bbox diagonal, on a run whose cleanup
///   took another path). A tangle no disk passes for stays as it is.
/// Measured (Table 4.2 setup): nefertiti's output had 14 crossing face pairs on its base where the
/// input and CGAL's output have none. Flips and collapses (crossing face pairs by meshqa, before ->
/// after; coarsened: mean edge 0.15 -> [1.2, 1.8]): cheese simplified 74 -> 43, and coarsened
/// armadillo 15 -> 0 (6 after one round; CGAL 0), camelhead 10 -> 0, bunny 4 -> 0, cow 5 -> 0,
/// eight 20 -> 16 (CGAL 12); the Hausdorff distances the same. Edges inside: cheese simplified
/// 64.74 -> 64.64 %, camelhead coarsened 93.15 -> 92.77 %, the rest the same or more. Every other
/// Table 4.2 run gives the same mesh (none has crossings left for them).

#include <cstddef>
#include <optional>
#include <stop_token>
#include <utility>
#include <vector>

#include "core/mesh.h"
#include "remesh/crease_lines.h"
#include "remesh/reference_surface.h"

namespace remesh {

struct UntangleCounts {
  std::size_t pairs_before = 0;  ///< crossing face pairs before
  /// The crossing face pairs left, as find_self_intersections() would give them now.
  std::vector<std::pair<unsigned, unsigned>> left;
  std::size_t moved = 0;      ///< vertex moves, flips, collapses and flattened vertices
  std::size_t flipped = 0;    ///< of them, flips
  std::size_t collapsed = 0;  ///< collapses
  std::size_t flattened = 0;  ///< of them, vertices of flattened disks
  /// Faces given to its crossing tests; past untangle_budget() of the mesh's faces it stops.
  std::size_t work = 0;
  /// Stopped before it was done: by its budget, or because the stop token was triggered.
  bool cut_short = false;
};

/// The work (faces given to crossing tests) after which untangle() makes no more edits on a mesh
/// of `faces` faces: a crumpled input can hold tens of thousands of crossing pairs, whose
/// untangling took minutes (untangle.cpp, kWorkPerFace). Every edit is whole: the mesh stays valid.
std::size_t untangle_budget(std::size_t faces);

/// Moves the vertices of crossing faces of `mesh` apart, flips and collapses their edges (see the
/// file comment). The mesh stays valid, without deleted elements, and the topology and the boundary
/// do not change. No vertex move folds a face; flips and collapses may turn faces that are turned
/// already in the tangle (their normals need not agree with the old ones), but never make a pair
/// of adjacent faces sharper than geom::adjacent_ok allows.
/// With `creases` (Params::keep_creases: the CreaseGuard's rule, crease_lines.h), a vertex on a
/// crease moves only along it and a corner not at all, an edge along a crease is never flipped, a
/// vertex on a crease is collapsed only along it into another, and no flattened disk moves a crease
/// vertex: the creases stay as the run kept them. (A flip is refused when a crease joins the edge's
/// ends, CreaseGuard::along(a, b), whatever the angle of its faces: a tangle may crumple them flat.)
/// `crossing`, when given, are the mesh's crossing face pairs as find_self_intersections() gives
/// them now (a caller that has just counted them): the search that starts the step is skipped.
/// A stop request ends it between two edits (UntangleCounts::cut_short), as does its budget.
UntangleCounts untangle(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                        unsigned threads, const CreaseGuard* creases = nullptr,
                        std::optional<std::vector<std::pair<unsigned, unsigned>>> crossing = std::nullopt,
                        std::stop_token stop = {});

/// untangle() with the crease guard, then, for the crossings that leaves, untangle() without it:
/// a crossing is worse than a crease vertex moved (equalize's last step with Params::keep_creases).
/// Without `creases`, untangle() alone. The counts are both passes' (pairs_before the first's,
/// left the second's). Measured (bench --spread --keep-creases, crossing face pairs summed over the
/// five intervals; the guard ignored -> the guard alone -> this): cheese simplified 65 -> 116 ->
/// 72, cow simplified 67 -> 86 -> 67, cow refined (whose input crosses itself) 316 -> 326 -> 317;
/// fandisk (no crossings) the same meshes throughout.
/// `crossing` as for untangle().
UntangleCounts untangle_creases_first(TriMesh& mesh, const ReferenceSurface& reference, double e_min,
                                      double e_max, unsigned threads, const CreaseGuard* creases,
                                      std::optional<std::vector<std::pair<unsigned, unsigned>>> crossing = std::nullopt,
                                      std::stop_token stop = {});

}  // namespace remesh
