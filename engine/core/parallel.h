#pragma once
/// \file parallel.h
/// A deterministic data-parallel loop. The range [0, n) is cut into fixed-size blocks whose
/// boundaries do not depend on the thread count, so a reduction done per block and then combined in
/// block order gives bit-identical results with 1 or 64 threads.

#include <cstddef>
#include <functional>

namespace remesh {

/// Threads used by parallel loops when a caller passes 0: the hardware concurrency (at least 1).
unsigned default_thread_count();

/// Calls `body(begin, end, block_index)` for consecutive blocks of `block` indices covering [0, n),
/// on up to `threads` threads (0 = default_thread_count()). Returns when all blocks are done.
/// The first exception thrown by a body is rethrown on the calling thread.
void parallel_blocks(std::size_t n, std::size_t block, unsigned threads,
                     const std::function<void(std::size_t, std::size_t, std::size_t)>& body);

/// Number of blocks parallel_blocks() uses for n indices.
inline std::size_t block_count(std::size_t n, std::size_t block) { return (n + block - 1) / block; }

/// Calls `body(i)` for every i in [0, n) in parallel. `body` must only write to data owned by i.
template <class F>
void parallel_for(std::size_t n, unsigned threads, F&& body, std::size_t block = 1024) {
  parallel_blocks(n, block, threads, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t i = b; i < e; ++i) body(i);
  });
}

}  // namespace remesh
