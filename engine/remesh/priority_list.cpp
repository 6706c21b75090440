#include "remesh/priority_list.h"

#include <algorithm>
#include <cmath>

#include "remesh/statistics.h"

namespace remesh {

std::vector<unsigned> make_priority_list(const TriMesh& mesh, double m_i, double sigma, unsigned threads) {
  const std::vector<double> lengths = edge_lengths(mesh, threads);
  std::vector<unsigned> list;
  for (unsigned i = 0; i < lengths.size(); ++i) {
    if (mesh.status(mesh.edge_handle(i)).deleted()) continue;
    if (lengths[i] > m_i + sigma || lengths[i] < m_i - sigma) list.push_back(i);
  }
  std::sort(list.begin(), list.end(), [&](unsigned a, unsigned b) {
    const double da = std::abs(lengths[a] - m_i), db = std::abs(lengths[b] - m_i);
    return da != db ? da > db : a < b;
  });
  return list;
}

}  // namespace remesh
