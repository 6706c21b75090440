#include "job_runner.h"

#include <stdexcept>

#include "dual/trivalent_dual.h"
#include "io/mesh_io.h"
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

RunOutput run_job(const remesh::api::JobRecord& job, std::string_view upload, unsigned threads,
                  const remesh::OnIteration& on_iteration, std::stop_token stop) {
  remesh::LoadedMesh loaded = read_input(job, upload);
  remesh::TriMesh mesh = loaded.mesh;
  remesh::Params params = job.params;
  params.threads = threads;
  remesh::Result result = remesh::equalize(mesh, params, on_iteration, stop);

  RunOutput out;
  out.outcome = result.outcome;
  out.iterations_done = result.iterations_done;
  out.thin = result.thin;
  out.phases = result.phases;
  out.seconds = result.seconds;
  if (result.outcome == remesh::Outcome::Cancelled) return out;

  collect_garbage(mesh);
  for (const std::string& f : remesh::api::remeshed_formats())
    out.files["remeshed." + f] = remesh::write_mesh(mesh, format_of(f));
  remesh::ReferenceSurface reference(loaded.mesh);
  remesh::PolyMesh dual = remesh::trivalent_dual(mesh, &reference);
  for (const std::string& f : remesh::api::dual_formats())
    out.files["dual." + f] = remesh::write_mesh(dual, format_of(f));
  return out;
}

std::string convert_input(const remesh::api::JobRecord& job, std::string_view upload, const std::string& format) {
  remesh::LoadedMesh loaded = read_input(job, upload);
  return remesh::write_mesh(loaded.mesh, format_of(format));
}

}  // namespace remeshd
