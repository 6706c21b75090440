#pragma once
/// \file metrics.h
/// Counters and histograms of the service, rendered as Prometheus text (GET /metrics).

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <tuple>

namespace remeshd {

/// Gauges owned by others, read at scrape time.
struct Gauges {
  std::map<std::string, std::size_t> jobs_by_state;  ///< every state name, 0 included
  std::size_t queue_depth = 0;
  std::size_t busy_workers = 0;
  std::size_t workers = 0;
  std::size_t open_streams = 0;
  std::size_t uploads_reading = 0;  ///< large uploads holding a slot of the upload gate
  std::size_t uploads_waiting = 0;  ///< and waiting for one
};

class Metrics {
 public:
  /// Records one finished HTTP request. `route` is the pattern ("/api/v1/jobs/{id}"); a method
  /// other than GET, HEAD, POST, PUT, DELETE, OPTIONS and PATCH is counted as "other".
  void observe_request(const std::string& method, const std::string& route, int status, double seconds);
  /// Counts one remesh iteration (any job).
  void count_iteration();
  /// Counts a job reaching a final state.
  void count_job_finished(const std::string& state);
  /// Why a request got a 503: the job queue was full, no upload slot came free in time, the event
  /// streams were all taken, or the service was stopping.
  enum class Busy { QueueFull, UploadSlots, EventStreams, ShuttingDown };
  /// Counts one 503 by its reason (remeshd_busy_refusals_total{reason}).
  void count_busy(Busy reason);
  /// Prometheus text exposition format 0.0.4.
  std::string render(const Gauges& gauges);

  /// Upper bounds of the latency histogram, seconds.
  static constexpr std::array<double, 12> kBuckets = {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05,
                                                       0.1,   0.25,   0.5,   1,    2.5,   10};

 private:
  struct Histogram {
    std::array<std::uint64_t, kBuckets.size()> buckets{};
    std::uint64_t count = 0;
    double sum = 0;
  };
  std::mutex mutex_;
  std::map<std::tuple<std::string, std::string, int>, std::uint64_t> requests_;  ///< method, route, status
  std::map<std::string, Histogram> latency_;                                       ///< by route
  std::uint64_t iterations_ = 0;
  std::deque<double> recent_iterations_;  ///< steady-clock times of the last minute's iterations
  std::map<std::string, std::uint64_t> finished_;
  std::array<std::uint64_t, 4> busy_{};  ///< by Busy
};

}  // namespace remeshd
