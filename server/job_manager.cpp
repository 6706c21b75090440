#include "job_manager.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <stop_token>
#include <thread>
#include <utility>

#include "api/json_codec.h"
#include "job_runner.h"

namespace remeshd {

using remesh::IterationStats;
using remesh::api::JobRecord;
using remesh::api::JobState;
using remesh::api::now_seconds;
using remesh::api::state_name;

namespace {

std::chrono::duration<double> secs(double s) { return std::chrono::duration<double>(s); }

}  // namespace

JobManager::JobManager(ManagerConfig config, JobStore& store, Logger& log, Metrics& metrics)
    : config_(config), store_(store), log_(log), metrics_(metrics) {
  config_.workers = std::max(1u, config_.workers);
}

JobManager::~JobManager() { shutdown(); }

void JobManager::persist(const JobRecord& record) {
  try {
    store_.save_state(record);
  } catch (const std::exception& e) {
    log_.error("storage", {str("job", record.id), str("error", e.what())});
  }
}

void JobManager::transition(Job& job, JobState state) {
  JobRecord& r = job.record;
  JobState from = r.state;
  r.state = state;
  double now = now_seconds();
  if (state == JobState::Running) r.started_at = now, ++r.attempts;
  if (remesh::api::is_final(state)) {
    r.finished_at = now;
    metrics_.count_job_finished(std::string(state_name(state)));
    janitor_wake_.notify_all();
  }
  job.events.push_back({JobEvent::Kind::State, state, 0});
  persist(r);
  std::vector<LogField> fields = {str("job", r.id), str("from", std::string(state_name(from))),
                                  str("to", std::string(state_name(state)))};
  if (r.outcome) fields.push_back(str("outcome", *r.outcome));
  if (r.error) fields.push_back(str("error", *r.error));
  if (r.started_at && remesh::api::is_final(state)) fields.push_back(num("run_seconds", now - *r.started_at));
  log_.info("job", fields);
  changed_.notify_all();
}

void JobManager::start() {
  std::vector<std::string> problems;
  std::vector<JobStore::Loaded> loaded = store_.load_all(problems);
  for (const std::string& p : problems) log_.warn("storage", {str("skipped", p)});
  std::sort(loaded.begin(), loaded.end(),
            [](const auto& a, const auto& b) { return a.record.created_at < b.record.created_at; });
  std::size_t requeued = 0;
  // A run the process did not live through ended after its last row, not when the process started
  // again: its finish is the time its rows were last written (at least its start), so that
  // run_seconds does not count the time the service was down.
  auto ended_at = [this](const JobRecord& r) {
    double at = now_seconds();
    if (r.started_at) at = std::max(*r.started_at, store_.stats_written_at(r.id).value_or(*r.started_at));
    return at;
  };
  {
    std::lock_guard lock(mutex_);
    for (JobStore::Loaded& l : loaded) {
      auto job = std::make_shared<Job>();
      job->record = std::move(l.record);
      JobRecord& r = job->record;
      if (r.state == JobState::Cancelling) {  // the user asked; the process ended first
        r.state = JobState::Cancelled;
        r.outcome = "cancelled";
        r.finished_at = ended_at(r);
        persist(r);
      }
      if (remesh::api::is_final(r.state)) {
        job->rows = std::move(l.rows);
        job->events.push_back({JobEvent::Kind::State, JobState::Queued, 0});
        if (r.started_at) job->events.push_back({JobEvent::Kind::State, JobState::Running, 0});
        for (std::size_t i = 0; i < job->rows.size(); ++i)
          job->events.push_back({JobEvent::Kind::Iteration, r.state, i});
        job->events.push_back({JobEvent::Kind::State, r.state, 0});
      } else {
        // Accepted but not finished: the rows of the run it did not finish go either way (when
        // they were written is kept first, for a job failed below).
        const double run_ended = ended_at(r);
        try {
          store_.clear_stats(r.id);
        } catch (const std::exception& e) {
          log_.warn("storage", {str("job", r.id), str("error", e.what())});
        }
        r.iteration = 0;
        r.latest.reset();
        job->events.push_back({JobEvent::Kind::State, JobState::Queued, 0});
        if (r.attempts >= remesh::api::kMaxAttempts) {
          // The process ended during each of its runs, and not by a shutdown: the input may crash
          // the engine. Failed, not run again (JobRecord::attempts).
          r.state = JobState::Failed;
          r.error = "the service stopped " + std::to_string(r.attempts) +
                    " times while running this job (a crash or a kill); it is not run again";
          r.finished_at = run_ended;
          metrics_.count_job_finished(std::string(state_name(JobState::Failed)));
          log_.warn("job", {str("job", r.id), str("to", "failed"), str("error", *r.error)});
          job->events.push_back({JobEvent::Kind::State, JobState::Failed, 0});
        } else {  // run it (again) from the start
          r.state = JobState::Queued;
          r.started_at.reset();
          queue_.push_back(r.id);
          ++requeued;
        }
        persist(r);
      }
      jobs_[r.id] = job;
    }
  }
  log_.info("storage", {str("dir", store_.root().string()), num("jobs", static_cast<double>(loaded.size())),
                        num("requeued", static_cast<double>(requeued))});
  for (unsigned i = 0; i < config_.workers; ++i) workers_.emplace_back([this] { worker_loop(); });
  janitor_ = std::thread([this] { janitor_loop(); });
}

void JobManager::shutdown() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && workers_.empty()) return;
    stopping_ = true;
    for (auto& [id, job] : jobs_) {
      if (job->record.state == JobState::Running || job->record.state == JobState::Cancelling)
        job->stop.request_stop();
      if (job->record.state != JobState::Running || job->interrupted) continue;
      // Taken back now, on disk, not when the run stops: it checks for the stop between phases
      // only, and after its last iteration not at all (making and writing the results of a
      // 138 000-face run took 1.9 s). A SIGKILL in that time (an orchestrator's grace period
      // running out) left the run counted as a crash (JobRecord::attempts).
      job->interrupted = true;
      --job->record.attempts;
      persist(job->record);
    }
  }
  work_.notify_all();
  changed_.notify_all();
  janitor_wake_.notify_all();
  for (std::thread& t : workers_)
    if (t.joinable()) t.join();
  workers_.clear();
  if (janitor_.joinable()) janitor_.join();
}

