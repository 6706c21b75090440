#include "cgal_isotropic.h"

#include <chrono>
#include <stdexcept>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>

namespace remesh::bench {

double run_cgal_isotropic(const std::string& in_path, const std::string& out_path, double target,
                          unsigned iterations) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  namespace PMP = CGAL::Polygon_mesh_processing;
  Mesh mesh;
  if (!CGAL::IO::read_polygon_mesh(in_path, mesh)) throw std::runtime_error("CGAL cannot read " + in_path);
  const auto start = std::chrono::steady_clock::now();
  PMP::isotropic_remeshing(faces(mesh), target, mesh, CGAL::parameters::number_of_iterations(iterations));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  mesh.collect_garbage();
  if (!CGAL::IO::write_polygon_mesh(out_path, mesh, CGAL::parameters::stream_precision(17)))
    throw std::runtime_error("CGAL cannot write " + out_path);
  return seconds;
}

}  // namespace remesh::bench
