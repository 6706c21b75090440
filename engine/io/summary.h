#pragma once
/// \file summary.h
/// What a user wants to know about a mesh before remeshing it.

#include <cstddef>
#include <vector>

#include "core/mesh.h"

namespace remesh {

struct ComponentSummary {
  std::size_t vertices = 0, faces = 0, edges = 0;
  std::size_t boundary_loops = 0;
  long euler = 0;  ///< V - E + F of the component
  int genus = 0;   ///< (2 - euler - boundary_loops) / 2
  bool closed = false;
};

struct MeshSummary {
  std::size_t vertices = 0, faces = 0, edges = 0;
  std::size_t components = 0, boundary_loops = 0, boundary_edges = 0;
  long euler = 0;
  std::vector<ComponentSummary> per_component;  ///< in order of their lowest vertex index
  Vec3 bbox_min{0, 0, 0}, bbox_max{0, 0, 0};
  double bbox_diagonal = 0;
  double mean_edge = 0, min_edge = 0, max_edge = 0;
  double area = 0;
};

MeshSummary summarize(const TriMesh& mesh);

}  // namespace remesh