void JobManager::wake_all() { changed_.notify_all(); }

JobManager::Submit JobManager::submit(const JobRecord& record, std::string_view upload) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return Submit::ShuttingDown;
    if (queue_.size() >= config_.queue_size) return Submit::QueueFull;
  }
  store_.create(record, upload);  // outside the lock: it syncs to disk
  std::lock_guard lock(mutex_);
  auto job = std::make_shared<Job>();
  job->record = record;
  job->events.push_back({JobEvent::Kind::State, JobState::Queued, 0});
  jobs_[record.id] = job;
  queue_.push_back(record.id);
  log_.info("job", {str("job", record.id), str("to", "queued"), str("format", record.format),
                    num("bytes", static_cast<double>(record.bytes)),
                    num("faces", record.summary.value("faces", 0.0))});
  work_.notify_one();
  changed_.notify_all();
  return Submit::Accepted;
}

bool JobManager::is_suspect(const std::string& id) const {
  const auto it = jobs_.find(id);
  return it != jobs_.end() && it->second->record.state == JobState::Queued && it->second->record.attempts > 0;
}

bool JobManager::may_start_front() const {
  if (queue_.empty() || alone_) return false;
  return !is_suspect(queue_.front()) || active_ == 0;
}

void JobManager::worker_loop() {
  for (;;) {
    std::string id;
    bool suspect = false;
    {
      std::unique_lock lock(mutex_);
      work_.wait(lock, [&] { return stopping_ || may_start_front(); });
      if (stopping_) return;
      id = queue_.front();
      queue_.pop_front();
      suspect = is_suspect(id);
      alone_ = suspect;
      ++active_;
    }
    run(id);
    {
      std::lock_guard lock(mutex_);
      --active_;
      if (suspect) alone_ = false;
    }
    work_.notify_all();  // a suspect may wait for the others to end, the others for a suspect
#ifdef __GLIBC__
    // The job's memory back to the system, not only to malloc: an idle daemon holds ~20 MB
    // instead of the last job's ~90 (nefertiti, Table 4.2 setup).
    malloc_trim(0);
#endif
  }
}

