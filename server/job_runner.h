#pragma once
/// \file job_runner.h
/// The engine work of one job, free of threads and HTTP: read the stored upload, remesh, and
/// serialise the remeshed mesh and its trivalent dual in every download format.

#include <functional>
#include <stop_token>
#include <string>
#include <vector>
#include <string_view>

#include "api/job.h"
#include "dual/dual_stats.h"
#include "remesh/equalize.h"

namespace remeshd {

struct RunOutput {
  /// The engine's, whole (outcome, thin parts, crossing pairs, seconds by step); its outcome is
  /// Cancelled also when a stop came during the dual's relaxation.
  remesh::Result result;
  remesh::DualStats dual;  ///< the dual's, against [e_min, e_max] / sqrt(3) (not when cancelled)
  /// The result files its formats cannot hold ("remeshed.stl": float32 past 3.4e38), not written.
  std::vector<std::string> unwritable;
  /// How far the result lies from the input (not when cancelled).
  remesh::SurfaceDistance distance;
};

/// Receives each result file as soon as it is serialised: its name ("remeshed.obj", "dual.glb",
/// ...) and bytes, which it must not keep (they are freed when it returns).
using FileSink = std::function<void(const std::string& name, std::string_view bytes)>;

/// Runs the job described by `job` on `upload`, which is freed once read (an upload of up to the
/// service's 256 MB limit is not held through the run). `threads` engine threads (0 = all cores).
/// Unless the run is cancelled, the remeshed mesh and its dual go to `write` in every download
/// format, one file at a time (so the run's peak holds one serialised file, not ten).
/// Throws whatever the engine or `write` throws (the caller marks the job failed with the message).
RunOutput run_job(const remesh::api::JobRecord& job, std::string upload, unsigned threads,
                  const remesh::OnIteration& on_iteration, std::stop_token stop, const FileSink& write);

/// The validated input (read as the job read it) in `format` ("obj", "glb", ...).
std::string convert_input(const remesh::api::JobRecord& job, std::string_view upload, const std::string& format);

/// A result run_job() wrote as OBJ (`obj`, its bytes: "v x y z" and "f i j k ..." lines, polygons
/// kept) in `format`: for a job finished by a daemon that did not write that format yet.
std::string convert_result(std::string_view obj, const std::string& format);

}  // namespace remeshd
