#include "connection_server.h"

#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstring>
#include <string>

namespace remeshd {
namespace {

/// Waits up to `ms` milliseconds for `events` on sock: > 0 ready (or the socket has an error or
/// hang-up to report, which the next recv or send returns), 0 timed out, < 0 failed.
int wait_for(socket_t sock, short events, long ms) {
  pollfd p{sock, events, 0};
  const int timeout = static_cast<int>(std::clamp<long>(ms, 0, INT_MAX));
  int r;
  do r = ::poll(&p, 1, timeout);
  while (r < 0 && errno == EINTR);
  if (r > 0 && (p.revents & POLLNVAL)) return -1;
  return r;
}

/// Milliseconds from now until `end` (negative once past).
long ms_until(std::chrono::steady_clock::time_point end) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()).count();
}

long milliseconds(time_t sec, time_t usec) { return static_cast<long>(sec) * 1000 + static_cast<long>(usec) / 1000; }

/// False once the peer has closed (a read would return end of file) or the socket failed; true
/// while nothing is to be read or data waits.
bool peer_open(socket_t sock) {
  const int r = wait_for(sock, POLLIN, 0);
  if (r == 0) return true;
  if (r < 0) return false;
  char byte;
  ssize_t n;
  do n = ::recv(sock, &byte, 1, MSG_PEEK);
  while (n < 0 && errno == EINTR);
  return n > 0;
}

void address_of(socket_t sock, bool peer, std::string& ip, int& port) {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  auto* sa = reinterpret_cast<sockaddr*>(&addr);
  if ((peer ? ::getpeername(sock, sa, &len) : ::getsockname(sock, sa, &len)) != 0) return;
  if (addr.ss_family == AF_INET) port = ntohs(reinterpret_cast<const sockaddr_in*>(&addr)->sin_port);
  else if (addr.ss_family == AF_INET6) port = ntohs(reinterpret_cast<const sockaddr_in6*>(&addr)->sin6_port);
  else return;
  char host[NI_MAXHOST];
  if (::getnameinfo(sa, len, host, sizeof host, nullptr, 0, NI_NUMERICHOST) == 0) ip = host;
}

/// One connection's stream, for all of its requests: what a read took from the socket past the
/// bytes asked for stays for the next read, the next request's included. httplib reads a request
/// head a byte at a time, so the stream reads ahead by up to a buffer. Reads and writes wait up to
/// the server's read and write timeouts; a write fails once the peer has closed while it is
/// answered (as 0.11.4's, which also failed when the peer had closed only its sending side).
class ConnectionStream final : public httplib::Stream {
 public:
  ConnectionStream(socket_t sock, long read_ms, long write_ms) : sock_(sock), read_ms_(read_ms), write_ms_(write_ms) {}

  bool is_readable() const override { return buffered() || wait_for(sock_, POLLIN, read_ms_) > 0; }
  bool is_writable() const override {
    if (wait_for(sock_, POLLOUT, write_ms_) <= 0) return false;
    if (peer_open(sock_)) {
      answering_ = true;
      return true;
    }
    // The peer sent end of file. Before any of the answer went out, that is a client that closed
    // its sending side after its request (nc -N, shutdown(SHUT_WR)) and still reads: it is answered
    // (0.11.4 wrote it nothing; a peer that closed entirely resets the connection, and a write then
    // fails). Once answering, it is a client gone: an event stream stops there.
    if (!answering_) half_closed_ = true;
    return half_closed_;
  }
  /// A request begins: its answer has not started.
  void next_answer() { answering_ = false; }

