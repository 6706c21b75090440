#include "daemon.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "io/mesh_io.h"
#include "support/mesh_generators.h"

namespace remesh::test {

namespace fs = std::filesystem;

TempDir::TempDir() {
  std::random_device rd;
  path = fs::temp_directory_path() / ("remeshd-test-" + std::to_string(rd()) + std::to_string(rd()));
  fs::create_directories(path);
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path, ec);
}

Daemon::Daemon(const fs::path& data_dir, std::vector<std::string> args) {
  static int counter = 0;
  log_ = (data_dir.parent_path() / ("remeshd-" + std::to_string(getpid()) + "-" + std::to_string(++counter) + ".log"))
             .string();
  std::vector<std::string> argv = {REMESHD_EXE, "--host", "127.0.0.1", "--port", "0", "--data-dir", data_dir.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    FILE* f = std::fopen(log_.c_str(), "w");
    if (f) {
      dup2(fileno(f), 2);
      dup2(fileno(f), 1);
    }
    std::vector<char*> cargv;
    for (auto& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    execv(cargv[0], cargv.data());
    _exit(127);
  }
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline) {
    std::string text = log();
    auto pos = text.find("listening");
    if (pos != std::string::npos) {
      auto p = text.find(" port=", pos);
      if (p != std::string::npos) {
        port_ = std::stoi(text.substr(p + 6));
        return;
      }
    }
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw std::runtime_error("remeshd exited at start: " + text);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  stop(SIGKILL);
  throw std::runtime_error("remeshd did not start: " + log());
}

Daemon::~Daemon() {
  if (pid_ > 0) stop(SIGTERM);
}

int Daemon::stop(int sig) {
  if (pid_ <= 0) return -1;
  kill(pid_, sig);
  int status = 0;
  for (int i = 0; i < 1000; ++i) {
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid_, SIGKILL);
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return 128 + SIGKILL;
}

std::string Daemon::log() const {
  std::ifstream in(log_);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

httplib::Client Daemon::client(const std::string& token) const {
  httplib::Client c("127.0.0.1", port_);
  c.set_connection_timeout(10);
  c.set_read_timeout(30);
  c.set_write_timeout(30);
  if (!token.empty()) c.set_bearer_token_auth(token.c_str());
  return c;
}

std::string sphere_obj(int subdiv) { return write_mesh(make_icosphere(subdiv), Format::Obj); }

httplib::Result submit_raw(httplib::Client& c, const std::string& mesh, const std::string& query,
                           const std::string& content_type) {
  return c.Post(("/api/v1/jobs?" + query).c_str(), mesh, content_type.c_str());
}

std::string submit(httplib::Client& c, const std::string& mesh, const std::string& query) {
  auto r = submit_raw(c, mesh, query);
  if (!r) throw std::runtime_error("POST /api/v1/jobs?" + query + ": no answer");
  if (r->status != 202)
    throw std::runtime_error("POST /api/v1/jobs?" + query + ": " + std::to_string(r->status) + " " + r->body);
  return nlohmann::json::parse(r->body)["id"];
}

nlohmann::json get_job(httplib::Client& c, const std::string& id) {
  auto r = c.Get(("/api/v1/jobs/" + id).c_str());
  if (!r || r->status != 200) throw std::runtime_error("GET job " + id + " failed");
  return nlohmann::json::parse(r->body);
}

nlohmann::json wait_job(httplib::Client& c, const std::string& id,
                        const std::function<bool(const nlohmann::json&)>& pred, double timeout) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  for (;;) {
    nlohmann::json j = get_job(c, id);
    if (pred(j)) return j;
    if (std::chrono::steady_clock::now() > deadline)
      throw std::runtime_error("timeout waiting for job " + id + ": " + j.dump());
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

nlohmann::json wait_final(httplib::Client& c, const std::string& id, double timeout) {
  return wait_job(
      c, id,
      [](const nlohmann::json& j) {
        std::string s = j["state"];
        return s == "succeeded" || s == "failed" || s == "cancelled";
      },
      timeout);
}

SseStream read_events(int port, const std::string& path, const httplib::Headers& headers, double timeout) {
  SseStream out;
  httplib::Client c("127.0.0.1", port);
  c.set_read_timeout(static_cast<time_t>(timeout));
  std::string buffer;
  SseEvent current;
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  auto flush_line = [&](const std::string& line) {
    if (line.empty()) {
      if (!current.data.empty() || !current.event.empty() || !current.id.empty()) {
        if (current.event.empty()) current.event = "message";
        if (!current.data.empty() && current.data.back() == '\n') current.data.pop_back();
        out.events.push_back(current);
      }
      current = SseEvent{};
      return;
    }
    if (line[0] == ':') {
      out.comments.push_back(line.substr(1));
      return;
    }
    auto colon = line.find(':');
    std::string field = line.substr(0, colon);
    std::string value = colon == std::string::npos ? "" : line.substr(colon + 1);
    if (!value.empty() && value[0] == ' ') value.erase(0, 1);
    if (field == "event") current.event = value;
    else if (field == "id") current.id = value;
    else if (field == "data") current.data += value + "\n";
    else if (field == "retry") out.retries.push_back(value);
  };
  auto res = c.Get(
      path.c_str(), headers,
      [&](const httplib::Response& r) {
        out.status = r.status;
        return true;
      },
      [&](const char* data, size_t n) {
        buffer.append(data, n);
        std::size_t pos;
        while ((pos = buffer.find('\n')) != std::string::npos) {
          flush_line(buffer.substr(0, pos));
          buffer.erase(0, pos + 1);
        }
        return std::chrono::steady_clock::now() < deadline;
      });
  out.completed = static_cast<bool>(res);
  if (res) out.status = res->status;
  return out;
}

std::string raw_exchange(int port, const std::string& request, double timeout) {
  return raw_exchange(port, std::vector<std::string>{request}, 0, timeout);
}

int connect_local(int port, double timeout, int receive_buffer) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  timeval tv{};
  tv.tv_sec = static_cast<long>(timeout);
  tv.tv_usec = static_cast<long>((timeout - static_cast<double>(tv.tv_sec)) * 1e6);
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  if (receive_buffer > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

std::string raw_exchange(int port, const std::vector<std::string>& parts, double pause, double timeout) {
  const int fd = connect_local(port, timeout);
  std::string answer;
  bool sent = fd >= 0;
  for (std::size_t i = 0; sent && i < parts.size(); ++i) {
    if (i > 0) std::this_thread::sleep_for(std::chrono::duration<double>(pause));
    sent = ::send(fd, parts[i].data(), parts[i].size(), MSG_NOSIGNAL) == static_cast<ssize_t>(parts[i].size());
  }
  if (sent) {
    char buffer[4096];
    for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) answer.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return answer;
}

std::thread slow_client(int port, std::string head, std::string unit, double period, const std::atomic<bool>& stop,
                        double limit) {
  return std::thread([=, &stop] {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) return;
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
        ::send(fd, head.data(), head.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(head.size())) {
      while (!stop && std::chrono::steady_clock::now() < until &&
             ::send(fd, unit.data(), unit.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(unit.size()))
        std::this_thread::sleep_for(std::chrono::duration<double>(period));
    }
    ::close(fd);
  });
}

std::size_t count_files(const fs::path& dir) {
  std::size_t n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); it != fs::recursive_directory_iterator(); ++it)
    if (it->is_regular_file()) ++n;
  return n;
}

}  // namespace remesh::test
