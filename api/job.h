#pragma once
/// \file job.h
/// The job model of the service: states, the record kept per job, and its JSON document (the
/// public shape of GET /api/v1/jobs/{id}, also what remeshd persists as state.json).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "dual/dual_stats.h"
#include "remesh/equalize.h"
#include "remesh/params.h"
#include "remesh/surface_distance.h"

namespace remesh::api {

/// queued -> running -> succeeded | failed | cancelled; queued/running -> cancelling -> cancelled.
enum class JobState { Queued, Running, Succeeded, Failed, Cancelling, Cancelled };

/// "queued", "running", "succeeded", "failed", "cancelling", "cancelled".
std::string_view state_name(JobState s);
/// Inverse of state_name; nullopt for anything else.
std::optional<JobState> parse_state(std::string_view s);
/// succeeded, failed, cancelled: nothing will change any more.
bool is_final(JobState s);

/// Seconds since the Unix epoch (UTC) with sub-second precision.
double now_seconds();
/// "2026-11-22T02:53:42.123Z" (milliseconds, UTC).
std::string iso8601(double unix_seconds);

/// Everything the service keeps about a job. Times are Unix seconds; nullopt = not yet.
struct JobRecord {
  std::string id;  ///< 32 lowercase hex characters
  JobState state = JobState::Queued;
  double created_at = 0;
  std::optional<double> started_at, finished_at;
  Params params;
  bool weld = false;
  std::string filename;        ///< as uploaded (display only, never a path)
  std::string format;          ///< format name of the input ("obj", ...)
  std::size_t bytes = 0;       ///< uploaded size
  nlohmann::json summary;      ///< to_json(MeshSummary) of the validated input
  nlohmann::json repairs = nlohmann::json::array();  ///< [{kind, count, detail}]
  int iteration = 0;           ///< iterations done
  std::optional<IterationStats> latest;
  std::optional<std::string> outcome;  ///< "converged", "completed", "cancelled"
  /// Of the result: its edges outside the interval and those in parts of the input too thin for
  /// any edge there to be inside (remesh/thin_parts.h); nullopt until the job succeeded.
  std::optional<ThinParts> thin_parts;
  /// Of the result: its pairs of faces that cross each other (Result::crossing_pairs); nullopt
  /// until the job succeeded.
  std::optional<std::size_t> crossing_pairs;
  /// Of the result: it lies over itself throughout, its crossing pairs not counted (Result::layered).
  bool layered = false;
  /// Of the result: the files its formats cannot hold ("remeshed.stl", "dual.glb": float32 past
  /// 3.4e38), made on demand only to be refused; their links are left out.
  std::vector<std::string> unwritable;
  /// Of the result: its triangles' shapes (Result::triangles); nullopt until the job succeeded.
  std::optional<TriangleQuality> triangles;
  /// Of the run that succeeded: where its time went, step by step (Result::phases), and the
  /// remeshing call's own seconds (Result::seconds); nullopt until the job succeeded.
  struct StepSeconds {
    PhaseSeconds steps;
    double total = 0;
  };
  std::optional<StepSeconds> seconds_by_step;
  /// Of the result's trivalent dual as an atom lattice (dual/dual_stats.h), its bonds judged
  /// against [e_min, e_max] / sqrt(3); nullopt until the job succeeded.
  std::optional<DualStats> dual;
  /// How far the result lies from the input (remesh/surface_distance.h); nullopt until the job
  /// succeeded.
  std::optional<SurfaceDistance> distance_to_input;
  std::optional<std::string> error;
  /// Runs started. Counted when a run starts and taken back when a shutdown is asked for (stored
  /// then, before the run stops: a kill during the grace period does not count it); a run the
  /// process did not live through otherwise (a crash, a kill) stays counted. A job counted already
  /// runs alone after a restart (nothing beside it), and one counted kMaxAttempts times is not run
  /// again (it fails, named so): an input that crashes the engine cannot take the service down at
  /// every start, and a job that only ran beside it is not blamed.
  int attempts = 0;
};

/// Runs of a job the service starts at most (JobRecord::attempts).
inline constexpr int kMaxAttempts = 2;

/// The public job document (see api/openapi.yaml, schema Job). `prefix` is the API root
/// ("/api/v1"); `now` (Unix seconds) closes open timing intervals.
nlohmann::json job_to_json(const JobRecord& job, std::string_view prefix, double now);

/// Reads back a document written by job_to_json (links and timings are ignored). Throws
/// std::runtime_error naming the bad field.
JobRecord job_from_json(const nlohmann::json& j);

/// "converged", "completed", "stalled" or "cancelled" (remesh::outcome_name).
std::string_view outcome_name(Outcome o);

/// Result kinds and the formats each can be downloaded in.
const std::vector<std::string>& remeshed_formats();  ///< obj, glb, gltf, ply, off, stl, lammps
const std::vector<std::string>& dual_formats();      ///< obj, glb, gltf, ply, off, xyz, lammps
/// A format made from the job's OBJ on its first download instead of written when the job ends:
/// text glTF ("gltf"), the GLB's document with its buffer in base64, a third larger than the GLB.
bool made_on_request(std::string_view format);

/// A fresh job id: 128 random bits from std::random_device as 32 lowercase hex characters.
std::string new_job_id();
/// True for exactly 32 characters of [0-9a-f] (so an id can name a directory safely).
bool is_valid_job_id(std::string_view id);

}  // namespace remesh::api
