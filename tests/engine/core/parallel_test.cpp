#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "core/parallel.h"

using remesh::parallel_blocks;
using remesh::parallel_for;

TEST_CASE("parallel_for visits every index exactly once", "[core][parallel]") {
  for (unsigned threads : {1u, 2u, 7u}) {
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1023}, std::size_t{5000}}) {
      std::vector<std::atomic<int>> hits(n);
      parallel_for(n, threads, [&](std::size_t i) { hits[i]++; }, 64);
      for (std::size_t i = 0; i < n; ++i) REQUIRE(hits[i] == 1);
    }
  }
}

TEST_CASE("block boundaries do not depend on the thread count", "[core][parallel]") {
  const std::size_t n = 10'000, block = 333;
  std::vector<double> values(n);
  for (std::size_t i = 0; i < n; ++i) values[i] = 1.0 / double(i + 1);
  auto blocked_sum = [&](unsigned threads) {
    std::vector<double> partial(remesh::block_count(n, block), 0.0);
    parallel_blocks(n, block, threads, [&](std::size_t b, std::size_t e, std::size_t k) {
      for (std::size_t i = b; i < e; ++i) partial[k] += values[i];
    });
    return std::accumulate(partial.begin(), partial.end(), 0.0);
  };
  const double one = blocked_sum(1);
  REQUIRE(blocked_sum(2) == one);  // bit-identical, not approximately equal
  REQUIRE(blocked_sum(5) == one);
}

TEST_CASE("an exception in a body reaches the caller", "[core][parallel]") {
  REQUIRE_THROWS_AS(parallel_for(100, 2, [](std::size_t i) {
                      if (i == 57) throw std::runtime_error("boom");
                    }, 8),
                    std::runtime_error);
}

TEST_CASE("the pool still works after a body threw", "[core][parallel]") {
  for (int round = 0; round < 3; ++round) {
    REQUIRE_THROWS_AS(parallel_for(1000, 2, [](std::size_t i) {
                        if (i % 97 == 5) throw std::runtime_error("boom");
                      }, 4),
                      std::runtime_error);
    std::vector<std::atomic<int>> hits(1000);
    parallel_for(1000, 2, [&](std::size_t i) { hits[i]++; }, 4);
    for (auto& h : hits) REQUIRE(h == 1);
  }
}

namespace {
/// Counts the threads that ran a loop body for the first time (a thread_local's construction).
std::atomic<int> fresh_threads{0};
struct FirstUse {
  FirstUse() { ++fresh_threads; }
  void touch() {}
};
thread_local FirstUse first_use;
}  // namespace

TEST_CASE("parallel loops reuse their helper threads", "[core][parallel]") {
  // Warm up: the pool starts its helpers (at most 6 from the tests above, 2 here).
  parallel_for(64, 2, [](std::size_t) { first_use.touch(); }, 1);
  const int before = fresh_threads;
  for (int loop = 0; loop < 200; ++loop) parallel_for(64, 2, [](std::size_t) { first_use.touch(); }, 1);
  // A thread per loop would construct the thread_local 200 times; kept helpers construct it once,
  // and only those the warm-up did not reach yet can still be new.
  REQUIRE(fresh_threads - before <= 6);
}

TEST_CASE("callers on several threads share the pool", "[core][parallel]") {
  // As in the service: several jobs run their loops at once, some nested in others' bodies.
  constexpr int kCallers = 4;
  std::vector<std::uint64_t> sums(kCallers, 0);
  {
    std::vector<std::jthread> callers;
    for (int c = 0; c < kCallers; ++c)
      callers.emplace_back([&, c] {
        for (int rep = 0; rep < 50; ++rep) {
          std::vector<std::uint64_t> partial(remesh::block_count(2000, 50), 0);
          parallel_blocks(2000, 50, 2, [&](std::size_t b, std::size_t e, std::size_t k) {
            for (std::size_t i = b; i < e; ++i) partial[k] += i;
            if (k == 0) {  // a nested loop inside a body
              std::atomic<int> inner{0};
              parallel_for(100, 2, [&](std::size_t) { ++inner; }, 10);
              if (inner != 100) partial[k] += 1'000'000'000;  // spoils the sum
            }
          });
          sums[c] = std::accumulate(partial.begin(), partial.end(), std::uint64_t{0});
        }
      });
  }
  for (auto s : sums) REQUIRE(s == 1999u * 2000u / 2u);
}

TEST_CASE("a forked child runs parallel loops and exits", "[core][parallel]") {
  // The benchmark forks a child per remeshing run after the parent ran loops of its own. The
  // child ends with exit(), static destructors included: the parent's helpers are not in it.
  parallel_for(1000, 2, [](std::size_t) {}, 10);
  std::fflush(nullptr);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    std::vector<std::atomic<int>> hits(5000);
    parallel_for(5000, 2, [&](std::size_t i) { hits[i]++; }, 16);
    int wrong = 0;
    for (auto& h : hits) wrong += h != 1;
    std::exit(wrong == 0 ? 0 : 1);
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
}
