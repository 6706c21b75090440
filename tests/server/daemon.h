#pragma once
// Test helpers: start the real remeshd executable on a free loopback port with a temporary data
// directory, talk to it with httplib::Client, stop it with SIGTERM or SIGKILL.
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace remesh::test {

/// A temporary directory removed at destruction.
struct TempDir {
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::filesystem::path path;
};

class Daemon {
 public:
  /// Starts remeshd with `args` (plus --host 127.0.0.1 --port 0 --data-dir <data_dir>) and waits
  /// until it listens. Throws std::runtime_error (with the log) if it does not start within 10 s.
  Daemon(const std::filesystem::path& data_dir, std::vector<std::string> args = {});
  ~Daemon();  ///< SIGTERM, then SIGKILL after 10 s

  int port() const { return port_; }
  int pid() const { return pid_; }
  /// A client for the daemon (timeouts 30 s); `token` sets the bearer header.
  httplib::Client client(const std::string& token = "") const;
  /// Sends `sig` and waits for the process; returns its exit status (or 128 + signal).
  int stop(int sig);
  const std::string& log_path() const { return log_; }
  std::string log() const;

 private:
  int pid_ = -1;
  int port_ = 0;
  std::string log_;
};

/// An icosphere with 20 * 4^subdiv faces, radius 1, as OBJ text.
std::string sphere_obj(int subdiv);

/// POST the mesh raw with query parameters; returns the result (status, body).
httplib::Result submit_raw(httplib::Client& c, const std::string& mesh, const std::string& query,
                           const std::string& content_type = "model/obj");
/// POST the mesh raw with query parameters; the new job's id. Throws (with the answer) unless 202.
std::string submit(httplib::Client& c, const std::string& mesh, const std::string& query);
/// The job document or throws.
nlohmann::json get_job(httplib::Client& c, const std::string& id);
/// Polls until `pred(job)` holds; returns the job. Throws after `timeout` seconds.
nlohmann::json wait_job(httplib::Client& c, const std::string& id,
                        const std::function<bool(const nlohmann::json&)>& pred, double timeout = 60);
/// Polls until the job is in a final state.
nlohmann::json wait_final(httplib::Client& c, const std::string& id, double timeout = 60);

/// One parsed server-sent event.
struct SseEvent {
  std::string event;  ///< "message" when absent
  std::string id;
  std::string data;
};
/// Reads an event stream until it ends (or `timeout` seconds); returns the events and the comment
/// lines and retry hints seen.
struct SseStream {
  std::vector<SseEvent> events;
  std::vector<std::string> comments;
  std::vector<std::string> retries;
  int status = 0;
  bool completed = false;  ///< the server ended the stream
};
SseStream read_events(int port, const std::string& path, const httplib::Headers& headers = {}, double timeout = 60);

/// Sends `request` (raw bytes: a request line, headers, maybe a body) to 127.0.0.1:`port` and
/// returns what the server answers until it closes or sends nothing for `timeout` seconds.
/// A socket connected to the daemon on loopback `port`, its reads timing out after `timeout`
/// seconds and its receive buffer `receive_buffer` bytes when not 0 (a client that reads slowly);
/// -1 when it cannot connect.
int connect_local(int port, double timeout, int receive_buffer = 0);
std::string raw_exchange(int port, const std::string& request, double timeout);
/// The same with the request sent in parts, `pause` seconds apart (each part its own segment).
std::string raw_exchange(int port, const std::vector<std::string>& parts, double pause, double timeout);

/// A slow client on a thread of its own: connects to 127.0.0.1:`port`, sends `head`, then `unit`
/// every `period` seconds until `stop` is set, a send fails or `limit` seconds have passed.
std::thread slow_client(int port, std::string head, std::string unit, double period, const std::atomic<bool>& stop,
                        double limit = 60);

/// Files (recursively) under a directory.
std::size_t count_files(const std::filesystem::path& dir);

}  // namespace remesh::test
