#include "core/parallel.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace remesh {

unsigned default_thread_count() {
  unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : n;
}

namespace {

/// One parallel_blocks() call: its blocks, claimed one at a time by the caller and the helpers.
/// Shared, so that a helper that starts after the call has returned finds nothing left to do and
/// touches nothing of the caller's.
struct Loop {
  std::size_t n = 0, block = 0, blocks = 0;
  const std::function<void(std::size_t, std::size_t, std::size_t)>* body = nullptr;
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};  ///< blocks finished (or skipped after an error)
  std::mutex error_mutex;
  std::exception_ptr error;

  /// Runs blocks until none is left.
  void run() {
    for (;;) {
      const std::size_t b = next.fetch_add(1);
      if (b >= blocks) return;
      try {
        (*body)(b * block, std::min(n, (b + 1) * block), b);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        // The blocks nobody has claimed yet are skipped: count them done.
        const std::size_t claimed = std::min(next.exchange(blocks), blocks);
        done.fetch_add(blocks - claimed);
      }
      if (done.fetch_add(1) + 1 == blocks) done.notify_all();
    }
  }
};

/// Helper threads kept for the life of the process (a parallel loop runs a few hundred times per
/// run; starting a thread for each took ~30 us, and each new thread began with cold thread_local
/// scratch: the projection's triangle stamps, the filter's ring stamps). Helpers take loops from a
/// queue; the calling thread always works on its own loop too, so a loop finishes even when every
/// helper is busy with other callers' loops (the service runs several jobs at once) or, in a
/// process forked from one with helpers, when there are none.
class Pool {
 public:
  /// Offers `loop` to `helpers` helper threads, starting more threads if there are fewer.
  void offer(const std::shared_ptr<Loop>& loop, unsigned helpers) {
    bool sleeping;
    {
      std::lock_guard lock(mutex_);
      while (threads_.size() < helpers) threads_.emplace_back([this] { work(); });
      for (unsigned i = 0; i < helpers; ++i) queue_.push_back(loop);
      queued_.store(queue_.size(), std::memory_order_release);
      sleeping = sleepers_ > 0;
    }
    if (sleeping) wake_.notify_all();
  }

  /// The pool of this process. Never destroyed: its helpers end with the process (a destructor
  /// would join them, and in a forked child that calls exit() they do not exist). A forked child
  /// gets a pool of its own.
  static Pool& instance() {
    static std::mutex mutex;
    static Pool* pool = nullptr;
    static pid_t owner = 0;
    std::lock_guard lock(mutex);
    if (!pool || owner != getpid()) {
      pool = new Pool;  // the parent's, in a forked child, is abandoned with its absent threads
      owner = getpid();
    }
    return *pool;
  }

 private:
  void work() {
    for (;;) {
      // A run's loops come in quick succession (normals, filter, projection, guards, statistics,
      // with a little serial work between): look for the next one for a few tens of microseconds
      // before going to sleep, which costs a wake-up of about the same.
      for (int spin = 0; spin < kSpins && queued_.load(std::memory_order_acquire) == 0; ++spin)
        std::this_thread::yield();
      std::shared_ptr<Loop> loop;
      {
        std::unique_lock lock(mutex_);
        ++sleepers_;
        wake_.wait(lock, [this] { return !queue_.empty(); });
        --sleepers_;
        loop = std::move(queue_.front());
        queue_.pop_front();
        queued_.store(queue_.size(), std::memory_order_release);
      }
      loop->run();
    }
  }

  static constexpr int kSpins = 200;

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Loop>> queue_;
  std::vector<std::thread> threads_;
  std::atomic<std::size_t> queued_{0};  ///< queue_.size(), read without the lock while spinning
  int sleepers_ = 0;                     ///< helpers waiting on wake_
};

}  // namespace

void parallel_blocks(std::size_t n, std::size_t block, unsigned threads,
                     const std::function<void(std::size_t, std::size_t, std::size_t)>& body) {
  if (n == 0) return;
  if (block == 0) block = 1;
  const std::size_t blocks = block_count(n, block);
  if (threads == 0) threads = default_thread_count();
  const unsigned workers = static_cast<unsigned>(std::min<std::size_t>(threads, blocks));
  auto loop = std::make_shared<Loop>();
  loop->n = n, loop->block = block, loop->blocks = blocks, loop->body = &body;
  if (workers > 1) Pool::instance().offer(loop, workers - 1);
  loop->run();
  // Wait for the blocks the helpers took.
  for (std::size_t d = loop->done.load(); d < blocks; d = loop->done.load()) loop->done.wait(d);
  if (loop->error) std::rethrow_exception(loop->error);
}

}  // namespace remesh
