#include "job_runner.h"

#include <stdexcept>

#include "dual/relax_bonds.h"
#include "dual/trivalent_dual.h"
#include "io/mesh_io.h"
#include "remesh/mesh_snapshot.h"
#include "remesh/reference_surface.h"

namespace remeshd {

namespace {

remesh::LoadedMesh read_input(const remesh::api::JobRecord& job, std::string_view upload) {
  remesh::ReadOptions options;
  options.format = remesh::parse_format(job.format);
  options.weld = job.weld;
  return remesh::read_mesh(upload, options);
}

remesh::Format format_of(const std::string& name) {
  auto f = remesh::parse_format(name);
  if (!f) throw std::invalid_argument("unknown format " + name);
  return *f;
}

}  // namespace

RunOutput run_job(const remesh::api::JobRecord& job, std::string upload, unsigned threads,
                  const remesh::OnIteration& on_iteration, std::stop_token stop, const FileSink& write) {
  remesh::LoadedMesh loaded = read_input(job, upload);
  std::string().swap(upload);
  // The run works on the loaded mesh itself; the input is kept for the dual's projection as points
  // and triangles only (48 bytes a vertex instead of a second mesh, ~200: a 2 M-face upload held
  // ~200 MB more for the whole run).
  const remesh::MeshSnapshot input(loaded.mesh);
  remesh::TriMesh& mesh = loaded.mesh;
  remesh::Params params = job.params;
  params.threads = threads;
  RunOutput out;
  out.result = remesh::equalize(mesh, params, on_iteration, stop);
  if (out.result.outcome == remesh::Outcome::Cancelled) return out;

  collect_garbage(mesh);
  for (const std::string& f : remesh::api::remeshed_formats())
    write("remeshed." + f, remesh::write_mesh(mesh, format_of(f)));
  const remesh::ReferenceSurface reference = [&] {
    remesh::TriMesh input_mesh;
    input.rebuild(input_mesh);
    return remesh::ReferenceSurface(input_mesh);
  }();
  remesh::PolyMesh dual = remesh::trivalent_dual(mesh, &reference);
  if (params.relax_dual) {
    remesh::relax_bonds(dual, params.e_min, params.e_max, reference, params.threads, stop);
    // A stop asked for meanwhile (DELETE, shutdown) cancels the job, as during the run.
    if (stop.stop_requested()) {
      out.result.outcome = remesh::Outcome::Cancelled;
      return out;
    }
  }
  out.dual = remesh::dual_stats(dual, params.e_min, params.e_max);
  for (const std::string& f : remesh::api::dual_formats())
    write("dual." + f, remesh::write_mesh(dual, format_of(f)));
  return out;
}

std::string convert_input(const remesh::api::JobRecord& job, std::string_view upload, const std::string& format) {
  remesh::LoadedMesh loaded = read_input(job, upload);
  return remesh::write_mesh(loaded.mesh, format_of(format));
}

}  // namespace remeshd
