#include "job_runner.h"

#include <algorithm>
#include <charconv>
#include <stdexcept>

#include "dual/relax_bonds.h"
#include "dual/trivalent_dual.h"
#include "io/mesh_io.h"
#include "remesh/mesh_snapshot.h"
#include "remesh/reference_surface.h"
#include "remesh/surface_distance.h"

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

  // A stop asked for after the run's last check (DELETE, shutdown) cancels the job before its files
  // are written (and before the dual's), as during the run.
  auto stopped = [&] {
    const bool now = stop.stop_requested();
    if (now) out.result.outcome = remesh::Outcome::Cancelled;
    return now;
  };
  if (stopped()) return out;
  collect_garbage(mesh);
  // A format that cannot hold the result (STL, GLB and glTF store float32: a mesh placed beyond
  // 3.4e38) is not written; a download of it makes it then, and is refused saying why. The job
  // succeeds with the others. Text glTF is made on request; it holds what GLB holds.
  auto write_each = [&](const std::string& stem, const auto& m, const std::vector<std::string>& formats) {
    for (const std::string& f : formats) {
      if (remesh::api::made_on_request(f)) {
        const auto& none = out.unwritable;
        if (std::find(none.begin(), none.end(), stem + ".glb") != none.end()) out.unwritable.push_back(stem + "." + f);
        continue;
      }
      std::string bytes;
      try {
        bytes = remesh::write_mesh(m, format_of(f));
      } catch (const std::range_error&) {
        out.unwritable.push_back(stem + "." + f);
        continue;
      }
      write(stem + "." + f, bytes);
    }
  };
  write_each("remeshed", mesh, remesh::api::remeshed_formats());
  const remesh::ReferenceSurface reference = [&] {
    remesh::TriMesh input_mesh;
    input.rebuild(input_mesh);
    out.distance = remesh::surface_distance(mesh, input_mesh, params.threads);
    return remesh::ReferenceSurface(input_mesh);
  }();
  remesh::PolyMesh dual = remesh::trivalent_dual(mesh, &reference);
  if (params.relax_dual) {
    // A stop asked for meanwhile ends the relaxation, and is taken below.
    remesh::relax_bonds(dual, params.e_min, params.e_max, reference, params.threads, stop);
  }
  if (stopped()) return out;
  out.dual = remesh::dual_stats(dual, params.e_min, params.e_max);
  write_each("dual", dual, remesh::api::dual_formats());
  return out;
}

std::string convert_input(const remesh::api::JobRecord& job, std::string_view upload, const std::string& format) {
  remesh::LoadedMesh loaded = read_input(job, upload);
  return remesh::write_mesh(loaded.mesh, format_of(format));
}

std::string convert_result(std::string_view obj, const std::string& format) {
  remesh::PolygonSoup soup;
  auto fail = [] { throw std::runtime_error("the stored OBJ result is malformed"); };
  // The numbers of a line after its keyword, as doubles (whitespace-separated).
  auto numbers = [&](std::string_view line, auto&& take) {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && line[i] == ' ') ++i;
      if (i == line.size()) break;
      double x = 0;
      const auto [end, ec] = std::from_chars(line.data() + i, line.data() + line.size(), x);
      if (ec != std::errc()) fail();
      take(x);
      i = static_cast<std::size_t>(end - line.data());
    }
  };
  while (!obj.empty()) {
    const std::size_t nl = obj.find('\n');
    std::string_view line = obj.substr(0, nl);
    obj.remove_prefix(nl == std::string_view::npos ? obj.size() : nl + 1);
    if (line.starts_with("v ")) {
      remesh::Vec3 p(0, 0, 0);
      int k = 0;
      numbers(line.substr(2), [&](double x) { k < 3 ? void(p[k++] = x) : fail(); });
      if (k != 3) fail();
      soup.points.push_back(p);
    } else if (line.starts_with("f ")) {
      numbers(line.substr(2), [&](double i) {
        if (!(i >= 1 && i <= static_cast<double>(soup.points.size()))) fail();
        soup.indices.push_back(static_cast<std::uint32_t>(i) - 1);
      });
      soup.offsets.push_back(static_cast<std::uint32_t>(soup.indices.size()));
    }
  }
  return remesh::write_mesh(soup, format_of(format));
}

}  // namespace remeshd
