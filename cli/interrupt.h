#pragma once
/// \file interrupt.h
/// Ctrl-C during a run: the first SIGINT asks the remesher to stop (through a std::stop_source) so
/// the partial, valid mesh can still be written; a second SIGINT ends the program at once.

#include <stop_token>
#include <thread>

namespace remesh::cli {

/// While alive, SIGINT calls `source.request_stop()`. The handler only sets a flag (that is all a
/// signal handler may safely do); a watcher thread turns the flag into the stop request.
class InterruptGuard {
 public:
  explicit InterruptGuard(std::stop_source source);
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  /// True once SIGINT arrived.
  static bool interrupted();

 private:
  std::stop_source source_;
  std::jthread watcher_;
};

}  // namespace remesh::cli
