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
  // First come, first served: with others waiting, a newcomer waits behind them even when a slot
  // is free this moment (one freed for the first of them, who is still waking up).
  if (busy_ >= slots_ || !line_.empty()) {
    if (line_.size() >= max_waiting_) return entry;
    const std::uint64_t ticket = next_ticket_++;
    line_.push_back(ticket);
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_seconds_);
    const bool turn = free_.wait_until(lock, until, [&] { return closed_ || (busy_ < slots_ && line_.front() == ticket); });
    line_.erase(std::find(line_.begin(), line_.end(), ticket));
    // The next in line may be able to go now (a slot free, or this one leaving the front).
    free_.notify_all();
    if (closed_) {
      entry.refusal = Refusal::Closed;
      return entry;
    }
    if (!turn) return entry;
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
  free_.notify_all();
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
  return static_cast<unsigned>(line_.size());
}

}  // namespace remeshd