void JobManager::run(const std::string& id) {
  std::shared_ptr<Job> job;
  JobRecord record;
  std::stop_token token;
  {
    std::lock_guard lock(mutex_);
    auto it = jobs_.find(id);
    // A job taken from the queue just before the shutdown stays queued: started now, it would be
    // neither stopped nor taken back (shutdown).
    if (stopping_ || it == jobs_.end() || it->second->record.state != JobState::Queued) return;
    job = it->second;
    job->record.iteration = 0;
    job->record.latest.reset();
    job->rows.clear();
    transition(*job, JobState::Running);
    ++busy_;
    record = job->record;
    token = job->stop.get_token();
  }
  // Ends the run in `state`; `fill` (under the same lock) writes a successful run's figures into
  // the record. A run that succeeded while a DELETE was answered `cancelling` (after the run's last
  // check for a stop, while its results were written) ends cancelled instead, decided under the
  // lock the DELETE takes: it ended `succeeded` (a service QA finding), and checked apart from
  // this lock a DELETE could still come between. Returns the state it ended in.
  auto finish = [&](JobState state, const std::function<void(JobRecord&)>& fill = {}) {
    std::lock_guard lock(mutex_);
    --busy_;
    if (state == JobState::Succeeded && job->record.state == JobState::Cancelling) {
      state = JobState::Cancelled;
      job->record.outcome = "cancelled";
    } else if (fill) {
      fill(job->record);
    }
    if (job->interrupted) {
      if (state == JobState::Cancelled && job->record.state == JobState::Running) {
        // Stopped by the shutdown, which took the run back already (shutdown).
        log_.info("job", {str("job", id), str("interrupted", "shutdown"),
                          str("state", "running (re-queued on start)")});
        return JobState::Running;
      }
      // It ended anyway (finished, failed, or cancelled by the user): the run counts.
      ++job->record.attempts;
    }
    transition(*job, state);
    return state;
  };
  try {
    std::string upload = store_.read_upload(id);
    store_.clear_stats(id);
    auto on_iteration = [&](const IterationStats& row) {
      store_.append_stats(id, row);
      metrics_.count_iteration();
      std::lock_guard lock(mutex_);
      job->rows.push_back(row);
      job->events.push_back({JobEvent::Kind::Iteration, JobState::Running, job->rows.size() - 1});
      job->record.latest = row;
      job->record.iteration = row.iteration;
      changed_.notify_all();
    };
    auto write = [&](const std::string& name, std::string_view bytes) { store_.write_file(id, name, bytes); };
    // The time limit: a watchdog stops the run through the job's own stop source (the engine
    // checks it between phases and within its long steps), unless the run ends first.
    std::atomic<bool> timed_out{false};
    std::jthread watchdog;
    if (config_.max_job_seconds > 0)
      watchdog = std::jthread([&timed_out, job, limit = config_.max_job_seconds](std::stop_token ended) {
        std::mutex m;
        std::condition_variable_any cv;
        std::unique_lock lock(m);
        cv.wait_for(lock, ended, secs(limit), [] { return false; });
        if (!ended.stop_requested() && !job->stop.stop_requested()) {
          timed_out = true;
          job->stop.request_stop();
        }
      });
    RunOutput out = run_job(record, std::move(upload), config_.engine_threads, on_iteration, token, write);
    watchdog = std::jthread();  // stopped and joined: timed_out is final
    const remesh::Result& result = out.result;
    if (result.outcome == remesh::Outcome::Cancelled && timed_out) {
      {
        std::lock_guard lock(mutex_);
        job->record.error = "the run took longer than the service's limit of " +
                            remesh::format_double(config_.max_job_seconds) +
                            " s (remeshd --max-job-seconds) and was stopped";
      }
      log_.warn("job", {str("job", id), str("stopped", "time limit")});
      finish(JobState::Failed);
      store_.remove_results(id);  // those written before the stop (the remeshed mesh's, say)
      return;
    }
    if (result.outcome == remesh::Outcome::Cancelled) {
      {
        std::lock_guard lock(mutex_);
        job->record.outcome = "cancelled";
      }
      if (finish(JobState::Cancelled) == JobState::Cancelled) store_.remove_results(id);
      return;
    }
    const JobState ended = finish(JobState::Succeeded, [&](JobRecord& r) {
      r.outcome = std::string(remesh::api::outcome_name(result.outcome));
      r.thin_parts = result.thin;
      r.crossing_pairs = result.crossing_pairs;
      r.layered = result.layered;
      r.triangles = result.triangles;
      r.unwritable = out.unwritable;
      r.dual = out.dual;
      r.distance_to_input = out.distance;
      r.seconds_by_step = remesh::api::JobRecord::StepSeconds{result.phases, result.seconds};
    });
    // Cancelled late: its result files go (never served: a job serves results only once it has
    // succeeded), as a job cancelled sooner has none.
    if (ended == JobState::Cancelled) store_.remove_results(id);
  } catch (const std::exception& e) {
    {
      std::lock_guard lock(mutex_);
      job->record.error = e.what();
    }
    finish(JobState::Failed);
  } catch (...) {
    {
      std::lock_guard lock(mutex_);
      job->record.error = "unknown error";
    }
    finish(JobState::Failed);
  }
}

