#pragma once
/// \file connection_server.h
/// httplib::Server with its connections' loop of our own, for faults of cpp-httplib 0.11.4:
///
/// - **Pipelined requests.** 0.11.4 reads a connection through a stream made anew for each request,
///   whose 4 KiB read-ahead is dropped with it. Whatever a client sent past one request (the next
///   pipelined request, or the head of one whose body was still on its way) was lost; the next
///   bytes from the socket were then read as a request head, so a request's body could run as a
///   request of its own (QA: a pipelined GET and POST head, then a body that was a DELETE of
///   another job: the GET answered, the POST lost, the DELETE run). Here one stream serves the
///   whole connection and keeps its read-ahead from one request to the next (RFC 9112 9.3.2:
///   answered in order).
/// - **The accept backlog.** 0.11.4 listens with a backlog of 5, so a burst of connections (a page
///   opening several streams, many clients) waited for SYN retransmits (1 s or more).
/// - **The end of a connection.** 0.11.4 closed it with what the client had sent past the last
///   request unread, which resets it: the client lost the end of the answers already sent. Here
///   the sending side is shut first, and what the client still sends is read and dropped (at most
///   2 s; a connection with nothing to read closes at once).
/// - **Half-closed clients.** 0.11.4 took a client that closed its sending side after its request
///   (nc -N) for one gone and wrote it nothing; here it is answered (ConnectionStream::is_writable).
///
/// A connection still ends as in httplib: after keep_alive_max_count requests, when the client
/// sends no request within the keep-alive timeout, when a request asks for it or fails, or when
/// the server stops listening (checked every 50 ms while the connection waits, not only between
/// requests as 0.11.4 did).

#include <httplib.h>

namespace remeshd {

class ConnectionServer : public httplib::Server {
 public:
  /// Listens again with the system's largest backlog (call after bind_to_port).
  void widen_backlog();

 private:
  bool process_and_close_socket(socket_t sock) override;
};

}  // namespace remeshd
