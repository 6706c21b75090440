#pragma once
/// \file job_runner.h
/// The engine work of one job, free of threads and HTTP: read the stored upload, remesh, and
/// serialise the remeshed mesh and its trivalent dual in every download format.

#include <map>
#include <stop_token>
#include <string>
#include <string_view>

#include "api/job.h"
#include "remesh/equalize.h"

namespace remeshd {

struct RunOutput {
  remesh::Outcome outcome = remesh::Outcome::Completed;
  int iterations_done = 0;
  remesh::ThinParts thin;  ///< Result::thin
  remesh::PhaseSeconds phases;  ///< Result::phases
  double seconds = 0;           ///< Result::seconds
  /// File name ("remeshed.obj", "dual.glb", ...) -> bytes; empty when cancelled.
  std::map<std::string, std::string> files;
};

/// Runs the job described by `job` on `upload`. `threads` engine threads (0 = all cores).
/// Throws whatever the engine throws (the caller marks the job failed with the message).
RunOutput run_job(const remesh::api::JobRecord& job, std::string_view upload, unsigned threads,
                  const remesh::OnIteration& on_iteration, std::stop_token stop);

/// The validated input (read as the job read it) in `format` ("obj", "glb", ...).
std::string convert_input(const remesh::api::JobRecord& job, std::string_view upload, const std::string& format);

}  // namespace remeshd
