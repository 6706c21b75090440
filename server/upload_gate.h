#pragma once
/// \file upload_gate.h
/// Large uploads are turned into meshes a few at a time. Reading a mesh takes about ten times its
/// file's size in memory for a moment (the polygons read, the half-edge mesh, the search for faces
/// crossing each other: a 36 MB OBJ of 977 000 faces about 360 MB), and each upload is read on its
/// own HTTP thread: eight such uploads at once took the daemon to 2.9 GB, and the 80 HTTP threads
/// could take it past a machine's memory, where the kernel kills it. Reading more at once than
/// there are cores gains no time either (those eight took 27 s each, side by side). A slot is
/// taken once the upload's bytes are in (a client sending slowly holds none), and waiters go in
/// the order they came.

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>

namespace remeshd {

class UploadGate {
 public:
  /// `slots` uploads pass at once (at least 1); one more waits up to `wait_seconds` for its turn,
  /// while fewer than `max_waiting` wait already (else it is refused at once).
  UploadGate(unsigned slots, double wait_seconds, unsigned max_waiting);

  /// A slot, held until destroyed.
  class Pass {
   public:
    explicit Pass(UploadGate* gate) : gate_(gate) {}
    Pass(Pass&& other) noexcept : gate_(other.gate_) { other.gate_ = nullptr; }
    Pass& operator=(Pass&& other) noexcept {
      if (this != &other) {
        if (gate_) gate_->leave();
        gate_ = other.gate_;
        other.gate_ = nullptr;
      }
      return *this;
    }
    Pass(const Pass&) = delete;
    ~Pass() {
      if (gate_) gate_->leave();
    }

   private:
    UploadGate* gate_;
  };

  enum class Refusal { Busy, Closed };
  /// A slot, or why none: Busy when none came free in time or too many wait already, Closed once
  /// close() was called (the daemon is stopping).
  struct Entry {
    std::optional<Pass> pass;
    Refusal refusal = Refusal::Busy;
  };
  Entry enter();

  /// Wakes every waiter with Closed, and refuses from now on.
  void close();

  unsigned slots() const { return slots_; }
  /// Uploads holding a slot now, and waiting for one.
  unsigned busy() const;
  unsigned waiting() const;

 private:
  void leave();

  const unsigned slots_;
  const double wait_seconds_;
  const unsigned max_waiting_;
  mutable std::mutex mutex_;
  std::condition_variable free_;
  unsigned busy_ = 0;
  std::deque<std::uint64_t> line_;  ///< tickets of the waiters, first come first
  std::uint64_t next_ticket_ = 0;
  bool closed_ = false;
};

}  // namespace remeshd