std::optional<JobRecord> JobManager::record(const std::string& id) const {
  std::lock_guard lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return std::nullopt;
  return it->second->record;
}

std::optional<std::vector<IterationStats>> JobManager::rows(const std::string& id) const {
  std::lock_guard lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return std::nullopt;
  return it->second->rows;
}

JobManager::Page JobManager::list(std::optional<JobState> state, std::size_t limit, std::size_t offset) const {
  std::vector<const JobRecord*> matching;
  Page page;
  std::lock_guard lock(mutex_);
  for (const auto& [id, job] : jobs_)
    if (!state || job->record.state == *state) matching.push_back(&job->record);
  std::sort(matching.begin(), matching.end(), [](const JobRecord* a, const JobRecord* b) {
    return a->created_at != b->created_at ? a->created_at > b->created_at : a->id > b->id;
  });
  page.total = matching.size();
  for (std::size_t i = offset; i < matching.size() && page.jobs.size() < limit; ++i)
    page.jobs.push_back(*matching[i]);
  return page;
}

JobManager::Cancel JobManager::cancel(const std::string& id, JobRecord* after) {
  std::unique_lock lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return Cancel::NotFound;
  Job& job = *it->second;
  switch (job.record.state) {
    case JobState::Queued:
      queue_.erase(std::remove(queue_.begin(), queue_.end(), id), queue_.end());
      job.record.outcome = "cancelled";
      transition(job, JobState::Cancelled);
      break;
    case JobState::Running:
      transition(job, JobState::Cancelling);
      job.stop.request_stop();
      break;
    case JobState::Cancelling:
      break;
    default: {  // finished: remove it and its files
      jobs_.erase(it);
      changed_.notify_all();
      lock.unlock();
      store_.remove(id);
      log_.info("job", {str("job", id), str("removed", "by request")});
      return Cancel::Removed;
    }
  }
  if (after) *after = job.record;
  return Cancel::Accepted;
}

std::optional<std::size_t> JobManager::start_cursor(const std::string& id, std::optional<int> last_event_id,
                                                    std::optional<JobState>& state_before) const {
  std::lock_guard lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return std::nullopt;
  state_before.reset();
  if (!last_event_id) return 0;
  const Job& job = *it->second;
  for (std::size_t i = 0; i < job.events.size(); ++i) {
    const JobEvent& e = job.events[i];
    if (e.kind == JobEvent::Kind::State) state_before = e.state;
    if (e.kind == JobEvent::Kind::Iteration && job.rows[e.row].iteration == *last_event_id) return i + 1;
  }
  state_before.reset();  // not found (e.g. the job ran again after a restart): everything
  return 0;
}

JobManager::Batch JobManager::poll(const std::string& id, std::size_t cursor, double timeout_seconds) const {
  Batch batch;
  std::unique_lock lock(mutex_);
  auto ready = [&] {
    auto it = jobs_.find(id);
    return stopping_ || it == jobs_.end() || it->second->events.size() > cursor ||
           remesh::api::is_final(it->second->record.state);
  };
  changed_.wait_for(lock, secs(timeout_seconds), ready);
  batch.shutting_down = stopping_;
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return batch;
  const Job& job = *it->second;
  batch.found = true;
  batch.state = job.record.state;
  for (std::size_t i = cursor; i < job.events.size(); ++i) {
    batch.events.push_back(job.events[i]);
    batch.rows.push_back(job.events[i].kind == JobEvent::Kind::Iteration ? job.rows[job.events[i].row]
                                                                         : IterationStats{});
  }
  batch.cursor = std::max(cursor, job.events.size());
  batch.ended = remesh::api::is_final(job.record.state);
  return batch;
}

bool JobManager::stored(const std::string& id) const {
  std::error_code ec;
  return std::filesystem::exists(store_.file_path(id, "state.json"), ec);
}

