#pragma once
/// \file priority_list.h
/// Algorithm 2: the edges whose length lies outside [m_i - sigma, m_i + sigma], worst first
/// (sorted by |length - m_i| descending; ties by edge index, so the order is deterministic).

#include <vector>

#include "core/mesh.h"

namespace remesh {

/// Edge indices of the priority list. Lengths are measured in parallel.
std::vector<unsigned> make_priority_list(const TriMesh& mesh, double m_i, double sigma, unsigned threads);

}  // namespace remesh
