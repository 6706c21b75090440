// remeshd: the remeshing service. Parses options, opens the data directory, starts the workers and
// the HTTP server, and shuts down cleanly on SIGTERM/SIGINT/SIGHUP (running jobs stay re-queueable).
#include <pthread.h>
#include <signal.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <cstdio>
#include <cstdlib>
#include <thread>

#include "http_server.h"
#include "job_manager.h"
#include "job_store.h"
#include "log.h"
#include "metrics.h"
#include "options.h"
#include "static_files.h"

namespace {
/// How long a shutdown waits for the requests in flight (after the jobs have stopped).
constexpr double kShutdownGraceSeconds = 3;
}  // namespace

int main(int argc, char** argv) {
  using namespace remeshd;
  ParseResult parsed = parse_options(argc, argv);
  if (!parsed.options) {
    std::fprintf(parsed.exit_code ? stderr : stdout, "%s\n", parsed.message.c_str());
    return parsed.exit_code;
  }
  const Options& o = *parsed.options;
  Logger log(o.log_format == "json");
#ifdef __GLIBC__
  // One malloc arena for every thread, set before any starts. With glibc's default (one per thread
  // that contends, up to 8 per core), memory a job freed stayed in its threads' arenas, unused by
  // the next job's: the daemon's resident memory grew job after job (nefertiti jobs one after
  // another on one worker: 121, 160, 199 MB after the first three, 321 MB after six). With one
  // arena it stays at 88-98 MB, and the jobs take the same time (5.6-5.8 s each; with 2 workers,
  // 8.6-9.2 s each either way: the engine allocates per phase, not per element).
  mallopt(M_ARENA_MAX, 1);
#endif

  // Signals are taken by one thread (sigwait); every other thread blocks them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  // A hangup (the terminal closed, or a supervisor's reload) stops the service as SIGTERM does; it
  // killed it, and two during one job failed that job as if it had crashed it (JobRecord::attempts).
  // Not when it was started ignoring hangups (nohup): a blocked signal is waited for even then.
  // The user signals, which it has no use for, are ignored.
  struct sigaction hup {};
  if (sigaction(SIGHUP, nullptr, &hup) == 0 && hup.sa_handler != SIG_IGN) sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  ::signal(SIGPIPE, SIG_IGN);
  ::signal(SIGUSR1, SIG_IGN);
  ::signal(SIGUSR2, SIG_IGN);

  try {
    unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    ManagerConfig mc;
    mc.workers = o.workers ? o.workers : cores;
    mc.queue_size = o.queue_size;
    mc.job_ttl_seconds = o.job_ttl_hours * 3600.0;
    mc.max_job_seconds = o.max_job_seconds;
    mc.data_cap_bytes = static_cast<std::uint64_t>(o.data_cap_mb) * 1024 * 1024;
    mc.engine_threads = std::max(1u, cores / mc.workers);

    JobStore store(o.data_dir);
    Metrics metrics;
    JobManager jobs(mc, store, log, metrics);
    std::filesystem::path web_root = resolve_web_root(o.web_root);
    HttpServer http(o, jobs, metrics, log, web_root);
    int port = http.bind();
    jobs.start();
    // An IPv6 address goes in brackets in a URL (http://[::1]:8080/).
    const std::string host = o.host.find(':') != std::string::npos ? "[" + o.host + "]" : o.host;
    log.info("listening", {str("url", "http://" + host + ":" + std::to_string(port) + "/"), num("port", port),
                           num("workers", mc.workers), str("data_dir", o.data_dir), str("web_root", web_root.string()),
                           str("auth", o.token.empty() ? "off" : "bearer token"),
                           str("cors", o.cors_origin.empty() ? "off" : o.cors_origin)});
    if (o.host != "127.0.0.1" && o.host != "localhost" && o.host != "::1" && o.token.empty())
      log.warn("security", {str("detail", "listening beyond loopback without --token")});

    std::thread signal_thread([&] {
      int sig = 0;
      sigwait(&signals, &sig);
      log.info("shutdown", {str("signal", sig == SIGTERM  ? "SIGTERM"
                                          : sig == SIGINT ? "SIGINT"
                                          : sig == SIGHUP ? "SIGHUP"
                                                          : "internal")});
      jobs.shutdown();  // interrupts running jobs; they stay 'running' on disk and run again on start
      // serve() returns when cpp-httplib 0.11's thread pool has joined every connection's thread,
      // and a connection ends when its client is done: one that sends a byte now and then (each
      // restarts the 30 s read timeout) held the exit for as long as it kept sending (QA: 34-42 s
      // after SIGTERM, a request sent a byte every 0.5 s or an upload at 1 KB/s). httplib keeps the
      // accepted sockets to itself (its per-connection loop is private), so they cannot be shut
      // down from here; past a grace for the requests in flight, the process exits without them.
      // Nothing is lost: the jobs are stopped and stored above, every file is written to a
      // temporary name and renamed (what a cut-off upload left is removed at the next start, as
      // after a kill -9), and the clients still connected see the connection close.
      if (!http.stop(kShutdownGraceSeconds)) {
        log.warn("shutdown", {str("detail", "connections still open after the grace are closed"),
                              num("grace_seconds", kShutdownGraceSeconds)});
        log.info("stopped", {});
        std::_Exit(0);
      }
    });
    bool ok = http.serve();
    pthread_kill(signal_thread.native_handle(), SIGTERM);  // no-op if it already ran
    signal_thread.join();
    jobs.shutdown();
    log.info("stopped", {});
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    log.error("fatal", {str("error", e.what())});
    return 1;
  }
}
