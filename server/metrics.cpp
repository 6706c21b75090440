#include "metrics.h"

#include <chrono>

#include "api/json_codec.h"

namespace remeshd {

namespace {

double steady_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr double kRateWindow = 10.0;  ///< seconds averaged by remeshd_iterations_per_second

std::string esc(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\\' || c == '"') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

/// The method as a label: the methods a client of this service may send, else "other". A label of
/// whatever name a request carried made a series of each: 3000 requests with random 7000-character
/// methods (each a 400) grew /metrics from 23 KB to 21.5 MB, held for the process's life.
const char* method_label(const std::string& method) {
  for (const char* known : {"GET", "HEAD", "POST", "PUT", "DELETE", "OPTIONS", "PATCH"})
    if (method == known) return known;
  return "other";
}

}  // namespace

void Metrics::observe_request(const std::string& method, const std::string& route, int status, double seconds) {
  std::lock_guard lock(mutex_);
  ++requests_[{method_label(method), route, status}];
  Histogram& h = latency_[route];
  for (std::size_t i = 0; i < kBuckets.size(); ++i)
    if (seconds <= kBuckets[i]) ++h.buckets[i];
  ++h.count;
  h.sum += seconds;
}

void Metrics::count_iteration() {
  double now = steady_now();
  std::lock_guard lock(mutex_);
  ++iterations_;
  recent_iterations_.push_back(now);
  while (!recent_iterations_.empty() && recent_iterations_.front() < now - kRateWindow)
    recent_iterations_.pop_front();
}

void Metrics::count_job_finished(const std::string& state) {
  std::lock_guard lock(mutex_);
  ++finished_[state];
}

void Metrics::count_busy(Busy reason) {
  std::lock_guard lock(mutex_);
  ++busy_[static_cast<std::size_t>(reason)];
}

std::string Metrics::render(const Gauges& g) {
  using remesh::format_double;
  std::string o;
  o += "# HELP remeshd_jobs Jobs known to the service, by state.\n# TYPE remeshd_jobs gauge\n";
  for (const auto& [state, n] : g.jobs_by_state)
    o += "remeshd_jobs{state=\"" + state + "\"} " + std::to_string(n) + "\n";
  o += "# HELP remeshd_queue_depth Jobs waiting for a worker.\n# TYPE remeshd_queue_depth gauge\n";
  o += "remeshd_queue_depth " + std::to_string(g.queue_depth) + "\n";
  o += "# HELP remeshd_busy_workers Workers running a job.\n# TYPE remeshd_busy_workers gauge\n";
  o += "remeshd_busy_workers " + std::to_string(g.busy_workers) + "\n";
  o += "# HELP remeshd_workers Worker threads.\n# TYPE remeshd_workers gauge\n";
  o += "remeshd_workers " + std::to_string(g.workers) + "\n";
  o += "# HELP remeshd_event_streams Open event streams.\n# TYPE remeshd_event_streams gauge\n";
  o += "remeshd_event_streams " + std::to_string(g.open_streams) + "\n";
  o += "# HELP remeshd_uploads_reading Large uploads being read into meshes (a slot of --upload-slots each).\n"
       "# TYPE remeshd_uploads_reading gauge\n";
  o += "remeshd_uploads_reading " + std::to_string(g.uploads_reading) + "\n";
  o += "# HELP remeshd_uploads_waiting Large uploads waiting for a slot.\n# TYPE remeshd_uploads_waiting gauge\n";
  o += "remeshd_uploads_waiting " + std::to_string(g.uploads_waiting) + "\n";

  std::lock_guard lock(mutex_);
  double now = steady_now();
  while (!recent_iterations_.empty() && recent_iterations_.front() < now - kRateWindow)
    recent_iterations_.pop_front();
  o += "# HELP remeshd_iterations_total Remesh iterations done (all jobs).\n"
       "# TYPE remeshd_iterations_total counter\n";
  o += "remeshd_iterations_total " + std::to_string(iterations_) + "\n";
  o += "# HELP remeshd_iterations_per_second Iterations per second over the last 10 seconds.\n"
       "# TYPE remeshd_iterations_per_second gauge\n";
  o += "remeshd_iterations_per_second " + format_double(recent_iterations_.size() / kRateWindow) + "\n";
  o += "# HELP remeshd_jobs_finished_total Jobs that reached a final state since start.\n"
       "# TYPE remeshd_jobs_finished_total counter\n";
  for (const char* s : {"succeeded", "failed", "cancelled"})
    o += std::string("remeshd_jobs_finished_total{state=\"") + s + "\"} " + std::to_string(finished_[s]) + "\n";
  // Every reason from the start (0), so that a rate over it needs no first refusal.
  o += "# HELP remeshd_busy_refusals_total Requests answered 503, by reason.\n"
       "# TYPE remeshd_busy_refusals_total counter\n";
  for (const auto& [reason, name] : {std::pair{Busy::QueueFull, "queue_full"}, {Busy::UploadSlots, "upload_slots"},
                                     {Busy::EventStreams, "event_streams"}, {Busy::ShuttingDown, "shutting_down"}})
    o += std::string("remeshd_busy_refusals_total{reason=\"") + name + "\"} " +
         std::to_string(busy_[static_cast<std::size_t>(reason)]) + "\n";
  o += "# HELP remeshd_http_requests_total HTTP requests by method, route and status.\n"
       "# TYPE remeshd_http_requests_total counter\n";
  for (const auto& [key, n] : requests_) {
    const auto& [method, route, status] = key;
    o += "remeshd_http_requests_total{method=\"" + esc(method) + "\",route=\"" + esc(route) + "\",status=\"" +
         std::to_string(status) + "\"} " + std::to_string(n) + "\n";
  }
  o += "# HELP remeshd_http_request_duration_seconds HTTP request latency by route.\n"
       "# TYPE remeshd_http_request_duration_seconds histogram\n";
  for (const auto& [route, h] : latency_) {
    std::string r = esc(route);
    for (std::size_t i = 0; i < kBuckets.size(); ++i)
      o += "remeshd_http_request_duration_seconds_bucket{route=\"" + r + "\",le=\"" + format_double(kBuckets[i]) +
           "\"} " + std::to_string(h.buckets[i]) + "\n";
    o += "remeshd_http_request_duration_seconds_bucket{route=\"" + r + "\",le=\"+Inf\"} " + std::to_string(h.count) + "\n";
    o += "remeshd_http_request_duration_seconds_sum{route=\"" + r + "\"} " + format_double(h.sum) + "\n";
    o += "remeshd_http_request_duration_seconds_count{route=\"" + r + "\"} " + std::to_string(h.count) + "\n";
  }
  return o;
}

}  // namespace remeshd
