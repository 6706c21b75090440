#pragma once
/// \file options.h
/// remeshd's configuration: command-line options, each also read from an environment variable
/// (REMESHD_<NAME>, e.g. REMESHD_PORT); the command line wins over the environment.

#include <cstddef>
#include <optional>
#include <string>

namespace remeshd {

struct Options {
  std::string host = "127.0.0.1";     ///< listen address; loopback unless told otherwise
  int port = 8080;                    ///< 0 = any free port (printed at start)
  unsigned workers = 0;               ///< remesh worker threads; 0 = number of cores
  std::string data_dir;               ///< "" = $XDG_STATE_HOME/remeshd, else ~/.local/state/remeshd, else ./remeshd-data
  std::size_t max_upload_mb = 256;    ///< largest upload body, MiB
  std::size_t max_faces = 2'000'000;  ///< largest input mesh, faces
  std::size_t max_output_faces = 5'000'000;  ///< largest estimated result, faces
  int max_iterations = 1000;          ///< largest `iterations` parameter
  std::size_t queue_size = 64;        ///< queued (not yet running) jobs before 503
  double job_ttl_hours = 168;         ///< finished jobs are removed after this; 0 = never
  std::size_t data_cap_mb = 10240;    ///< size cap of the data directory, MiB; 0 = none
  double max_job_seconds = 3600;      ///< a run is stopped (the job fails) after this long; 0 = none
  std::string token;                  ///< "" = no authentication
  std::string cors_origin;            ///< "" = CORS off; "*" or an origin
  std::string log_format = "text";    ///< text | json
  std::string web_root;               ///< "" = built-in default (see server/README.md)
  unsigned http_threads = 0;          ///< HTTP thread pool; 0 = max_streams + 16
  unsigned max_streams = 64;          ///< concurrent SSE streams before 503
  unsigned upload_slots = 0;          ///< large uploads read at once (upload_gate.h); 0 = as many as workers
  double upload_wait_seconds = 60;    ///< a large upload waits this long for a slot, then 503
  double stream_lifetime_seconds = 300;  ///< an SSE stream ends after this with a retry: hint
  double heartbeat_seconds = 15;      ///< `: ping` comment interval on idle streams
};

/// What parse_options decided.
struct ParseResult {
  std::optional<Options> options;  ///< set when the daemon should run
  std::string message;             ///< help text (exit 0) or the error (exit 2) when not
  int exit_code = 0;
};

/// Parses argv (and the environment). `--help` gives the help text; an unknown option or a bad
/// value gives a one-line error naming it.
ParseResult parse_options(int argc, char** argv);

/// The help text.
std::string help_text();

/// The data directory to use when none is given.
std::string default_data_dir();

}  // namespace remeshd
