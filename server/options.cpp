#include "options.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <stdexcept>
#include <vector>

namespace remeshd {

namespace {

/// The longest heartbeat and stream lifetime, a day: an event stream's waits are time points, and
/// --heartbeat-seconds 1e10 overflowed them (the stream then pinged in a busy loop).
constexpr double kMaxStreamSeconds = 86400;

/// One option: its name (also the env name REMESHD_<NAME upper, '-' -> '_'>), help, setter.
struct Spec {
  const char* name;
  const char* value_name;
  const char* help;
  std::function<void(Options&, const std::string&)> set;
};

/// The most worker or HTTP threads (`--workers 100000` failed after 3 s with "Resource temporarily
/// unavailable", not naming the option).
constexpr std::size_t kMaxThreads = 4096;

std::size_t to_size(const std::string& name, const std::string& v, std::size_t max = SIZE_MAX) {
  std::size_t out = 0;
  auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (ec != std::errc() || p != v.data() + v.size() || v.empty())
    throw std::invalid_argument("--" + name + ": '" + v + "' is not a non-negative integer");
  if (out > max) throw std::invalid_argument("--" + name + ": " + v + " is more than " + std::to_string(max));
  return out;
}

double to_double(const std::string& name, const std::string& v) {
  double out = 0;
  auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (ec != std::errc() || p != v.data() + v.size() || v.empty() || !std::isfinite(out) || out < 0)
    throw std::invalid_argument("--" + name + ": '" + v + "' is not a non-negative number");
  return out;
}

const std::vector<Spec>& specs() {
  static const std::vector<Spec> s = {
      {"host", "ADDR", "listen address (default 127.0.0.1; 0.0.0.0 exposes the service)",
       [](Options& o, const std::string& v) { o.host = v; }},
      {"port", "N", "listen port (default 8080; 0 = any free port)",
       [](Options& o, const std::string& v) {
         std::size_t p = to_size("port", v);
         if (p > 65535) throw std::invalid_argument("--port: " + v + " is not a port (0..65535)");
         o.port = static_cast<int>(p);
       }},
      {"workers", "N", "remesh worker threads (default: number of cores)",
       [](Options& o, const std::string& v) { o.workers = static_cast<unsigned>(to_size("workers", v, kMaxThreads)); }},
      {"data-dir", "DIR",
       "job storage (default $XDG_STATE_HOME/remeshd, else ~/.local/state/remeshd, else ./remeshd-data)",
       [](Options& o, const std::string& v) { o.data_dir = v; }},
      {"max-upload-mb", "N", "largest upload in MiB (default 256; 1 to 1048576)",
       [](Options& o, const std::string& v) {
         // In bytes it must fit the byte counts: 2^44 MiB wrapped round to a limit of 0.
         o.max_upload_mb = to_size("max-upload-mb", v);
         if (o.max_upload_mb < 1 || o.max_upload_mb > 1'048'576)
           throw std::invalid_argument("--max-upload-mb: " + v + " is not 1 to 1048576 (MiB)");
       }},
      {"max-faces", "N", "largest input mesh in faces (default 2000000; 0 = no limit)",
       [](Options& o, const std::string& v) { o.max_faces = to_size("max-faces", v); }},
      {"max-output-faces", "N", "largest estimated result in faces (default 5000000; 0 = no limit)",
       [](Options& o, const std::string& v) { o.max_output_faces = to_size("max-output-faces", v); }},
      {"max-iterations", "N", "largest iterations parameter (default 1000)",
       [](Options& o, const std::string& v) {
         std::size_t n = to_size("max-iterations", v);
         if (n < 1 || n > 1'000'000) throw std::invalid_argument("--max-iterations: must be 1..1000000");
         o.max_iterations = static_cast<int>(n);
       }},
      {"max-job-seconds", "S", "a run still going after S seconds is stopped and its job fails (default 3600; 0 = no limit)",
       [](Options& o, const std::string& v) {
         o.max_job_seconds = to_double("max-job-seconds", v);
         if (!(o.max_job_seconds >= 0 && o.max_job_seconds <= 1e7))
           throw std::invalid_argument("--max-job-seconds: " + v + " is not 0 to 10000000");
       }},
      {"queue-size", "N", "queued jobs accepted before 503 (default 64, at least 1)",
       [](Options& o, const std::string& v) {
         // 0 started a service that answered every job 503 'queue is full (0 jobs)'.
         o.queue_size = to_size("queue-size", v);
         if (o.queue_size < 1) throw std::invalid_argument("--queue-size: must be at least 1 (a job waits there for a worker)");
       }},
      {"job-ttl-hours", "H", "finished jobs are deleted after H hours (default 168; 0 = never)",
       [](Options& o, const std::string& v) { o.job_ttl_hours = to_double("job-ttl-hours", v); }},
      {"data-cap-mb", "N", "size cap of the data directory in MiB, oldest finished jobs go first (default 10240; 0 = none)",
       [](Options& o, const std::string& v) {
         o.data_cap_mb = to_size("data-cap-mb", v);
         if (o.data_cap_mb > (std::size_t{1} << 40))
           throw std::invalid_argument("--data-cap-mb: " + v + " is past 2^40 MiB (0 = no cap)");
       }},
      {"token", "T", "require 'Authorization: Bearer T' on every /api route (default: none)",
       [](Options& o, const std::string& v) {
         // An empty one (REMESHD_TOKEN=${UNSET} in a compose file) served every route without one.
         if (v.empty())
           throw std::invalid_argument("--token (or REMESHD_TOKEN) is empty; leave it out to serve without a token");
         o.token = v;
       }},
      {"cors-origin", "O", "allow cross-origin requests from O ('*' = any; default: CORS off)",
       [](Options& o, const std::string& v) { o.cors_origin = v; }},
      {"log-format", "text|json", "log line format (default text)",
       [](Options& o, const std::string& v) {
         if (v != "text" && v != "json") throw std::invalid_argument("--log-format: '" + v + "' is not text or json");
         o.log_format = v;
       }},
      {"web-root", "DIR", "directory of the web page (default: the build's web/ or <exe>/../web)",
       [](Options& o, const std::string& v) { o.web_root = v; }},
      {"http-threads", "N", "HTTP thread pool size (default: max-streams + 16)",
       [](Options& o, const std::string& v) {
         o.http_threads = static_cast<unsigned>(to_size("http-threads", v, kMaxThreads));
       }},
      {"max-streams", "N", "concurrent event streams before 503 (default 64)",
       [](Options& o, const std::string& v) {
         // At most what leaves the HTTP threads' default, max-streams + 16, within kMaxThreads.
         o.max_streams = static_cast<unsigned>(to_size("max-streams", v, kMaxThreads - 16));
         // 0 answered every event stream with 503.
         if (o.max_streams == 0) throw std::invalid_argument("--max-streams: at least 1");
       }},
      {"upload-slots", "N",
       "uploads of 1 MiB or more turned into meshes at once; more wait (default: as many as workers)",
       [](Options& o, const std::string& v) {
         o.upload_slots = static_cast<unsigned>(to_size("upload-slots", v, kMaxThreads));
       }},
      {"upload-wait-seconds", "S", "how long a large upload waits for a slot before a 503 (default 60)",
       [](Options& o, const std::string& v) {
         o.upload_wait_seconds = to_double("upload-wait-seconds", v);
         if (!(o.upload_wait_seconds >= 0 && o.upload_wait_seconds <= 3600))
           throw std::invalid_argument("--upload-wait-seconds: 0 to 3600");
       }},
      {"stream-lifetime-seconds", "S", "an event stream ends after S seconds; clients reconnect (default 300)",
       [](Options& o, const std::string& v) {
         o.stream_lifetime_seconds = to_double("stream-lifetime-seconds", v);
         if (!(o.stream_lifetime_seconds >= 1 && o.stream_lifetime_seconds <= kMaxStreamSeconds))
           throw std::invalid_argument("--stream-lifetime-seconds: 1 to 86400");
       }},
      {"heartbeat-seconds", "S", "': ping' comment interval on idle streams (default 15)",
       [](Options& o, const std::string& v) {
         o.heartbeat_seconds = to_double("heartbeat-seconds", v);
         if (!(o.heartbeat_seconds >= 0.1 && o.heartbeat_seconds <= kMaxStreamSeconds))
           throw std::invalid_argument("--heartbeat-seconds: 0.1 to 86400");
       }},
  };
  return s;
}

std::string env_name(const std::string& option) {
  std::string e = "REMESHD_";
  for (char c : option) e += c == '-' ? '_' : static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return e;
}

}  // namespace

std::string default_data_dir() {
  if (const char* x = std::getenv("XDG_STATE_HOME"); x && *x) return std::string(x) + "/remeshd";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.local/state/remeshd";
  return "./remeshd-data";
}

std::string help_text() {
  std::string t =
      "remeshd: the remeshing service (HTTP API under /api/v1, web page at /)\n\n"
      "usage: remeshd [options]\n\n"
      "Every option can also be set by an environment variable (shown); the command line wins.\n\n";
  for (const Spec& s : specs()) {
    std::string left = std::string("  --") + s.name + " " + s.value_name;
    if (left.size() < 34) left.resize(34, ' ');
    t += left + " " + s.help + "  [" + env_name(s.name) + "]\n";
  }
  t += "  --help                             this text\n";
  return t;
}

ParseResult parse_options(int argc, char** argv) {
  ParseResult result;
  Options o;
  try {
    for (const Spec& s : specs())
      if (const char* v = std::getenv(env_name(s.name).c_str())) s.set(o, v);
    for (int i = 1; i < argc; ++i) {
      std::string arg = argv[i];
      if (arg == "--help" || arg == "-h") {
        result.message = help_text();
        return result;
      }
      if (arg.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument '" + arg + "' (see --help)");
      std::string name = arg.substr(2), value;
      bool has_value = false;
      if (auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        has_value = true;
      }
      const Spec* spec = nullptr;
      for (const Spec& s : specs())
        if (name == s.name) spec = &s;
      if (!spec) throw std::invalid_argument("unknown option '--" + name + "' (see --help)");
      if (!has_value) {
        if (i + 1 >= argc) throw std::invalid_argument("--" + name + " needs a value");
        value = argv[++i];
      }
      spec->set(o, value);
    }
  } catch (const std::invalid_argument& e) {
    result.message = std::string("remeshd: ") + e.what();
    result.exit_code = 2;
    return result;
  }
  if (o.data_dir.empty()) o.data_dir = default_data_dir();
  result.options = o;
  return result;
}

}  // namespace remeshd
