#pragma once
/// \file job_store.h
/// remeshd's data directory. Layout: <data>/jobs/<id>/ with
///   upload          the bytes as uploaded (re-read when the job runs or is re-run)
///   state.json      the job document (written atomically on every state change)
///   stats.jsonl     one statistics row per line, appended per iteration
///   remeshed.<fmt>, dual.<fmt>, input.<fmt>   results and input conversions (atomic)
/// A job directory appears complete or not at all (built as .tmp-<id>, then renamed). Job ids are
/// validated as 32 hex characters before they name anything.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/job.h"

namespace remeshd {

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, fsync, rename,
/// fsync of the directory. Throws std::runtime_error naming the path on failure.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);
/// Whole file; throws std::runtime_error naming the path.
std::string read_file(const std::filesystem::path& path);

class JobStore {
 public:
  /// Creates <data_dir>/jobs if needed, locks <data_dir>/lock (one daemon per directory) and
  /// removes leftovers of interrupted creations. Throws std::runtime_error if the directory cannot
  /// be used or another process holds it.
  explicit JobStore(std::filesystem::path data_dir);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  const std::filesystem::path& root() const { return root_; }

  /// Stores a new job: its upload and state. Throws std::runtime_error on I/O failure (nothing
  /// is left behind then).
  void create(const remesh::api::JobRecord& job, std::string_view upload);
  /// Rewrites state.json atomically.
  void save_state(const remesh::api::JobRecord& job);
  /// Appends one row to stats.jsonl (not synced: rows are re-made when a job is re-run).
  void append_stats(const std::string& id, const remesh::IterationStats& row);
  /// Empties stats.jsonl (a job that runs again starts over).
  void clear_stats(const std::string& id);
  /// When stats.jsonl was last written (seconds since the epoch, as api::now_seconds()): the last
  /// row of a run the process did not live through. Nullopt if it cannot be read.
  std::optional<double> stats_written_at(const std::string& id) const;
  /// Every complete row of stats.jsonl (a torn last line is skipped).
  std::vector<remesh::IterationStats> load_stats(const std::string& id) const;
  /// The uploaded bytes.
  std::string read_upload(const std::string& id) const;
  /// Path of a stored file of the job (`name` is one of our fixed names, never client text).
  std::filesystem::path file_path(const std::string& id, const std::string& name) const;
  /// Writes a result file atomically.
  void write_file(const std::string& id, const std::string& name, std::string_view bytes);
  /// Removes the job's result files (remeshed.*, dual.*), keeping its upload, state and statistics
  /// (a job cancelled after they were written; no error for files already gone).
  void remove_results(const std::string& id);
  /// Removes the job's directory (no error if it is gone), renamed away first so that nothing
  /// written for the job meanwhile brings it back.
  void remove(const std::string& id);
  /// Bytes used by the job's directory.
  std::uint64_t job_bytes(const std::string& id) const;

  struct Loaded {
    remesh::api::JobRecord record;
    std::vector<remesh::IterationStats> rows;
  };
  /// Every stored job with a readable state; `problems` gets one line per directory skipped.
  std::vector<Loaded> load_all(std::vector<std::string>& problems) const;

 private:
  std::filesystem::path dir(const std::string& id) const;
  std::filesystem::path root_;  ///< <data_dir>/jobs
  int lock_fd_ = -1;            ///< flock()ed <data_dir>/lock
};

}  // namespace remeshd
