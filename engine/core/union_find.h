#pragma once
/// \file union_find.h
/// The root of x in a disjoint-set forest `parent` (parent[i] == i at a root), halving the path
/// on the way. Callers join two roots themselves (which one becomes the root is theirs to choose).

#include <vector>

namespace remesh {

template <class Index>
Index find_root(std::vector<Index>& parent, Index x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace remesh