  ssize_t read(char* ptr, size_t size) override {
    if (buffered()) return take(ptr, size);
    if (wait_for(sock_, POLLIN, read_ms_) <= 0) return -1;
    if (size >= buffer_.size()) return receive(ptr, size);
    const ssize_t n = receive(buffer_.data(), buffer_.size());
    if (n <= 0) return n;
    begin_ = 0;
    end_ = static_cast<std::size_t>(n);
    return take(ptr, size);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!is_writable()) return -1;
    ssize_t n;
    do n = ::send(sock_, ptr, size, MSG_NOSIGNAL);
    while (n < 0 && errno == EINTR);
    return n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { address_of(sock_, true, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { address_of(sock_, false, ip, port); }
  socket_t socket() const override { return sock_; }

  /// Bytes read from the socket that no request has taken yet.
  bool buffered() const { return begin_ < end_; }

 private:
  ssize_t take(char* ptr, size_t size) {
    const std::size_t n = std::min(size, end_ - begin_);
    std::memcpy(ptr, buffer_.data() + begin_, n);
    begin_ += n;
    return static_cast<ssize_t>(n);
  }
  ssize_t receive(char* ptr, size_t size) {
    ssize_t n;
    do n = ::recv(sock_, ptr, size, 0);
    while (n < 0 && errno == EINTR);
    return n;
  }

  socket_t sock_;
  long read_ms_, write_ms_;
  std::array<char, 4096> buffer_{};
  std::size_t begin_ = 0, end_ = 0;
  mutable bool answering_ = false;    ///< some of the current answer is written
  mutable bool half_closed_ = false;  ///< the client closed its side before an answer began
};

/// Whether the next request has begun: bytes already read, or bytes arriving within
/// `timeout_sec` while the server still listens (checked every 50 ms).
bool next_request(const ConnectionStream& strm, socket_t sock, const std::atomic<socket_t>& listening,
                  time_t timeout_sec) {
  if (listening == INVALID_SOCKET) return false;
  if (strm.buffered()) return true;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_sec);
  for (;;) {
    const long left = ms_until(end);
    const int r = wait_for(sock, POLLIN, std::min(50L, std::max(0L, left)));
    if (r != 0) return r > 0;
    if (listening == INVALID_SOCKET || left <= 0) return false;
  }
}

/// Ends a connection without resetting it. A socket closed with bytes it has not read sends a reset,
/// which makes the peer drop what it has not read yet of the answers already sent (QA: five
/// pipelined downloads and a sixth request after them, on a connection that ends after five: the
/// client got one or two of the five, then ECONNRESET). So the sending side is shut first (the
/// answers, then the end), and what the client still sends is read and dropped until it closes
/// too, for at most kLingerMs (RFC 9112 9.6). With nothing waiting to be read, it closes at once
/// (a client that reads its answer and stays idle held the thread the whole 2 s).
void close_gently(socket_t sock) {
  constexpr long kLingerMs = 2000;
  ::shutdown(sock, SHUT_WR);
  if (wait_for(sock, POLLIN, 0) == 0) {
    ::close(sock);
    return;
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(kLingerMs);
  char dropped[4096];
  for (;;) {
    const long left = ms_until(end);
    if (left <= 0 || wait_for(sock, POLLIN, left) <= 0) break;
    ssize_t n;
    do n = ::recv(sock, dropped, sizeof dropped, 0);
    while (n < 0 && errno == EINTR);
    if (n <= 0) break;  // the client's end, or an error
  }
  ::close(sock);
}

}  // namespace

void ConnectionServer::widen_backlog() {
  socket_t s = svr_sock_;
  if (s != INVALID_SOCKET) ::listen(s, SOMAXCONN);
}

bool ConnectionServer::process_and_close_socket(socket_t sock) {
  ConnectionStream strm(sock, milliseconds(read_timeout_sec_, read_timeout_usec_),
                        milliseconds(write_timeout_sec_, write_timeout_usec_));
  bool ok = false;
  for (std::size_t left = keep_alive_max_count_; left > 0 && next_request(strm, sock, svr_sock_, keep_alive_timeout_sec_);
       --left) {
    bool closed = false;
    strm.next_answer();
    ok = process_request(strm, left == 1, closed, nullptr);
    if (!ok || closed) break;
  }
  close_gently(sock);
  return ok;
}

}  // namespace remeshd