std::filesystem::path JobManager::file(const std::string& id, const std::string& name) {
  std::filesystem::path path = store_.file_path(id, name);
  if (std::filesystem::exists(path)) return path;
  const bool input = name.starts_with("input.");
  // A result in a format added after its job finished is made from the job's OBJ of that mesh.
  const std::size_t dot = name.find('.');
  const std::filesystem::path obj = store_.file_path(id, name.substr(0, dot) + ".obj");
  if (!input && (dot == std::string::npos || !std::filesystem::exists(obj))) return path;
  const std::string key = id + "/" + name;
  std::shared_ptr<std::mutex> making;
  {
    std::lock_guard lock(making_mutex_);
    std::shared_ptr<std::mutex>& slot = making_[key];
    if (!slot) slot = std::make_shared<std::mutex>();
    making = slot;
  }
  // The entry goes when the last request for the file is done with it (made or failed).
  struct Release {
    JobManager& jobs;
    const std::string& key;
    std::shared_ptr<std::mutex>& making;
    ~Release() {
      std::lock_guard lock(jobs.making_mutex_);
      auto it = jobs.making_.find(key);
      making.reset();
      if (it != jobs.making_.end() && it->second.use_count() == 1) jobs.making_.erase(it);
    }
  } release{*this, key, making};
  std::lock_guard file_lock(*making);
  if (std::filesystem::exists(path)) return path;
  auto rec = record(id);
  if (!rec) throw std::runtime_error("job not found");
  std::string bytes = input ? convert_input(*rec, store_.read_upload(id), name.substr(6))
                            : convert_result(read_file(obj), name.substr(dot + 1));
  store_.write_file(id, name, bytes);
  // The data cap counts it now (the janitor wakes), not when the next job finishes: downloads of
  // input conversions alone grew a capped directory past its cap.
  if (config_.data_cap_bytes > 0) janitor_wake_.notify_all();
  return path;
}

Gauges JobManager::gauges() const {
  Gauges g;
  for (JobState s : {JobState::Queued, JobState::Running, JobState::Succeeded, JobState::Failed,
                     JobState::Cancelling, JobState::Cancelled})
    g.jobs_by_state[std::string(state_name(s))] = 0;
  std::lock_guard lock(mutex_);
  for (const auto& [id, job] : jobs_) ++g.jobs_by_state[std::string(state_name(job->record.state))];
  g.queue_depth = queue_.size();
  g.busy_workers = busy_;
  g.workers = config_.workers;
  return g;
}

void JobManager::trim_memory_soon() {
  {
    std::lock_guard lock(mutex_);
    trim_wanted_ = true;
  }
  janitor_wake_.notify_all();
}

void JobManager::janitor_loop() {
  double interval = config_.job_ttl_seconds > 0 ? std::clamp(config_.job_ttl_seconds / 4, 1.0, 60.0) : 60.0;
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (!trim_wanted_) janitor_wake_.wait_for(lock, secs(interval));  // a finished job wakes it too
    if (stopping_) break;
    if (std::exchange(trim_wanted_, false)) {
      // After the request is answered and its headers freed (a moment after the call).
      janitor_wake_.wait_for(lock, secs(0.2), [this] { return stopping_; });
      if (stopping_) break;
#ifdef __GLIBC__
      malloc_trim(0);
#endif
      continue;
    }
    lock.unlock();
    try {
      expire();
    } catch (const std::exception& e) {
      log_.error("janitor", {str("error", e.what())});
    }
    lock.lock();
  }
}

void JobManager::expire() {
  double now = now_seconds();
  std::vector<std::pair<double, std::string>> finished;  // (finished_at, id)
  std::vector<std::string> expired;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [id, job] : jobs_) {
      const JobRecord& r = job->record;
      if (!remesh::api::is_final(r.state) || !r.finished_at) continue;
      if (config_.job_ttl_seconds > 0 && *r.finished_at + config_.job_ttl_seconds < now) expired.push_back(id);
      else finished.emplace_back(*r.finished_at, id);
    }
  }
  // Files first, then the entry: once a job reads as gone, its directory is gone too.
  for (const std::string& id : expired) {
    store_.remove(id);
    {
      std::lock_guard lock(mutex_);
      jobs_.erase(id);
    }
    log_.info("job", {str("job", id), str("removed", "expired")});
  }
  if (config_.data_cap_bytes == 0) return;
  std::vector<std::string> all;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [id, job] : jobs_) all.push_back(id);
  }
  std::uint64_t total = 0;
  std::map<std::string, std::uint64_t> sizes;
  for (const std::string& id : all) total += sizes[id] = store_.job_bytes(id);
  std::sort(finished.begin(), finished.end());
  // Oldest first; the newest finished job is kept even if it alone is over the cap (its owner has
  // not had a chance to download it yet).
  if (!finished.empty()) finished.pop_back();
  for (const auto& [when, id] : finished) {
    if (total <= config_.data_cap_bytes) break;
    store_.remove(id);
    {
      std::lock_guard lock(mutex_);
      jobs_.erase(id);
    }
    total -= std::min(total, sizes[id]);
    log_.info("job", {str("job", id), str("removed", "data cap")});
  }
}

}  // namespace remeshd
