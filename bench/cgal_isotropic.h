#pragma once
/// \file cgal_isotropic.h
/// The CGAL anchor of the benchmark, in its own translation unit (CGAL is heavy to compile and is
/// GPL: it is linked into the benchmark only, never into the product).

#include <string>

namespace remesh::bench {

/// Reads `in_path` into a CGAL Surface_mesh, runs PMP::isotropic_remeshing(faces, target, mesh,
/// number_of_iterations(iterations)) with nothing protected (the settings of
/// ../shared/tools/meshqa/src/cgal_remesh.cpp) and writes `out_path`. Returns the seconds of the
/// remeshing call alone. Throws std::runtime_error on I/O failure.
double run_cgal_isotropic(const std::string& in_path, const std::string& out_path, double target,
                          unsigned iterations);

}  // namespace remesh::bench
