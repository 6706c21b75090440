// Benchmark (not a test): with 2 jobs running on 2 workers and 64 SSE clients connected, measures
//   - SSE delivery delay: from an iteration's row being stored (stats.jsonl grows; polled every
//     0.5 ms) to each client receiving the event;
//   - /healthz latency percentiles, polled every 20 ms meanwhile;
//   - the daemon's resident memory (VmRSS, VmHWM) after those jobs and after each of 4 more run
//     one after another (does it hold what the jobs freed?), and with 40 downloads of a result open
//     whose clients read nothing.
// usage: bench_remeshd [clients=64] [subdiv=4] [iterations=40]
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <atomic>
#include <cstdio>
#include <mutex>
#include <thread>

#include "daemon.h"

using namespace remesh::test;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t0, Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(t - t0).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p / 100.0 * (v.size() - 1) + 0.5))];
}

}  // namespace

int main(int argc, char** argv) {
  int clients = argc > 1 ? std::atoi(argv[1]) : 64;
  int subdiv = argc > 2 ? std::atoi(argv[2]) : 4;
  int iterations = argc > 3 ? std::atoi(argv[3]) : 40;
  TempDir tmp;
  Daemon d(tmp.path / "data", {"--workers", "2", "--max-streams", std::to_string(clients + 8)});
  auto c = d.client();
  std::string query = "emin=0.03&emax=0.05&run_all_iterations=true&iterations=" + std::to_string(iterations);
  std::vector<std::string> ids;
  for (int i = 0; i < 2; ++i) {
    auto r = submit_raw(c, sphere_obj(subdiv), query);
    if (!r || r->status != 202) {
      std::fprintf(stderr, "submit failed\n");
      return 1;
    }
    ids.push_back(json::parse(r->body)["id"]);
  }
  const Clock::time_point t0 = Clock::now();

  // Row stored: watch each job's stats.jsonl grow.
  std::mutex mutex;
  std::vector<std::vector<double>> stored(2, std::vector<double>(iterations + 1, -1));
  std::atomic<bool> done{false};
  std::thread watcher([&] {
    std::vector<std::uintmax_t> lines(2, 0);
    while (!done) {
      for (int j = 0; j < 2; ++j) {
        std::ifstream in(tmp.path / "data" / "jobs" / ids[j] / "stats.jsonl");
        std::string line;
        std::uintmax_t n = 0;
        while (std::getline(in, line)) ++n;
        double now = ms_since(t0, Clock::now());
        std::lock_guard lock(mutex);
        for (std::uintmax_t k = lines[j] + 1; k <= n && k <= static_cast<std::uintmax_t>(iterations); ++k)
          stored[j][k] = now;
        lines[j] = std::max(lines[j], n);
      }
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  });

  // SSE clients: arrival time of every iteration event.
  std::vector<double> delays;
  std::vector<std::thread> readers;
  std::atomic<int> ended{0};
  for (int i = 0; i < clients; ++i)
    readers.emplace_back([&, i] {
      int job = i % 2;
      httplib::Client sc("127.0.0.1", d.port());
      sc.set_read_timeout(300);
      std::string buffer, id;
      std::vector<std::pair<int, double>> arrivals;
      double connected = -1;  // rows stored before this are history replay, not delivery
      sc.Get(("/api/v1/jobs/" + ids[job] + "/events").c_str(), [&](const char* data, size_t n) {
        double now = ms_since(t0, Clock::now());
        if (connected < 0) connected = now;
        buffer.append(data, n);
        std::size_t pos;
        while ((pos = buffer.find('\n')) != std::string::npos) {
          std::string line = buffer.substr(0, pos);
          buffer.erase(0, pos + 1);
          if (line.rfind("id: ", 0) == 0) arrivals.emplace_back(std::stoi(line.substr(4)), now);
          if (line == "event: end") ++ended;
        }
        return true;
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(50));  // let the watcher catch up
      std::lock_guard lock(mutex);
      for (auto [it, when] : arrivals)
        if (it >= 1 && it <= iterations && stored[job][it] >= connected && stored[job][it] <= when)
          delays.push_back(when - stored[job][it]);
    });

  // /healthz meanwhile.
  std::vector<double> health;
  int health_failed = 0;
  while (ended.load() < clients) {
    httplib::Client h("127.0.0.1", d.port());
    h.set_read_timeout(10);
    auto t = Clock::now();
    auto r = h.Get("/healthz");
    double ms = ms_since(t, Clock::now());
    if (r && r->status == 200) health.push_back(ms);
    else ++health_failed;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (ms_since(t0, Clock::now()) > 600'000) break;
  }
  for (auto& t : readers) t.join();
  done = true;
  watcher.join();
  json job = get_job(c, ids[0]);
  std::printf("remeshd bench: 2 jobs (icosphere subdiv %d -> ~%d faces, %d iterations) on 2 workers, %d SSE clients\n",
              subdiv, job["latest"].is_null() ? 0 : static_cast<int>(job["latest"]["edges"].get<double>() * 2 / 3),
              iterations, clients);
  std::printf("  run time %.1f s, mean iteration %.1f ms\n", ms_since(t0, Clock::now()) / 1000,
              job["timings"]["run_seconds"].get<double>() * 1000 / iterations);
  std::printf("  SSE delivery delay (row stored -> client), %zu samples: p50 %.2f ms  p90 %.2f ms  p99 %.2f ms  max %.2f ms\n",
              delays.size(), percentile(delays, 50), percentile(delays, 90), percentile(delays, 99),
              percentile(delays, 100));
  std::printf("  /healthz latency, %zu requests (%d failed): p50 %.2f ms  p90 %.2f ms  p99 %.2f ms  max %.2f ms\n",
              health.size(), health_failed, percentile(health, 50), percentile(health, 90), percentile(health, 99),
              percentile(health, 100));
  auto memory = [&] {  // "resident X MB (peak Y MB)" from /proc/<pid>/status
    std::ifstream in("/proc/" + std::to_string(d.pid()) + "/status");
    std::string line, rss = "?", hwm = "?";
    while (std::getline(in, line)) {
      auto kb = [&] { return std::to_string(std::atol(line.c_str() + line.find_first_of("0123456789")) / 1024); };
      if (line.rfind("VmRSS:", 0) == 0) rss = kb();
      if (line.rfind("VmHWM:", 0) == 0) hwm = kb();
    }
    return "resident " + rss + " MB (peak " + hwm + " MB)";
  };
  for (const auto& id : ids) wait_final(c, id, 600);
  std::printf("  after the 2 jobs: %s\n", memory().c_str());
  std::printf("  4 more, one after another, after each:");
  std::string last;
  for (int i = 0; i < 4; ++i) {
    auto r = submit_raw(c, sphere_obj(subdiv), query);
    if (!r || r->status != 202) {
      std::fprintf(stderr, "submit failed\n");
      return 1;
    }
    last = json::parse(r->body)["id"];
    wait_final(c, last, 600);
    std::printf("%s %s", i ? ";" : "", memory().c_str());
  }
  std::printf("\n");

  // Downloads whose clients read nothing: each holds what the daemon keeps for it (QA: a copy of
  // the whole file each, before downloads were read from the file as the client takes them). The
  // file is larger than the socket buffers take in (loopback's grow to 4 MB): a job of its own.
  last = submit(c, sphere_obj(5), "emin=0.012&emax=0.018&iterations=10");
  wait_final(c, last, 600);
  std::printf("  after a larger job (icosphere subdiv 5 at [0.012, 0.018]): %s\n", memory().c_str());
  const std::string path = "/api/v1/jobs/" + last + "/result?mesh=dual&format=lammps";
  auto file = c.Get(path.c_str());
  if (!file || file->status != 200) {
    std::fprintf(stderr, "download failed\n");
    return 1;
  }
  constexpr int kStalled = 40;
  std::vector<int> sockets;
  for (int i = 0; i < kStalled; ++i) {
    const int fd = connect_local(d.port(), 30, 4096);
    if (fd < 0) continue;
    const std::string request = "GET " + path + " HTTP/1.1\r\nHost: x\r\n\r\n";
    (void)::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
    sockets.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::seconds(3));
  std::printf("  %d downloads of a %.1f MB file, none read: %s\n", kStalled, static_cast<double>(file->body.size()) / 1e6,
              memory().c_str());
  for (int fd : sockets) ::close(fd);
  std::this_thread::sleep_for(std::chrono::seconds(2));
  std::printf("  after they closed: %s\n", memory().c_str());
  return 0;
}
