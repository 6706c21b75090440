/// \file interrupt.cpp
#include "interrupt.h"

#include <atomic>
#include <chrono>
#include <csignal>

namespace remesh::cli {
namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void on_sigint(int) {
  g_interrupted.store(true);
  std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C ends the program
}

}  // namespace

InterruptGuard::InterruptGuard(std::stop_source source) : source_(std::move(source)) {
  g_interrupted.store(false);
  std::signal(SIGINT, on_sigint);
  watcher_ = std::jthread([this](std::stop_token own) {
    while (!own.stop_requested()) {
      if (g_interrupted.load()) {
        source_.request_stop();
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
}

InterruptGuard::~InterruptGuard() {
  watcher_.request_stop();
  if (watcher_.joinable()) watcher_.join();
  std::signal(SIGINT, SIG_DFL);
}

bool InterruptGuard::interrupted() { return g_interrupted.load(); }

}  // namespace remesh::cli
