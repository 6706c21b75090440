#include "remesh/statistics.h"

#include <cmath>
#include <vector>

#include "core/parallel.h"
#include "remesh/geometry.h"

namespace remesh {

namespace {
constexpr std::size_t kBlock = 4096;

struct EdgeSums {
  std::size_t count = 0, small = 0, big = 0;
  double sum = 0, sum_dev2 = 0;
};
}  // namespace

std::vector<double> edge_lengths(const TriMesh& mesh, unsigned threads) {
  std::vector<double> lengths(mesh.n_edges(), 0.0);
  parallel_for(mesh.n_edges(), threads, [&](std::size_t i) {
    const auto e = mesh.edge_handle(static_cast<unsigned>(i));
    if (!mesh.status(e).deleted()) lengths[i] = mesh.calc_edge_length(e);
  }, kBlock);
  return lengths;
}

double mean_edge_length(const TriMesh& mesh, unsigned threads) {
  const std::size_t n = mesh.n_edges();
  std::vector<EdgeSums> blocks(block_count(n, kBlock));
  parallel_blocks(n, kBlock, threads, [&](std::size_t b, std::size_t e, std::size_t block) {
    EdgeSums s;
    for (std::size_t i = b; i < e; ++i) {
      const auto eh = mesh.edge_handle(static_cast<unsigned>(i));
      if (mesh.status(eh).deleted()) continue;
      s.sum += mesh.calc_edge_length(eh);
      ++s.count;
    }
    blocks[block] = s;
  });
  EdgeSums total;
  for (const auto& s : blocks) total.sum += s.sum, total.count += s.count;
  return total.count ? total.sum / static_cast<double>(total.count) : 0.0;
}

double surface_area(const TriMesh& mesh) {
  double area = 0;
  for (auto f : mesh.faces())
    if (!mesh.status(f).deleted()) area += 0.5 * geom::face_normal(mesh, f).norm();
  return area;
}

IterationStats measure(const TriMesh& mesh, double e_min, double e_max, unsigned threads) {
  IterationStats row;
  const std::vector<double> lengths = edge_lengths(mesh, threads);
  const std::size_t n = lengths.size();
  const std::size_t nb = block_count(n, kBlock);
  std::vector<EdgeSums> blocks(nb);
  auto live = [&](std::size_t i) { return !mesh.status(mesh.edge_handle(static_cast<unsigned>(i))).deleted(); };
  parallel_blocks(n, kBlock, threads, [&](std::size_t b, std::size_t e, std::size_t block) {
    EdgeSums s;
    for (std::size_t i = b; i < e; ++i) {
      if (!live(i)) continue;
      ++s.count;
      s.sum += lengths[i];
      if (lengths[i] < e_min) ++s.small;
      if (lengths[i] > e_max) ++s.big;
    }
    blocks[block] = s;
  });
  EdgeSums total;
  for (const auto& s : blocks) {
    total.count += s.count, total.small += s.small, total.big += s.big;
    total.sum += s.sum;
  }
  const double mean = total.count ? total.sum / static_cast<double>(total.count) : 0.0;
  parallel_blocks(n, kBlock, threads, [&](std::size_t b, std::size_t e, std::size_t block) {
    double s = 0;
    for (std::size_t i = b; i < e; ++i)
      if (live(i)) s += (lengths[i] - mean) * (lengths[i] - mean);
    blocks[block].sum_dev2 = s;
  });
  for (const auto& s : blocks) total.sum_dev2 += s.sum_dev2;

  // Vertices, interior vertices, regular ones: counted per block (integers: any order adds up the same).
  struct VertexCounts {
    std::size_t vertices = 0, interior = 0, regular = 0;
  };
  std::vector<VertexCounts> vertex_blocks(block_count(mesh.n_vertices(), kBlock));
  parallel_blocks(mesh.n_vertices(), kBlock, threads, [&](std::size_t b, std::size_t e, std::size_t block) {
    VertexCounts c;
    for (std::size_t i = b; i < e; ++i) {
      const auto v = mesh.vertex_handle(static_cast<unsigned>(i));
      if (mesh.status(v).deleted()) continue;
      ++c.vertices;
      if (mesh.is_boundary(v)) continue;  // includes isolated vertices
      ++c.interior;
      if (vertex_valence(mesh, v) == 6) ++c.regular;
    }
    vertex_blocks[block] = c;
  });
  std::size_t interior = 0, regular = 0, vertices = 0;
  for (const VertexCounts& c : vertex_blocks) vertices += c.vertices, interior += c.interior, regular += c.regular;
  row.vertices = vertices;
  row.edges = total.count;
  row.mean = mean;
  row.deviation = total.count ? std::sqrt(total.sum_dev2 / static_cast<double>(total.count)) : 0.0;
  row.regular_percent = interior ? 100.0 * static_cast<double>(regular) / static_cast<double>(interior) : 0.0;
  row.small = total.small;
  row.big = total.big;
  row.inside_fraction =
      total.count ? static_cast<double>(total.count - total.small - total.big) / static_cast<double>(total.count) : 1.0;
  return row;
}

}  // namespace remesh
