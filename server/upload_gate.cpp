#include "upload_gate.h"

#include <algorithm>
#include <chrono>

namespace remeshd {

UploadGate::UploadGate(unsigned slots, double wait_seconds, unsigned max_waiting)
    : slots_(std::max(1u, slots)), wait_seconds_(std::max(0.0, wait_seconds)), max_waiting_(max_waiting) {}

UploadGate::Entry UploadGate::enter() {
  std::unique_lock lock(mutex_);
  Entry entry;
  if (closed_) {
    entry.refusal = Refusal::Closed;
    return entry;
  }
  if (busy_ >= slots_) {
    if (waiting_ >= max_waiting_) return entry;
    ++waiting_;
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_seconds_);
    const bool free = free_.wait_until(lock, until, [&] { return closed_ || busy_ < slots_; });
    --waiting_;
    if (closed_) {
      entry.refusal = Refusal::Closed;
      return entry;
    }
    if (!free) return entry;
  }
  ++busy_;
  entry.pass.emplace(this);
  return entry;
}

void UploadGate::leave() {
  {
    const std::lock_guard lock(mutex_);
    --busy_;
  }
  free_.notify_one();
}

void UploadGate::close() {
  {
    const std::lock_guard lock(mutex_);
    closed_ = true;
  }
  free_.notify_all();
}

unsigned UploadGate::busy() const {
  const std::lock_guard lock(mutex_);
  return busy_;
}

unsigned UploadGate::waiting() const {
  const std::lock_guard lock(mutex_);
  return waiting_;
}

}  // namespace remeshd
