// Benchmark (not a test): N large uploads sent at once, to a daemon whose upload gate lets all of
// them be read at once (--upload-slots N) and to one with the default gate (as many slots as its 2
// workers), in the same run. Every upload is read and refused after reading (--max-output-faces 1:
// 413), so the daemon's peak memory (VmHWM) is that of reading meshes, with no job running.
// Prints, for each: the peak, the time until the last answer, the slowest and fastest answer, and
// the ratios gated / ungated.
// usage: bench_uploads [uploads=8] [subdiv=7]   (an icosphere of 20 * 4^subdiv faces, as OBJ)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "daemon.h"

using namespace remesh::test;
using Clock = std::chrono::steady_clock;

namespace {

/// VmHWM of process `pid`, MB.
double peak_mb(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + line.find_first_of("0123456789")) / 1024.0;
  return 0;
}

struct Figures {
  double peak_mb = 0, all_seconds = 0, slowest = 0, fastest = 1e300;
  int answered = 0;
};

Figures run(const std::string& mesh, int uploads, const std::string& slots) {
  TempDir tmp;
  std::vector<std::string> args = {"--workers", "2", "--max-output-faces", "1", "--http-threads", "96"};
  if (!slots.empty()) args.insert(args.end(), {"--upload-slots", slots});
  Daemon d(tmp.path / "data", args);
  Figures f;
  std::vector<double> seconds(static_cast<std::size_t>(uploads), -1);
  std::vector<std::thread> clients;
  const Clock::time_point t0 = Clock::now();
  for (int i = 0; i < uploads; ++i)
    clients.emplace_back([&, i] {
      auto c = d.client();
      c.set_read_timeout(600, 0);
      auto r = submit_raw(c, mesh, "emin=0.02&emax=0.03");
      if (r && r->status == 413) seconds[static_cast<std::size_t>(i)] = std::chrono::duration<double>(Clock::now() - t0).count();
    });
  for (auto& t : clients) t.join();
  f.all_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  f.peak_mb = peak_mb(d.pid());
  for (double s : seconds)
    if (s >= 0) ++f.answered, f.slowest = std::max(f.slowest, s), f.fastest = std::min(f.fastest, s);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  const int uploads = argc > 1 ? std::atoi(argv[1]) : 8;
  const int subdiv = argc > 2 ? std::atoi(argv[2]) : 7;
  const std::string mesh = sphere_obj(subdiv);
  std::printf("remeshd upload bench: %d uploads at once of an icosphere OBJ, %d faces, %.1f MB; each read, then "
              "refused for its estimated output (413)\n",
              uploads, 20 << (2 * subdiv), static_cast<double>(mesh.size()) / 1e6);
  const Figures open = run(mesh, uploads, std::to_string(uploads));
  const Figures gated = run(mesh, uploads, "");
  for (const auto& [name, f] : {std::pair{"all read at once (--upload-slots N)", open},
                                std::pair{"default gate (2 slots)             ", gated}})
    std::printf("  %s: peak %.0f MB, last answer %.2f s (answers %.2f-%.2f s), %d of %d answered 413\n", name,
                f.peak_mb, f.all_seconds, f.fastest, f.slowest, f.answered, uploads);
  std::printf("  gated / all at once: peak %.2fx, last answer %.2fx\n", gated.peak_mb / open.peak_mb,
              gated.all_seconds / open.all_seconds);
  return 0;
}
