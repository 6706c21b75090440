#pragma once
/// \file job_manager.h
/// The jobs of the service: the in-memory table (backed by JobStore), a bounded FIFO queue, a
/// fixed pool of worker threads, cancellation, per-job event logs for SSE, expiry and the size cap.
/// All methods are thread-safe; none throws except where noted.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/job.h"
#include "job_store.h"
#include "log.h"
#include "metrics.h"

namespace remeshd {

/// One entry of a job's event log (what an SSE stream replays).
struct JobEvent {
  enum class Kind { State, Iteration } kind = Kind::State;
  remesh::api::JobState state = remesh::api::JobState::Queued;  ///< for State
  std::size_t row = 0;                                          ///< index into the rows, for Iteration
};

/// Settings of the manager (from Options).
struct ManagerConfig {
  unsigned workers = 1;
  std::size_t queue_size = 64;
  double job_ttl_seconds = 0;      ///< 0 = never expire
  std::uint64_t data_cap_bytes = 0;  ///< 0 = no cap
  unsigned engine_threads = 0;     ///< threads per job
  /// A run still going after this many seconds is stopped and the job fails, saying so (0 = no
  /// limit): a valid input can still take hours (a fan of a million spokes round one vertex).
  double max_job_seconds = 0;
};

class JobManager {
 public:
  JobManager(ManagerConfig config, JobStore& store, Logger& log, Metrics& metrics);
  ~JobManager();

  /// Loads stored jobs (re-queues the unfinished ones), starts workers and the janitor.
  void start();
  /// Stops accepting work; running jobs are interrupted and stay re-queueable on disk.
  void shutdown();

  enum class Submit { Accepted, QueueFull, ShuttingDown };
  /// Stores and queues a validated job. Throws std::runtime_error when storing fails.
  Submit submit(const remesh::api::JobRecord& job, std::string_view upload);

  std::optional<remesh::api::JobRecord> record(const std::string& id) const;
  std::optional<std::vector<remesh::IterationStats>> rows(const std::string& id) const;

  struct Page {
    std::vector<remesh::api::JobRecord> jobs;  ///< newest first
    std::size_t total = 0;                     ///< matching jobs before paging
  };
  Page list(std::optional<remesh::api::JobState> state, std::size_t limit, std::size_t offset) const;

  enum class Cancel { NotFound, Accepted, Removed };
  /// Queued -> cancelled; running -> cancelling (stops within an iteration); cancelling -> as is
  /// (all Accepted); finished -> files removed (Removed).
  Cancel cancel(const std::string& id, remesh::api::JobRecord* after = nullptr);

  /// A batch of events for an SSE stream.
  struct Batch {
    bool found = false;
    std::vector<JobEvent> events;
    std::vector<remesh::IterationStats> rows;  ///< rows for Iteration events, parallel to those events
    std::size_t cursor = 0;                    ///< pass back to the next poll
    bool ended = false;                        ///< job final and every event delivered
    remesh::api::JobState state = remesh::api::JobState::Queued;
    bool shutting_down = false;
  };
  /// Where a stream starts: after the row with iteration `last_event_id` (nullopt: the beginning);
  /// `state_before` is the job's state at that point (to send first), when starting mid-log.
  std::optional<std::size_t> start_cursor(const std::string& id, std::optional<int> last_event_id,
                                          std::optional<remesh::api::JobState>& state_before) const;
  /// Events after `cursor`; waits up to `timeout_seconds` when there are none yet.
  Batch poll(const std::string& id, std::size_t cursor, double timeout_seconds) const;
  /// Has the janitor hand freed memory back to the system in a moment (malloc_trim): after a
  /// request whose headers took megabytes, which cpp-httplib read whole and the request's end
  /// frees, but to malloc only.
  void trim_memory_soon();
  /// Wakes every waiting poll (shutdown).
  void wake_all();

  /// Is the job's directory there, whole? (Expiry and the data cap remove it before the job's entry,
  /// a DELETE after.) False once its removal has begun.
  bool stored(const std::string& id) const;
  /// Path of a stored file of a job, e.g. "remeshed.obj"; for "input.<fmt>", a result format made
  /// on request (api::made_on_request: text glTF) and a result format its job finished without
  /// (added to the service since), the file is made on first use (the results from their OBJ).
  /// Requests for one file wait for its making; other files are made meanwhile. Throws
  /// std::runtime_error (engine or I/O), std::range_error (a format that cannot hold the mesh)
  /// while making it.
  std::filesystem::path file(const std::string& id, const std::string& name);

  Gauges gauges() const;

 private:
  struct Job {
    remesh::api::JobRecord record;
    std::vector<remesh::IterationStats> rows;
    std::vector<JobEvent> events;
    std::stop_source stop;
    bool interrupted = false;  ///< stopped by shutdown, not by the user; its run taken back already
  };

  void worker_loop();
  /// May a worker take the job at the front of the queue now? A suspect (a job started before
  /// whose run the process did not live through: JobRecord::attempts >= 1) runs alone, once
  /// nothing else runs and nothing else starts while it does, so that when the process dies again
  /// the job that did it is known. Caller holds mutex_.
  bool may_start_front() const;
  bool is_suspect(const std::string& id) const;
  void run(const std::string& id);
  void janitor_loop();
  bool trim_wanted_ = false;  ///< trim_memory_soon() was called (under mutex_)
  void expire();
  /// Sets a state (and the event), persists it, logs it. Caller holds mutex_.
  void transition(Job& job, remesh::api::JobState state);
  void persist(const remesh::api::JobRecord& record);

  ManagerConfig config_;
  JobStore& store_;
  Logger& log_;
  Metrics& metrics_;

  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;  ///< any job changed (SSE waits here)
  std::condition_variable work_;             ///< queue or shutdown (workers wait here)
  std::condition_variable janitor_wake_;
  std::map<std::string, std::shared_ptr<Job>> jobs_;
  std::deque<std::string> queue_;
  std::size_t busy_ = 0;
  std::size_t active_ = 0;  ///< jobs taken from the queue by workers and not yet done with
  bool alone_ = false;      ///< a suspect runs (may_start_front)
  bool stopping_ = false;
  std::vector<std::thread> workers_;
  std::thread janitor_;
  /// file()'s making of a file, one lock per file ("<id>/<name>") while it is made: a 360 MB glTF
  /// taking 9 s held up a 31 KB conversion of another job's input as long under one lock.
  std::mutex making_mutex_;
  std::map<std::string, std::shared_ptr<std::mutex>> making_;
};

}  // namespace remeshd
